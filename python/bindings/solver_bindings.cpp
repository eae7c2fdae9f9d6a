// Python Solver: construction, the lock, solve() (a METH_FASTCALL entry point) and its result
// (new or written into `out`), rows on an engine, response columns, pickling.
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <limits>

#include "py_solver.hpp"
#include "result_type.hpp"

namespace vsbind {

vereshchagin::InertiaCheck inertiaCheckArg(const std::string& value, const std::string& where) {
  if (value == "physical") return vereshchagin::InertiaCheck::Physical;
  if (value == "joint_space") return vereshchagin::InertiaCheck::JointSpace;
  raise(where +
        "inertia_check must be 'physical' (every body a rigid body) or 'joint_space' (identified models: "
        "any symmetric inertia, H(q) positive definite at each solve), got '" +
        value + "'");
}

PySolver::PySolver(const py::object& model, const py::object& gravity, const py::object& rcond,
                   const py::object& damping, const py::object& inertia_check, const py::object& max_constraints)
    : damping_arg_(damping) {
  if (py::isinstance<PyChain>(model)) {
    chain_ = std::make_unique<PyChain>(model.cast<const PyChain&>());
    addressing = chain_.get();
  } else if (py::isinstance<PyTree>(model)) {
    tree_ = std::make_unique<PyTree>(model.cast<const PyTree&>());
    addressing = tree_.get();
  } else {
    throw py::type_error("Solver(model): model must be a vereshchagin.Chain or vereshchagin.Tree, got " +
                         std::string(Py_TYPE(model.ptr())->tp_name));
  }
  options_.rcond = scalarArg(rcond, "rcond");
  if (inertia_check.is_none())  // the check the model was built with
    options_.inertia_check = tree_ ? tree_->inertia_check : chain_->inertia_check;
  else
    options_.inertia_check = inertiaCheckArg(py::str(inertia_check).cast<std::string>(), "");
  if (!damping.is_none()) {
    options_.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
    options_.damping = scalarArg(damping, "damping");
  }
  if (!max_constraints.is_none()) {
    if (PyBool_Check(max_constraints.ptr()) || !PyIndex_Check(max_constraints.ptr()))
      raise("max_constraints must be an int >= 1 (None: the default), got " +
            py::repr(max_constraints).cast<std::string>());
    const std::optional<long long> value = intWithin(max_constraints.ptr(), 1, 1 << 24);
    if (!value)
      raise("max_constraints must be in 1 .. 16777216 (None: the default), got " +
            py::str(max_constraints).cast<std::string>());
    options_.max_constraints = static_cast<int>(*value);
  }
  gravity_ = vec3(gravity, "gravity");
  const vereshchagin::ModelOptions model_options{options_.inertia_check};
  cpp_model_ = tree_ ? vereshchagin::Model(tree_->robot.tree, tree_->robot.root_link, model_options)
                     : vereshchagin::Model(chain_->robot.chain, model_options);
  const char* invalid = tree_ ? "invalid tree: " : "invalid chain: ";
  if (const vereshchagin::Status s = cpp_model_.status(); !s) raise(invalid + std::string(s.message()));
  auto probe = std::make_unique<Engine>(cpp_model_, gravity_, options_);
  if (const vereshchagin::Status s = probe->data.status(); !s) raise(invalid + std::string(s.message()));
  max_columns = probe->data.maxConstraints();
  engines_.push_back(std::move(probe));
  nj = cpp_model_.nrOfJoints();
  ns = cpp_model_.nrOfSegments();
  friction.setModelValues(addressing->jointInfos());
}

PySolver::Lock::Lock(PySolver& s) : s_(s) {
  if (s.holder_.load() == std::this_thread::get_id())
    raise(
        "a Solver call re-entered the same Solver while it converts its arguments (an argument's __array__, "
        "property or __index__ calls this solver): convert the arguments first, or use another Solver");
  if (!s.mutex_.try_lock()) {
    py::gil_scoped_release release;  // another thread solves: wait without blocking it
    s.mutex_.lock();
  }
  s.holder_.store(std::this_thread::get_id());
}

PySolver::Lock::~Lock() {
  s_.holder_.store(std::thread::id());
  s_.mutex_.unlock();
}

Engine& PySolver::engine(std::size_t k) {
  while (engines_.size() <= k) engines_.push_back(std::make_unique<Engine>(cpp_model_, gravity_, options_));
  return *engines_[k];
}

void PySolver::setGravity(const py::object& gravity) {
  const KDL::Vector g = vec3(gravity, "gravity");
  Lock lk(*this);
  gravity_ = g;
  for (auto& e : engines_) e->input.gravity = g;
}

py::array PySolver::gravity() const {
  py::array g = newDoubles({3});
  for (int k = 0; k < 3; ++k) doubles(g)[k] = gravity_(k);
  return g;
}

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

py::object PySolver::solve(PyObject* const* args, PyObject* out) {
  Lock lk(*this);
  last_state_ = false;
  args_.parse(*this, args, /*batch=*/false);
  const char* failure;
  {
    py::gil_scoped_release release;
    failure = runRow(args_, 0, 0);
  }
  if (failure) raise(failure);
  last_state_ = true;
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

namespace {

Eigen::VectorXi jointList(const Addressable& chain, const py::object& joints) {
  const char* what = "joints must be a sequence of joint names or int indices";
  if (joints.is_none() || py::isinstance<py::str>(joints)) raise(what);
  py::sequence seq;
  if (py::isinstance<py::array>(joints)) {
    py::array a = joints.cast<py::array>();
    const char kind = a.dtype().kind();
    if (a.ndim() != 1 || (a.size() > 0 && kind != 'i' && kind != 'u' && kind != 'U'))
      raise(std::string(what) + ", got an array of shape " + shapeStr(a) + " and dtype " +
            std::string(py::str(a.dtype())));
    seq = a.attr("tolist")();
  } else if (py::isinstance<py::sequence>(joints)) {
    seq = joints.cast<py::sequence>();
  } else {
    raise(what);
  }
  Eigen::VectorXi j(static_cast<Eigen::Index>(seq.size()));
  for (Eigen::Index c = 0; c < j.size(); ++c)
    j(c) = chain.resolveJoint(seq[c].ptr(), "joints[" + std::to_string(c) + "]");
  return j;
}

}  // namespace

py::tuple PySolver::responseColumns(const py::object& joints, bool hold_sticking) {
  const Eigen::VectorXi requested = jointList(*addressing, joints);
  Lock lk(*this);
  if (!last_state_)
    raise(
        "response_columns() linearises around the last successful solve() (or the last row of solve_batch()): "
        "call solve() at the state first");
  Engine& e = *engines_[0];
  const Eigen::Index k = requested.size();
  Eigen::MatrixXd dq(nj, k), dt(nj, k);
  vereshchagin::Status rc;
  {
    py::gil_scoped_release release;
    rc = hold_sticking ? e.data.responseColumnsHoldingSticking(requested, dq, dt)
                       : e.data.responseColumns(requested, dq, dt);
  }
  if (!rc) raise(rc.message());
  auto toNumpy = [&](const Eigen::MatrixXd& M) {
    py::array a = newDoubles({static_cast<py::ssize_t>(nj), static_cast<py::ssize_t>(k)});
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(doubles(a), nj, k) = M;
    return a;
  };
  return py::make_tuple(toNumpy(dq), toNumpy(dt));
}

py::tuple PySolver::getState() const {
  return py::make_tuple(model(), gravity(), options_.rcond, damping_arg_,
                        vereshchagin::inertiaCheckName(options_.inertia_check),
                        options_.max_constraints > 0 ? py::object(py::int_(options_.max_constraints)) : py::none());
}

// ------------------------------------------------------------------------------------------------
// solve(): a METH_FASTCALL | METH_KEYWORDS method. Keyword names are matched by identity against
// interned strings first (what the interpreter passes for literal keywords), then by value.
namespace {

constexpr const char* kSolveParams[] = {"q",
                                        "qd",
                                        "alpha",
                                        "beta",
                                        "f_ext",
                                        "tau_ff",
                                        "friction",
                                        "constraints",
                                        "f_ext_pass_through",
                                        "tau_ff_pass_through",
                                        "out"};
constexpr int kOut = 10;
constexpr int kNumSolveParams = sizeof(kSolveParams) / sizeof(kSolveParams[0]);
PyObject* g_solve_names[kNumSolveParams];
PyObject* g_solver_error = nullptr;

// Fills `slots` from positional and keyword arguments; raises TypeError like Python functions.
void bindArguments(const char* fname, PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames, PyObject** slots,
                   const char* const* names, PyObject** interned, int count) {
  if (nargs > count)
    throw py::type_error(std::string(fname) + "() takes at most " + std::to_string(count) + " positional arguments (" +
                         std::to_string(nargs) + " given)");
  for (Py_ssize_t k = 0; k < nargs; ++k) slots[k] = args[k];
  if (kwnames == nullptr) return;
  const Py_ssize_t nkw = PyTuple_GET_SIZE(kwnames);
  for (Py_ssize_t k = 0; k < nkw; ++k) {
    PyObject* name = PyTuple_GET_ITEM(kwnames, k);
    int slot = -1;
    for (int s = 0; s < count && slot < 0; ++s)
      if (name == interned[s]) slot = s;
    for (int s = 0; s < count && slot < 0; ++s)
      if (PyUnicode_Compare(name, interned[s]) == 0) slot = s;
    if (slot < 0)
      throw py::type_error(std::string(fname) + "() got an unexpected keyword argument '" +
                           py::handle(name).cast<std::string>() + "'");
    if (slots[slot] != nullptr)
      throw py::type_error(std::string(fname) + "() got multiple values for argument '" + names[slot] + "'");
    slots[slot] = args[nargs + k];
  }
}

// The PySolver of a Solver instance (the method descriptor guarantees the type; a subclass whose
// __init__ did not call the base one has no value yet).
PySolver& solverOf(PyObject* self) {
  auto* inst = reinterpret_cast<py::detail::instance*>(self);
  void* value = nullptr;
  if (inst->simple_layout) {
    if (inst->simple_holder_constructed) value = inst->simple_value_holder[0];
  } else {
    value = inst->get_value_and_holder().value_ptr();
  }
  if (value == nullptr) throw py::type_error("Solver.__init__ was not called on this instance");
  return *static_cast<PySolver*>(value);
}

// Runs `body`, turning C++ exceptions into Python ones (SolverError for our messages).
template <typename Body>
PyObject* guarded(Body&& body) {
  try {
    return body().release().ptr();
  } catch (const SolverError& e) {
    PyErr_SetString(g_solver_error, e.what());
  } catch (py::error_already_set& e) {
    e.restore();
  } catch (const py::builtin_exception& e) {
    e.set_error();
  } catch (const std::bad_alloc&) {
    PyErr_NoMemory();
  } catch (const std::exception& e) {
    PyErr_SetString(PyExc_RuntimeError, e.what());
  }
  return nullptr;
}

PyObject* solveEntry(PyObject* self, PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames) {
  return guarded([&]() -> py::object {
    PyObject* a[kNumSolveParams] = {};
    bindArguments("solve", args, nargs, kwnames, a, kSolveParams, g_solve_names, kNumSolveParams);
    return solverOf(self).solve(a, a[kOut] == Py_None ? nullptr : a[kOut]);
  });
}

// _time_cpp(reps, q, qd, ...): seconds per C++ solve (outputs read as solve() reads them), for
// benchmarks that compare the Python call with the C++ work in the same process.
PyObject* timeCppEntry(PyObject* self, PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames) {
  return guarded([&]() -> py::object {
    if (nargs < 1) throw py::type_error("_time_cpp(reps, q, qd, ...) needs reps");
    const long reps = py::handle(args[0]).cast<long>();
    PyObject* a[kNumSolveParams] = {};
    bindArguments("_time_cpp", args + 1, nargs - 1, kwnames, a, kSolveParams, g_solve_names, kNumSolveParams);
    return py::float_(solverOf(self).timeCpp(a, reps));
  });
}

PyMethodDef g_solve_def = {"solve", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(solveEntry)),
                           METH_FASTCALL | METH_KEYWORDS, nullptr};  // doc set in bindSolver()
PyMethodDef g_time_def = {"_time_cpp", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(timeCppEntry)),
                          METH_FASTCALL | METH_KEYWORDS, nullptr};  // doc set in bindSolver()

void addFastMethod(py::handle cls, PyMethodDef* def) {
  PyObject* descr = PyDescr_NewMethod(reinterpret_cast<PyTypeObject*>(cls.ptr()), def);
  if (descr == nullptr || PyObject_SetAttrString(cls.ptr(), def->ml_name, descr) != 0) throw py::error_already_set();
  Py_DECREF(descr);
}

}  // namespace

void bindSolver(py::module_& mod) {
  g_solver_error = mod.attr("SolverError").ptr();
  g_solve_def.ml_doc = doc("_core.Solver.solve");
  g_time_def.ml_doc = doc("_core.Solver._time_cpp");
  for (int k = 0; k < kNumSolveParams; ++k) g_solve_names[k] = PyUnicode_InternFromString(kSolveParams[k]);

  py::class_<PySolver> cls(mod, "Solver", doc("_core.Solver"));
  cls.def(py::init<const py::object&, const py::object&, const py::object&, const py::object&, const py::object&,
                   const py::object&>(),
          py::arg("model"), py::arg("gravity") = std::vector<double>{0.0, 0.0, -9.81}, py::arg("rcond") = 1e-12,
          py::arg("damping") = py::none(), py::arg("inertia_check") = py::none(),
          py::arg("max_constraints") = py::none())
      .def("solve_batch", &PySolver::solveBatch, py::arg("q"), py::arg("qd"), py::arg("alpha") = py::none(),
           py::arg("beta") = py::none(), py::arg("f_ext") = py::none(), py::arg("tau_ff") = py::none(),
           py::arg("friction") = py::none(), py::arg("constraints") = py::none(),
           py::arg("f_ext_pass_through") = py::none(), py::arg("tau_ff_pass_through") = py::none(),
           py::arg("threads") = 1, doc("_core.Solver.solve_batch"))
      .def("response_columns", &PySolver::responseColumns, py::arg("joints"), py::arg("hold_sticking") = true,
           doc("_core.Solver.response_columns"))
      .def_property("gravity", &PySolver::gravity, &PySolver::setGravity, doc("_core.Solver.gravity"))
      .def_property_readonly(
          "n_joints", [](const PySolver& s) { return s.nj; }, doc("_core.Solver.n_joints"))
      .def_property_readonly(
          "n_segments", [](const PySolver& s) { return s.ns; }, doc("_core.Solver.n_segments"))
      .def_property_readonly(
          "model", [](const PySolver& s) { return s.model(); }, doc("_core.Solver.model"))
      .def_property_readonly(
          "chain",
          [](const PySolver& s) {
            if (s.isTree()) raise("this Solver is for a Tree: use solver.tree (or solver.model)");
            return s.model();
          },
          doc("_core.Solver.chain"))
      .def_property_readonly(
          "tree",
          [](const PySolver& s) {
            if (!s.isTree()) raise("this Solver is for a Chain: use solver.chain (or solver.model)");
            return s.model();
          },
          doc("_core.Solver.tree"))
      .def_property_readonly(
          "inertia_check", [](const PySolver& s) { return s.inertiaCheck(); }, doc("_core.Solver.inertia_check"))
      .def(py::pickle([](const PySolver& s) { return s.getState(); },
                      [](const py::tuple& t) {
                        if (t.size() != 5 && t.size() != 6) raise("Solver state must have 5 or 6 entries");
                        return std::make_unique<PySolver>(t[0], t[1], t[2], t[3], t[4],
                                                          t.size() == 6 ? py::object(t[5]) : py::none());
                      }));
  addFastMethod(cls, &g_solve_def);
  addFastMethod(cls, &g_time_def);
}

}  // namespace vsbind
