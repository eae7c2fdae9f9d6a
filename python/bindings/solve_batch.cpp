// Solver.solve_batch: the arguments parsed once by SolveArgs (B rows, each argument shared or with
// a leading batch axis), rows run on one engine per thread with the GIL released through the same
// runRow as Solver.solve (so every row equals the single solve bit for bit).
#include <algorithm>
#include <system_error>
#include <thread>

#include "py_solver.hpp"

namespace vsbind {

using namespace pybind11::literals;

namespace {

// solve_batch's threads: an int >= 0 (0: one per core), at most kMaxBatchThreads.
long threadsArg(const py::object& obj) {
  if (obj.is_none()) return 1;
  const long v = intOption(obj, "threads", 0, kMaxBatchThreads, "", "(0: one per core)", true);
  return v == 0 ? std::max(1u, std::thread::hardware_concurrency()) : v;
}

// Runs work(t, begin, end) on `threads` contiguous chunks of [0, B): chunk 0 on this thread.
// Returns the message of a thread the OS refused to start (the started ones are joined), or "".
template <typename Work>
std::string runChunks(long threads, py::ssize_t B, const Work& work) {
  if (threads <= 1) {
    work(0, 0, B);
    return "";
  }
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(threads));
  const py::ssize_t chunk = (B + threads - 1) / threads;
  try {
    for (long t = 1; t < threads; ++t) pool.emplace_back(work, t, std::min(B, t * chunk), std::min(B, (t + 1) * chunk));
  } catch (const std::system_error& e) {
    for (auto& th : pool) th.join();
    return "solve_batch could not start thread " + std::to_string(pool.size() + 1) + " of " + std::to_string(threads) +
           " (" + e.what() + "): pass fewer threads";
  }
  work(0, 0, std::min(B, chunk));
  for (auto& th : pool) th.join();
  return "";
}

}  // namespace

py::dict PySolver::solveBatch(PyObject* const* args, const py::object& threads_obj) {
  Lock lk(*this);
  last_state_ = false;  // until engine 0 holds the last row's state
  SolveArgs a;
  a.parse(*this, args, /*batch=*/true);
  const py::ssize_t B = a.rows;
  const long threads = std::min<long>(threadsArg(threads_obj), std::max<py::ssize_t>(B, 1));
  for (long t = 0; t < threads; ++t) engine(static_cast<std::size_t>(t));
  const py::ssize_t n = nj, BF = a.any_friction ? B : 0;  // the friction outputs: 0 rows without friction
  const py::array qdd = newDoubles({B, n}), tau = newDoubles({B, n}), nu = newDoubles({B, a.columns}),
                  acc = newDoubles({B, ns + 1, 6}), smin = newDoubles({B}), fr = newDoubles({BF, n}),
                  lim = newDoubles({BF, n}), gauss = newDoubles({BF}), rank = newInts({B}), status = newInts({BF, n}),
                  iters = newInts({BF});
  const RowOut o{doubles(qdd), doubles(tau),   doubles(nu), doubles(acc), doubles(smin), BF ? doubles(fr) : nullptr,
                 doubles(lim), doubles(gauss), ints(rank),  ints(status), ints(iters)};
  std::vector<std::pair<py::ssize_t, std::string>> failures(threads, {-1, ""});
  auto work = [&](long t, py::ssize_t begin, py::ssize_t end) {
    for (py::ssize_t b = begin; b < end; ++b) {
      if (const char* failure = runRow(a, b, t)) return void(failures[t] = {b, failure});
      if (!writeRow(a, b, t, o))
        return void(failures[t] = {b, "the results overflow: gauss_value is beyond the double range"});
    }
  };
  std::string start_failure;
  {
    py::gil_scoped_release release;
    start_failure = runChunks(threads, B, work);
  }
  if (!start_failure.empty()) raise(start_failure);
  for (const auto& f : failures)  // rows are in thread order: the first failure is the lowest row
    if (f.first >= 0) raise("batch row " + std::to_string(f.first) + ": " + f.second);
  // response_columns() after a batch linearises around its last row: engine 0 solved it unless
  // the rows were spread over threads; then it solves it once more (bit-identical rows).
  if (B > 0) {
    const char* failure = nullptr;
    if (threads > 1) {
      py::gil_scoped_release release;
      failure = runRow(a, B - 1, 0);
    }
    last_state_ = failure == nullptr;
  }
  py::dict out("qdd"_a = qdd, "tau_command"_a = tau, "nu"_a = nu, "link_acc"_a = acc, "constraint_rank"_a = rank,
               "smallest_singular_value"_a = smin);
  if (a.any_friction) {
    out["friction_torque"] = fr;
    out["limit_torque"] = lim;
    out["status"] = status;
    out["gauss_value"] = gauss;
    out["iterations"] = iters;
  }
  if (a.keys.empty()) return out;
  py::dict per_key;  // segment_nu: (B, m_i) views of nu per constraints= key
  for (std::size_t k = 0; k < a.keys.size(); ++k) {
    const py::ssize_t start = a.starts[k], count = a.blocks[a.blocks.size() - a.keys.size() + k].cols;
    per_key[a.keys[k]] = nu[py::make_tuple(py::slice(0, B, 1), py::slice(start, start + count, 1))];
  }
  out["segment_nu"] = per_key;
  return out;
}

}  // namespace vsbind
