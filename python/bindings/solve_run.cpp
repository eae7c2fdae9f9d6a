// Solver.solve (one row on workspace 0, its result new or written into `out`), its benchmark
// hooks (_solve_dict, _time_cpp) and Solver.solve_batch (vereshchagin::solveBatch over one
// workspace per thread), each on the arguments SolveArgs parsed.
#include <algorithm>

#include "py_solver.hpp"
#include "result_type.hpp"

namespace vsbind {

using namespace pybind11::literals;

constexpr const char* kOverflow = "the results overflow: gauss_value is beyond the double range";

void PySolver::solveArgs(PyObject* const* args, bool frictionless) {
  last_state_ = false;
  args_.parse(*this, args, /*batch=*/false);
  if (frictionless && args_.any_friction) raise("_solve_dict benchmarks the frictionless call: no friction");
  const char* failure;
  {
    py::gil_scoped_release release;
    vereshchagin::BatchWorkspace& w = *workspaces_[0];
    args_.input.fillRow(0, w.input);
    const vereshchagin::Status st = vereshchagin::solve(cpp_model_, w.data, w.input);
    failure = st ? nullptr : st.message();
  }
  if (failure) raise(failure);
  last_state_ = true;
}

py::object PySolver::solve(PyObject* const* args, PyObject* out) {
  Lock lk(*this);
  solveArgs(args, false);
  const bool fr = args_.any_friction;
  py::object r = newResult(ResultLayout{static_cast<int>(nj), static_cast<int>(ns), args_.columns, fr}, out);
  const ResultPointers p = resultPointers(r.ptr());
  int rank, iterations = 0;
  double smin, gauss = 0.0;
  const vereshchagin::BatchOutput o{
      p.qdd,          p.tau_command, p.nu,     p.link_acc, &smin, &rank, fr ? p.friction_torque : nullptr,
      p.limit_torque, &gauss,        p.status, &iterations};
  if (!o.write(0, workspaces_[0]->data, args_.columns, fr)) raise(kOverflow);
  setResultScalars(r.ptr(), rank, smin, gauss, iterations);
  if (!args_.keys.empty()) {
    const std::size_t nk = args_.keys.size(), first = args_.input.blocks.size() - nk;
    py::tuple keys(nk), starts(nk), counts(nk);
    for (std::size_t k = 0; k < nk; ++k) {
      keys[k] = args_.keys[k];
      starts[k] = args_.starts[k];
      counts[k] = args_.input.blocks[first + k].columns;
    }
    setSegmentLayout(r.ptr(), keys, starts, counts);
  }
  return r;
}

py::dict PySolver::solveDict(PyObject* const* args) {
  Lock lk(*this);
  solveArgs(args, true);
  py::array qdd = newDoubles({nj}), tau = newDoubles({nj}), nu = newDoubles({args_.columns}),
            acc = newDoubles({ns + 1, 6});
  int rank;
  double smin;
  vereshchagin::BatchOutput{doubles(qdd), doubles(tau), doubles(nu), doubles(acc), &smin, &rank}.write(
      0, workspaces_[0]->data, args_.columns, false);
  return py::dict("qdd"_a = qdd, "tau_command"_a = tau, "nu"_a = nu, "link_acc"_a = acc, "constraint_rank"_a = rank,
                  "smallest_singular_value"_a = smin);
}

double PySolver::timeCpp(PyObject* const* args, long reps) {
  Lock lk(*this);
  SolveArgs a;
  a.parse(*this, args, /*batch=*/false);
  py::gil_scoped_release release;
  return vereshchagin::secondsPerSolve(cpp_model_, a.input, *workspaces_[0], reps);
}

py::dict PySolver::solveBatch(PyObject* const* args, const py::object& threads_obj) {
  Lock lk(*this);
  last_state_ = false;  // until workspace 0 holds the last row's state
  SolveArgs a;
  a.parse(*this, args, /*batch=*/true);
  const py::ssize_t B = a.input.rows, n = nj, BF = a.any_friction ? B : 0;  // friction outputs: 0 rows without
  long threads = 1;
  if (!threads_obj.is_none())
    threads = intOption(threads_obj, "threads", 0, kMaxBatchThreads, "", "(0: one per core)", true);
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<vereshchagin::BatchWorkspace*> ws;
  for (long t = 0; t < std::min<long>(threads, std::max<py::ssize_t>(B, 1)); ++t) ws.push_back(&workspace(t));
  py::dict out("qdd"_a = newDoubles({B, n}), "tau_command"_a = newDoubles({B, n}), "nu"_a = newDoubles({B, a.columns}),
               "link_acc"_a = newDoubles({B, ns + 1, 6}), "constraint_rank"_a = newInts({B}),
               "smallest_singular_value"_a = newDoubles({B}), "friction_torque"_a = newDoubles({BF, n}),
               "limit_torque"_a = newDoubles({BF, n}), "status"_a = newInts({BF, n}),
               "gauss_value"_a = newDoubles({BF}), "iterations"_a = newInts({BF}));
  auto d = [&](const char* k) { return doubles(out[k].cast<py::array>()); };
  auto i = [&](const char* k) { return ints(out[k].cast<py::array>()); };
  const vereshchagin::BatchOutput o{d("qdd"),
                                    d("tau_command"),
                                    d("nu"),
                                    d("link_acc"),
                                    d("smallest_singular_value"),
                                    i("constraint_rank"),
                                    BF ? d("friction_torque") : nullptr,
                                    d("limit_torque"),
                                    d("gauss_value"),
                                    i("status"),
                                    i("iterations")};
  vereshchagin::BatchFailure failure;
  {
    py::gil_scoped_release release;
    failure = vereshchagin::solveBatch(cpp_model_, a.input, o, ws);
  }
  if (!failure.ok()) raise(failure.message);
  last_state_ = B > 0;
  // solver.py drops the friction outputs without friction and views nu per constraints= key.
  out["any_friction"] = a.any_friction;
  py::list layout;
  for (std::size_t k = 0; k < a.keys.size(); ++k)
    layout.append(
        py::make_tuple(a.keys[k], a.starts[k], a.input.blocks[a.input.blocks.size() - a.keys.size() + k].columns));
  out["segment_nu"] = layout;
  return out;
}

}  // namespace vsbind
