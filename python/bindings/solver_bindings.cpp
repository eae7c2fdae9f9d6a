// Solver's Python methods: solve(), solve_batch() and the benchmark hooks as METH_FASTCALL entry
// points (keyword names matched against interned strings), the rest through pybind11.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "py_solver.hpp"

namespace vsbind {

namespace {

// solve()'s parameters; solve_batch() has `threads` in place of `out`.
// clang-format off
constexpr const char* kSolveParams[] = {"q", "qd", "alpha", "beta", "f_ext", "tau_ff", "friction", "constraints",
                                        "f_ext_pass_through", "tau_ff_pass_through", "out", "a_desired", "contacts",
                                        "time_step", "contact_velocity_tolerance", "contact_max_pivots"};
// clang-format on
static_assert(sizeof(kSolveParams) == kNumSolveArgs * sizeof(char*), "one name per SolveArgs::parse argument");
PyObject* g_names[2][kNumSolveArgs];  // interned: solve()'s, solve_batch()'s

// Fills `slots` (solve()'s parameters) from positional and keyword arguments; raises TypeError
// like Python functions. names: g_names[0] or g_names[1]. step: q, qd, time_step positional, the rest keywords.
void bindArguments(const char* fname, PyObject* const* names, PyObject* const* args, Py_ssize_t nargs,
                   PyObject* kwnames, PyObject** slots, bool step) {
  if (nargs > (step ? 3 : kNumSolveArgs))
    throw py::type_error(std::string(fname) + "() takes at most " + std::to_string(step ? 3 : kNumSolveArgs) +
                         " positional arguments (" + std::to_string(nargs) + " given)");
  for (Py_ssize_t k = 0; k < nargs; ++k) slots[step && k == 2 ? kTimeStepArg : k] = args[k];
  for (Py_ssize_t k = 0; kwnames != nullptr && k < PyTuple_GET_SIZE(kwnames); ++k) {
    PyObject* name = PyTuple_GET_ITEM(kwnames, k);
    int slot = -1;
    for (int s = 0; s < kNumSolveArgs && slot < 0; ++s)
      if (name == names[s]) slot = s;
    for (int s = 0; s < kNumSolveArgs && slot < 0; ++s)
      if (PyUnicode_Compare(name, names[s]) == 0) slot = s;
    if (slot < 0)
      throw py::type_error(std::string(fname) + "() got an unexpected keyword argument '" +
                           py::handle(name).cast<std::string>() + "'");
    if (slots[slot] != nullptr)
      throw py::type_error(std::string(fname) + "() got multiple values for argument '" +
                           py::handle(names[slot]).cast<std::string>() + "'");
    slots[slot] = args[nargs + k];
  }
}

// The PySolver of a Solver instance (the method descriptor guarantees the type; a subclass whose
// __init__ did not call the base one has no value yet).
PySolver& solverOf(PyObject* self) {
  void* value = reinterpret_cast<py::detail::instance*>(self)->get_value_and_holder().value_ptr();
  if (value == nullptr) throw py::type_error("Solver.__init__ was not called on this instance");
  return *static_cast<PySolver*>(value);
}

// Runs `body`, turning C++ exceptions into Python ones with the module's translators, as pybind11's
// own dispatch does (SolverError for our messages).
template <typename Body>
PyObject* guarded(Body&& body) {
  try {
    return body().release().ptr();
  } catch (py::error_already_set& e) {
    e.restore();
  } catch (...) {
    py::detail::try_translate_exceptions();
  }
  return nullptr;
}

enum Entry { kSolve, kTimeCpp, kSolveBatch, kStep, kStepSymplectic };
constexpr const char* kEntryNames[] = {"solve", "_time_cpp", "solve_batch", "step", "_step_symplectic"};

// The METH_FASTCALL methods (what each returns: vereshchagin/_docstrings.py): solve, _time_cpp(reps, ...), solve_batch
// (`out` is its `threads`; a dict that solver.py wraps), step, _step_symplectic (`out` is its momentum).
template <Entry kind>
PyObject* fastEntry(PyObject* self, PyObject* const* args, Py_ssize_t nargs, PyObject* kwnames) {
  return guarded([&]() -> py::object {
    if (kind == kTimeCpp && nargs < 1) throw py::type_error("_time_cpp(reps, q, qd, ...) needs reps");
    const long reps = kind == kTimeCpp ? py::handle(args[0]).cast<long>() : 0;
    const int first = kind == kTimeCpp ? 1 : 0;  // _time_cpp's solve arguments follow reps
    PyObject* a[kNumSolveArgs] = {};
    bindArguments(kEntryNames[kind], g_names[kind == kSolveBatch], args + first, nargs - first, kwnames, a,
                  kind == kStep);
    if (kind >= kStep && a[kTimeStepArg] == nullptr)  // (its value: vereshchagin::step()'s check)
      throw py::type_error(std::string(kEntryNames[kind]) + "() missing required argument 'time_step' (pos 3)");
    if (kind == kTimeCpp) return py::float_(solverOf(self).timeCpp(a, reps));
    if (kind == kSolveBatch) return solverOf(self).solveBatch(a, a[kOutArg]);
    return solverOf(self).solve(a, a[kOutArg] == Py_None ? nullptr : a[kOutArg],
                                kind == kSolve ? 0 : kind - kSolveBatch);
  });
}

template <Entry kind>
PyMethodDef fastDef() {  // the doc is set in bindSolver()
  return {kEntryNames[kind], reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)()>(fastEntry<kind>)),
          METH_FASTCALL | METH_KEYWORDS, nullptr};
}

PyMethodDef g_fast_defs[] = {fastDef<kSolve>(), fastDef<kTimeCpp>(), fastDef<kSolveBatch>(), fastDef<kStep>(),
                             fastDef<kStepSymplectic>()};

}  // namespace

void bindSolver(py::module_& mod) {
  for (int k = 0; k < kNumSolveArgs; ++k) {
    g_names[0][k] = PyUnicode_InternFromString(kSolveParams[k]);
    g_names[1][k] = PyUnicode_InternFromString(k == kOutArg ? "threads" : kSolveParams[k]);
  }

  using O = const py::object&;
  py::class_<PySolver> cls(mod, "Solver", doc("_core.Solver"));
  cls.def(py::init<O, O, O, O, O, O>(), py::arg("model"), py::arg("gravity") = std::vector<double>{0.0, 0.0, -9.81},
          py::arg("rcond") = 1e-12, py::arg("damping") = py::none(), py::arg("inertia_check") = py::none(),
          py::arg("max_constraints") = py::none())
      .def("response_columns", &PySolver::responseColumns, py::arg("joints"), py::arg("hold_sticking") = true,
           doc("_core.Solver.response_columns"))
      .def("_whole_body", &PySolver::wholeBody, doc("_core.Solver._whole_body"))
      .def_property("gravity", &PySolver::gravity, &PySolver::setGravity, doc("_core.Solver.gravity"))
      .def_readonly("n_joints", &PySolver::nj, doc("_core.Solver.n_joints"))
      .def_readonly("n_segments", &PySolver::ns, doc("_core.Solver.n_segments"))
      .def_property_readonly("model", &PySolver::model, doc("_core.Solver.model"));
  cls.def_property_readonly("inertia_check", &PySolver::inertiaCheck, doc("_core.Solver.inertia_check"));
  for (PyMethodDef& def : g_fast_defs) {
    def.ml_doc = doc("_core.Solver." + std::string(def.ml_name));
    PyObject* descr = PyDescr_NewMethod(reinterpret_cast<PyTypeObject*>(cls.ptr()), &def);
    if (descr == nullptr) throw py::error_already_set();
    cls.attr(def.ml_name) = py::reinterpret_steal<py::object>(descr);
  }
}

}  // namespace vsbind
