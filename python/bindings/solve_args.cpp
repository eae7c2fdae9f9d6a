// The one parser of Solver.solve's and solve_batch's arguments (SolveArgs, py_solver.hpp): Python objects viewed as
// float64 arrays are handed to vereshchagin::BatchArgs, which checks their shapes into rows with a stride of a
// BatchInput (0: shared by every row; solve() is the one-row case without a batch axis); keys are resolved here.
// friction=: its _fields tuple's arrays checked by vereshchagin::frictionFromArrays, values by vereshchagin::solve.
#include <climits>

#include "py_solver.hpp"

namespace vsbind {

F64View SolveArgs::view(PyObject* obj, const char* name) {
  F64View v = asF64(obj, name);
  if (v.keep) keep_.push_back(std::move(v.keep));  // v.data stays valid: keep_ holds the copy
  return v;
}

vereshchagin::StridedRows SolveArgs::vector(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok) {
  vereshchagin::StridedRows r;
  check(BatchArgs::vector(r, name, view(obj, name), n, scalar_ok));
  return r;
}

// A block of alpha and its set-point, beta or (classical) a_desired (label: "" for solve's alpha,
// else "constraints[key]").
void SolveArgs::addBlock(int segment, PyObject* alpha, PyObject* set_point, const std::string& label, bool classical) {
  const std::string an = label.empty() ? "" : label + " alpha", bn = label.empty() ? "" : label + " beta";
  const char* a_name = label.empty() ? "alpha" : an.c_str();
  const char* sp_name = classical ? "a_desired" : label.empty() ? "beta" : bn.c_str();
  check(block(segment, view(alpha, a_name), a_name));
  const F64View sp = set_point ? view(set_point, sp_name) : F64View();
  check(setPoint(set_point ? &sp : nullptr, classical, sp_name, label));
}

// f_ext: (n_segments, 6) rows [force, moment] (base axes, moment about each tip origin), or a
// dict {segment or link: (6,) wrench}, the moment about that frame's origin.
void SolveArgs::parseFExt(PyObject* obj) {
  if (!PyDict_Check(obj)) {
    const long shape[2] = {solver_->ns, 6};
    check(rows(input.f_ext, "f_ext", view(obj, "f_ext"), 2, shape, vereshchagin::ShapeHint::FExt));
    return;
  }
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = "f_ext[" + py::repr(key).cast<std::string>() + "]";
    const FrameTarget t = solver_->addressing->resolveMoving(key, label);
    vereshchagin::WrenchRows& w = input.wrenches.emplace_back();
    w.segment = t.segment;
    w.on_frame = t.merged;
    w.point = vereshchagin::Vector3(t.link_in_tip.p.data);
    w.wrench = vector(value, label.c_str(), 6);
  }
}

// constraints: {segment or link: (alpha (6, m_i), beta (m_i,))}, one entry per frame.
void SolveArgs::parseConstraints(PyObject* obj) {
  if (!PyDict_Check(obj)) raise("constraints must be a dict {segment name or index: (alpha (6, m_i), beta (m_i,))}");
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = "constraints[" + py::repr(key).cast<std::string>() + "]";
    const FrameTarget t = solver_->addressing->resolveMoving(key, label);
    check(frame(t.segment, vereshchagin::Vector3(t.link_in_tip.p.data), label));
    if ((!PyTuple_Check(value) && !PyList_Check(value)) || PySequence_Fast_GET_SIZE(value) != 2)
      raise(label + " must be a pair (alpha " +
            (batched() ? "(6, m_i) or (B, 6, m_i), beta (m_i,) or (B, m_i))" : "(6, m_i), beta (m_i,))"));
    const int start = columns;
    addBlock(t.segment, PySequence_Fast_GET_ITEM(value, 0), PySequence_Fast_GET_ITEM(value, 1), label);
    if (t.merged) input.blocks.back().point = vereshchagin::Vector3(t.link_in_tip.p.data);
    layout.append(py::make_tuple(py::handle(key), start, input.blocks.back().columns));
  }
}

const vereshchagin::FrictionModel* SolveArgs::friction(PyObject* obj, vereshchagin::FrictionModel& scratch) {
  if (obj == nullptr || obj == Py_None || PyBool_Check(obj)) return obj == Py_True ? &solver_->model_friction : nullptr;
  static PyObject* const module = py::module_::import("vereshchagin.friction").release().ptr();
  static PyObject* const type = py::object(py::handle(module).attr("Friction")).release().ptr();
  static PyObject* const fields_name = PyUnicode_InternFromString("_fields");
  const bool cacheable = Py_TYPE(obj) == reinterpret_cast<PyTypeObject*>(type);
  const py::object f = cacheable ? py::reinterpret_steal<py::object>(PyObject_GetAttr(obj, fields_name))
                                 : py::handle(module).attr("_friction_fields")(py::handle(obj));
  if (!f) throw py::error_already_set();
  if (cacheable && f.ptr() == cache_key_.ptr()) return &cache_;
  if (!PyTuple_Check(f.ptr()) || PyTuple_GET_SIZE(f.ptr()) != 7) raise("friction._fields is not a tuple of 7");
  vereshchagin::FrictionModel& fm = cacheable ? cache_ : scratch;
  if (cacheable) cache_key_ = py::object();  // invalid until parsed
  auto item = [&](int k) { return PyTuple_GET_ITEM(f.ptr(), k); };
  auto view = [&](int k, const char* name) { return item(k) == Py_None ? F64View() : asF64(item(k), name); };
  const F64View st = asF64(item(0), "friction.static"), kv = view(1, "friction.kinetic"),
                lo = view(3, "friction.lower"), up = view(4, "friction.upper");
  auto opt = [&](int k, const F64View& v) { return item(k) == Py_None ? nullptr : &v; };
  check(vereshchagin::frictionFromArrays(fm, solver_->cppModel().nrOfJoints(), st, opt(1, kv),
                                         scalarArg(item(2), "friction.velocity_tolerance"), opt(3, lo), opt(4, up),
                                         scalarArg(item(5), "friction.limit_tolerance")));
  fm.max_iterations = static_cast<int>(PyLong_AsLong(item(6)));  // (an int in [-1, 2^31) by friction.py)
  if (cacheable) cache_key_ = f;
  return &fm;
}

// friction: one for every row, or in a batch a list or tuple of one per row.
void SolveArgs::parseFriction(PyObject* obj) {  // input.friction: cleared by start()
  any_friction = false;
  if (!batched() || !(PyList_Check(obj) || PyTuple_Check(obj))) {
    if (const vereshchagin::FrictionModel* fm = friction(obj, friction_scratch_)) input.friction.push_back(fm);
    any_friction = !input.friction.empty();
    return;
  }
  const Py_ssize_t n = PySequence_Fast_GET_SIZE(obj);
  check(batchAxis(n, "friction", "(a sequence of " + std::to_string(n) + ")"));
  friction_models_.resize(static_cast<std::size_t>(n));
  for (Py_ssize_t b = 0; b < n; ++b) {
    vereshchagin::FrictionModel& fm = friction_models_[b];
    const vereshchagin::FrictionModel* p = nullptr;
    const auto row = [b] { return "friction[" + std::to_string(b) + "]: "; };
    try {
      p = friction(PySequence_Fast_GET_ITEM(obj, b), fm);
    } catch (const SolverError& e) {
      raise(row() + e.what());
    } catch (py::error_already_set& e) {  // vereshchagin/friction.py's SolverError
      if (!e.matches(py::module_::import("vereshchagin._core").attr("SolverError"))) throw;
      raise(row() + std::string(py::str(e.value())));
    }
    if (p != nullptr && p != &fm) fm = *p;  // the cache or the model's values: the next row may change them
    input.friction.push_back(p ? &fm : nullptr);
    any_friction |= p != nullptr;
  }
}

// Each Contact holds its segment key and its checked values as a read-only float64 array (vereshchagin/contacts.py):
// point (3, in the segment's or link's frame), normal (3), mu, facets, force (NaN: a support).
void SolveArgs::parseContacts(PyObject* obj, const char* name) {
  static PyObject* const type =
      py::object(py::module_::import("vereshchagin.contacts").attr("Contact")).release().ptr();
  static PyObject* const segment_name = PyUnicode_InternFromString("_segment");
  static PyObject* const values_name = PyUnicode_InternFromString("_values");
  if (!PyList_Check(obj) && !PyTuple_Check(obj)) raise(std::string(name) + " must be a list of vereshchagin.Contact");
  for (Py_ssize_t k = 0; k < PySequence_Fast_GET_SIZE(obj); ++k) {
    PyObject* c = PySequence_Fast_GET_ITEM(obj, k);
    const std::string label = name + ("[" + std::to_string(k) + "]");
    if (!PyObject_TypeCheck(c, reinterpret_cast<PyTypeObject*>(type)))
      raise(label + " must be a vereshchagin.Contact, got " + Py_TYPE(c)->tp_name);
    const auto attr = [c](PyObject* name) {
      py::object o = py::reinterpret_steal<py::object>(PyObject_GetAttr(c, name));
      if (!o) throw py::error_already_set();
      return o;
    };
    const FrameTarget t = solver_->addressing->resolveMoving(attr(segment_name).ptr(), label);
    const F64View v = asF64(attr(values_name).ptr(), label.c_str());  // checked by Contact (force NaN: a support)
    if (v.ndim != 1 || v.shape[0] != 9) raise(label + ": not a vereshchagin.Contact's values");
    const KDL::Vector point = t.link_in_tip * KDL::Vector(v.data[0], v.data[1], v.data[2]);
    vereshchagin::PointContact& pc = input.contacts.emplace_back();
    pc.segment = t.segment;
    pc.point = vereshchagin::Vector3(point.data);
    pc.normal = vereshchagin::Vector3(v.data + 3);
    pc.mu = v.data[6];
    pc.facets = static_cast<int>(v.data[7]);
    pc.force = v.data[8];
  }
}

void SolveArgs::parse(PySolver& s, PyObject* const* a, bool batch) {
  start(batch, s.cppModel());
  solver_ = &s;
  if (!layout.empty()) PyList_SetSlice(layout.ptr(), 0, PY_SSIZE_T_MAX, nullptr);
  keep_.clear();
  if (a[0] == nullptr || a[1] == nullptr) raise("solve() needs q and qd");
  input.q = vector(a[0], "q", solver_->nq);
  input.q_dot = vector(a[1], "qd", solver_->nj);
  const bool classical = given(a[kADesiredArg]);
  check(vereshchagin::endBlockArgs(given(a[2]), given(a[3]), classical, s.isTree()));
  if (given(a[2])) {
    PyObject* set_point = classical ? a[kADesiredArg] : given(a[3]) ? a[3] : nullptr;
    addBlock(static_cast<int>(solver_->ns) - 1, a[2], set_point, "", classical);
    if (input.blocks.back().columns == 0) input.blocks.pop_back();  // no columns: nothing to constrain
  }
  if (given(a[4])) parseFExt(a[4]);
  if (given(a[5])) input.ff_torques = vector(a[5], "tau_ff", solver_->nj);
  if (given(a[7])) parseConstraints(a[7]);
  parseFriction(a[6]);
  input.contacts.clear();
  if (given(a[kContactsArg])) parseContacts(a[kContactsArg], "contacts");
  input.time_step = given(a[kTimeStepArg]) ? scalarArg(a[kTimeStepArg], "time_step") : 0.0;  // (range: by solve)
  const bool v_tol = given(a[kVelocityTolArg]);
  input.contact_velocity_tolerance = v_tol ? scalarArg(a[kVelocityTolArg], "contact_velocity_tolerance") : 1e-6;
  PyObject* p = given(a[kMaxPivotsArg]) ? a[kMaxPivotsArg] : nullptr;  // an int, not a bool (its value: solve()'s)
  const bool is_int = p && !PyBool_Check(p) && PyIndex_Check(p);
  const std::optional<long long> bound = !p ? -1 : is_int ? intWithin(p, INT_MIN, INT_MAX) : std::nullopt;
  if (!bound)
    raise("contact_max_pivots must be an int, -1 (the default bound) or > 0, got " + std::string(py::repr(p)));
  input.contact_max_pivots = static_cast<int>(*bound);
  // Pass-through weights: one per constraint column (their range: checked by vereshchagin::solve).
  if (given(a[8])) input.f_ext_pass_through = vector(a[8], "f_ext_pass_through", columns, /*scalar_ok=*/true);
  if (given(a[9])) input.ff_pass_through = vector(a[9], "tau_ff_pass_through", columns, /*scalar_ok=*/true);
}

}  // namespace vsbind
