// One row on an engine (SolveArgs::fillRow, then vereshchagin::solve), its results written as a
// row of the outputs, Solver.solve's result (new, or written into `out`) and _time_cpp's loop.
#include <algorithm>
#include <chrono>
#include <limits>

#include "py_solver.hpp"
#include "result_type.hpp"

namespace vsbind {

using namespace pybind11::literals;

const char* PySolver::runRow(const SolveArgs& a, py::ssize_t b, std::size_t k) {
  Engine& e = *engines_[k];
  a.fillRow(b, e.input);
  const vereshchagin::Status s = vereshchagin::solve(cpp_model_, e.data, e.input);
  return s.value() == 0 ? nullptr : s.message();
}

bool PySolver::writeRow(const SolveArgs& a, py::ssize_t b, std::size_t k, const RowOut& o) const {
  const vereshchagin::Data& d = engines_[k]->data;
  const py::ssize_t n = nj;
  std::copy_n(d.qdd().data(), n, o.qdd + b * n);
  std::copy_n(d.commandTorques().data(), n, o.tau_command + b * n);
  // nu has no entry for columns on a chain without segments (nothing moves): their magnitude is 0.
  std::fill_n(o.nu + b * a.columns, a.columns, 0.0);
  std::copy_n(d.nu().data(), d.nu().size(), o.nu + b * a.columns);
  std::copy_n(d.linkAccelerations().data(), 6 * (ns + 1), o.link_acc + b * 6 * (ns + 1));
  o.rank[b] = d.constraintRank();
  o.smin[b] = d.smallestSingularValue();
  if (o.friction_torque == nullptr) return true;
  if (a.friction(b) == nullptr) {  // a batch row without friction
    std::fill_n(o.friction_torque + b * n, n, std::nan(""));
    std::fill_n(o.limit_torque + b * n, n, std::nan(""));
    std::fill_n(o.status + b * n, n, -1);
    o.gauss[b] = std::nan("");
    o.iterations[b] = -1;
    return true;
  }
  std::copy_n(d.frictionTorques().data(), n, o.friction_torque + b * n);
  std::copy_n(d.limitTorques().data(), n, o.limit_torque + b * n);
  for (py::ssize_t j = 0; j < n; ++j) o.status[b * n + j] = static_cast<int>(d.jointStatus()[j]);
  o.gauss[b] = d.gaussValue();
  o.iterations[b] = d.iterations();
  return std::isfinite(o.gauss[b]);
}

void PySolver::solveArgs(PyObject* const* args, bool frictionless) {
  last_state_ = false;
  args_.parse(*this, args, /*batch=*/false);
  if (frictionless && args_.any_friction) raise("_solve_dict benchmarks the frictionless call: no friction");
  const char* failure;
  {
    py::gil_scoped_release release;
    failure = runRow(args_, 0, 0);
  }
  if (failure) raise(failure);
  last_state_ = true;
}

py::object PySolver::solve(PyObject* const* args, PyObject* out) {
  Lock lk(*this);
  solveArgs(args, false);
  py::object r =
      newResult(ResultLayout{static_cast<int>(nj), static_cast<int>(ns), args_.columns, args_.any_friction}, out);
  const ResultPointers p = resultPointers(r.ptr());
  int rank, iterations = 0;
  double smin, gauss = 0.0;
  const RowOut o{
      p.qdd,          p.tau_command, p.nu,  p.link_acc, &smin,      args_.any_friction ? p.friction_torque : nullptr,
      p.limit_torque, &gauss,        &rank, p.status,   &iterations};
  if (!writeRow(args_, 0, 0, o)) raise("the results overflow: gauss_value is beyond the double range");
  setResultScalars(r.ptr(), rank, smin, gauss, iterations);
  if (!args_.keys.empty()) {
    const std::size_t nk = args_.keys.size(), first = args_.blocks.size() - nk;
    py::tuple keys(nk), starts(nk), counts(nk);
    for (std::size_t k = 0; k < nk; ++k) {
      keys[k] = args_.keys[k];
      starts[k] = args_.starts[k];
      counts[k] = args_.blocks[first + k].cols;
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
  writeRow(args_, 0, 0,
           RowOut{doubles(qdd), doubles(tau), doubles(nu), doubles(acc), &smin, nullptr, nullptr, nullptr, &rank,
                  nullptr, nullptr});
  return py::dict("qdd"_a = qdd, "tau_command"_a = tau, "nu"_a = nu, "link_acc"_a = acc, "constraint_rank"_a = rank,
                  "smallest_singular_value"_a = smin);
}

// Seconds per C++ solve of the parsed row, reading every output solve() returns.
double PySolver::timeCpp(PyObject* const* args, long reps) {
  Lock lk(*this);
  SolveArgs a;
  a.parse(*this, args, /*batch=*/false);
  Eigen::VectorXd qdd(nj), tau(nj), nu(std::max(a.columns, 1)), fr(nj), lim(nj);
  Eigen::Matrix<double, 6, Eigen::Dynamic> acc(6, ns + 1);
  std::vector<int> status(nj);
  int rank, iters;
  double smin, gauss;
  const RowOut o{qdd.data(), tau.data(), nu.data(), acc.data(),    &smin, a.any_friction ? fr.data() : nullptr,
                 lim.data(), &gauss,     &rank,     status.data(), &iters};
  py::gil_scoped_release release;
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < reps; ++k) {
    if (runRow(a, 0, 0)) return std::numeric_limits<double>::quiet_NaN();
    writeRow(a, 0, 0, o);
  }
  const std::chrono::duration<double> dt = std::chrono::steady_clock::now() - t0;
  return dt.count() / static_cast<double>(reps);
}

}  // namespace vsbind
