// Solver.solve and step (a row on workspace 0, the result new or `out`), _step_symplectic, _whole_body, the benchmark
// hook _time_cpp and solve_batch (one workspace per thread), on the arguments SolveArgs parsed.
#include <algorithm>

#include "py_solver.hpp"

namespace vsbind {

using namespace pybind11::literals;

void PySolver::solveArgs(PyObject* const* args, double* const* next, const double* p) {
  last_state_ = false;
  args_.parse(*this, args, /*batch=*/false);
  vereshchagin::Status st;
  {
    py::gil_scoped_release release;
    vereshchagin::BatchWorkspace& w = *workspaces_[0];
    args_.input.fillRow(0, w.input);
    const auto P = [&](int k) { return Eigen::Map<Eigen::VectorXd>(next[k], k ? nj : nq); };  // q_next: nq
    st = !next ? vereshchagin::solve(cpp_model_, w.data, w.input)
         : p ? vereshchagin::stepSymplectic(cpp_model_, w.data, w.input, Eigen::Map<const Eigen::VectorXd>(p, nj), P(0),
                                            P(1), P(2))
             : vereshchagin::step(cpp_model_, w.data, w.input, P(0), P(1));
  }
  if (!st) raise(st.message());
  last_state_ = true;
  if (st.code() == vereshchagin::Error::Degraded && PyErr_WarnEx(PyExc_RuntimeWarning, st.message(), 1) != 0)
    throw py::error_already_set();  // (warnings as errors)
}

py::object PySolver::solve(PyObject* const* args, PyObject* out, int step) {
  Lock lk(*this);
  py::object next_arrays[3];  // the step's (no arrays made for a solve)
  double* next[3] = {};
  for (int k = 0; k < (step == 2 ? 3 : step ? 2 : 0); ++k)
    next[k] = doubles(next_arrays[k] = newDoubles({k ? nj : nq}));
  const F64View p = step == 2 ? vectorView(out ? out : Py_None, "momentum (out=)", nj) : F64View();
  solveArgs(args, step ? next : nullptr, step == 2 ? p.data : nullptr);
  const vereshchagin::PackedRow layout{nj, ns, args_.columns, args_.any_friction, long(args_.input.contacts.size())};
  py::object r = newResult(layout, step == 2 ? nullptr : out);  // (step 2's `out`: the momentum)
  if (!resultOutput(r.ptr()).write(0, workspaces_[0]->data, args_.columns, layout.friction))
    raise("the results overflow: gauss_value is beyond the double range");
  if (!args_.layout.empty()) setSegmentLayout(r.ptr(), py::tuple(args_.layout));
  if (step == 2) return py::make_tuple(next_arrays[0], next_arrays[1], next_arrays[2], r);
  return step ? py::object(py::make_tuple(next_arrays[0], next_arrays[1], r)) : r;
}

PySolver::WholeBodyOut PySolver::wholeBody(O q, O qd, O f_ext, O tau_ff, O actuated, O supports, O task) {
  Lock lk(*this);
  PyObject* a[kNumSolveArgs] = {q.ptr(), qd.ptr(), nullptr, nullptr, f_ext.ptr(), tau_ff.ptr()};
  args_.parse(*this, a, /*batch=*/false);  // solve()'s checks and messages
  args_.parseContacts(supports.ptr(), "supports");
  whole_body_.start(cpp_model_, args_.input, gravity_);
  for (const py::handle item : task) {
    const py::tuple t = py::reinterpret_borrow<py::tuple>(item);
    const std::string label = py::str(t[0]);
    const FrameTarget f = t[2].is_none() ? FrameTarget{t[1].cast<int>()} : addressing->resolveMoving(t[2].ptr(), label);
    const auto view = [&](int k, const char* what) { return asF64(t[k].ptr(), (label + what).c_str()); };
    check(whole_body_.addTask(f.segment, f.link_in_tip, view(3, " point"), view(4, " alpha"), view(5, " beta"), label));
  }
  const F64View mask = given(actuated.ptr()) ? asF64(actuated.ptr(), "actuated") : F64View();
  vereshchagin::Status st;
  {
    py::gil_scoped_release release;
    st = whole_body_.solve(given(actuated.ptr()) ? &mask : nullptr);
  }
  if (!st) raise("least_effort: " + std::string(st.message()));
  const vereshchagin::WholeBodyResult& r = whole_body_.result();
  return {r.tau, r.forces, r.qdd, r.effort, r.residual};
}

double PySolver::timeCpp(PyObject* const* args, long reps) {
  Lock lk(*this);
  SolveArgs a;
  a.parse(*this, args, /*batch=*/false);
  py::gil_scoped_release release;
  return vereshchagin::secondsPerSolve(cpp_model_, a.input, *workspaces_[0], reps);
}

py::dict PySolver::solveBatch(PyObject* const* args, PyObject* threads_obj) {
  Lock lk(*this);
  last_state_ = false;  // until workspace 0 holds the last row's state
  SolveArgs a;
  a.parse(*this, args, /*batch=*/true);
  const py::ssize_t B = a.input.rows, n = nj, BF = a.any_friction ? B : 0;  // friction outputs: 0 rows without
  const long t = threads_obj && threads_obj != Py_None ? py::handle(threads_obj).cast<long>() : 1;  // solver.py checks
  const long threads = std::clamp<long>(t == 0 ? std::thread::hardware_concurrency() : t, 1, 256);  // 0: one per core
  std::vector<vereshchagin::BatchWorkspace*> ws;
  for (long t = 0; t < std::min<long>(threads, std::max<py::ssize_t>(B, 1)); ++t) ws.push_back(&workspace(t));
  vereshchagin::BatchOutput o;
  py::dict out;
  const auto put = [&](const char* key, py::array a) {
    out[key] = a;
    return a;
  };
  o.qdd = doubles(put("qdd", newDoubles({B, n})));
  o.tau_command = doubles(put("tau_command", newDoubles({B, n})));
  o.nu = doubles(put("nu", newDoubles({B, a.columns})));
  o.link_acc = doubles(put("link_acc", newDoubles({B, ns + 1, 6})));
  o.constraint_rank = ints(put("constraint_rank", newInts({B})));
  o.smallest_singular_value = doubles(put("smallest_singular_value", newDoubles({B})));
  double* friction = doubles(put("friction_torque", newDoubles({BF, n})));
  o.friction_torque = BF ? friction : nullptr;
  o.limit_torque = doubles(put("limit_torque", newDoubles({BF, n})));
  o.status = ints(put("status", newInts({BF, n})));
  o.gauss_value = doubles(put("gauss_value", newDoubles({BF})));
  o.iterations = ints(put("iterations", newInts({BF})));
  const py::ssize_t k = static_cast<py::ssize_t>(a.input.contacts.size());
  o.contact_force = doubles(put("contact_force", newDoubles({B, k, 3})));
  o.contact_status = ints(put("contact_status", newInts({B, k})));
  o.contact_outcome = ints(put("contact_outcome", newInts({B})));
  vereshchagin::BatchFailure failure;
  {
    py::gil_scoped_release release;
    failure = vereshchagin::solveBatch(cpp_model_, a.input, o, ws);
  }
  if (!failure.ok()) raise(failure.message);
  last_state_ = B > 0;
  // solver.py drops the friction outputs without friction and views nu per constraints= key.
  out["any_friction"] = a.any_friction;
  out["segment_nu"] = a.layout;
  return out;
}

}  // namespace vsbind
