// The one parser of Solver.solve's and Solver.solve_batch's arguments (SolveArgs, py_solver.hpp):
// Python objects are viewed as float64 arrays and handed to vereshchagin::BatchArgs, which checks
// their shapes into rows with a stride of a BatchInput (0: shared by every row; solve() is the
// one-row case that accepts no batch axis); keys are resolved here. friction= (FrictionArg): the
// attributes viewed as arrays, checked by vereshchagin::frictionFromArrays with the Python names
// (friction.static, ...), values by vereshchagin::solve; a vereshchagin.Friction is parsed once
// and reused while its attributes are the same objects.
#include "py_solver.hpp"

namespace vsbind {

namespace {

// Raised for alpha/beta (the end segment's constraint) on a tree solver.
constexpr const char* kTreeAlpha =
    "alpha and beta constrain a chain's last segment; a Tree has no last segment: pass constraints={segment or "
    "link name: (alpha, beta)}";

bool given(PyObject* obj) {
  return obj != nullptr && obj != Py_None;
}

void check(const std::string& why) {
  if (!why.empty()) raise(why);
}

std::string keyLabel(const char* what, PyObject* key) {
  return std::string(what) + "[" + py::repr(key).cast<std::string>() + "]";
}

vereshchagin::Vector3 point(const KDL::Vector& p) {
  return vereshchagin::Vector3(p.x(), p.y(), p.z());
}

// The attributes of a vereshchagin.Friction, in the order of FrictionArg::cache_attrs_ (interned).
PyObject* attrName(int k) {
  static const char* const text[6] = {"static", "kinetic", "velocity_tolerance", "lower", "upper", "limit_tolerance"};
  static PyObject* names[6] = {};
  if (names[k] == nullptr) names[k] = PyUnicode_InternFromString(text[k]);
  return names[k];
}

// The instance dict of a vereshchagin.Friction (a dataclass: its fields live there).
PyObject* instanceDict(PyObject* obj) {
  PyObject** dict = _PyObject_GetDictPtr(obj);
  return dict == nullptr ? nullptr : *dict;
}

double scalarAttr(PyObject* fr, const char* attr, const char* name, double fallback) {
  const py::object obj = py::getattr(fr, attr, py::none());
  return obj.is_none() ? fallback : scalarArg(obj, name);
}

}  // namespace

const double* SolveArgs::keep(F64View& v) {
  if (v.keep) keep_.push_back(std::move(v.keep));
  return v.data;
}

Rows SolveArgs::vector(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok) {
  F64View v = asF64(obj, name);
  Rows r;
  check(BatchArgs::vector(r, name, v, n, scalar_ok));
  keep(v);
  return r;
}

// A block of alpha and its set-point, beta or (classical) a_desired (label: "" for solve's alpha,
// else "constraints[key]").
void SolveArgs::addBlock(int segment, PyObject* alpha, PyObject* set_point, const std::string& label, bool classical) {
  const std::string an = label.empty() ? "" : label + " alpha", bn = label.empty() ? "" : label + " beta";
  const char* a_name = label.empty() ? "alpha" : an.c_str();
  const char* sp_name = classical ? "a_desired" : label.empty() ? "beta" : bn.c_str();
  F64View a = asF64(alpha, a_name);
  check(block(segment, a, a_name));
  keep(a);
  F64View sp;
  if (set_point != nullptr) sp = asF64(set_point, sp_name);
  check(setPoint(set_point ? &sp : nullptr, classical, sp_name, label));
  keep(sp);
}

// f_ext: (n_segments, 6) rows [force, moment] (base axes, moment about each tip origin), or a
// dict {segment or link: (6,) wrench}, the moment about that frame's origin.
void SolveArgs::parseFExt(PyObject* obj) {
  if (!PyDict_Check(obj)) {
    const long shape[2] = {ns_, 6};
    F64View v = asF64(obj, "f_ext");
    check(rows(input.f_ext, "f_ext", v, 2, shape, vereshchagin::ShapeHint::FExt));
    keep(v);
    return;
  }
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = keyLabel("f_ext", key);
    const FrameTarget t = addressing_->resolveMoving(key, label);
    vereshchagin::WrenchRows& w = input.wrenches.emplace_back();
    w.segment = t.segment;
    w.on_frame = t.merged;
    w.point = point(t.link_in_tip.p);
    w.wrench = vector(value, label.c_str(), 6);
  }
}

// constraints: {segment or link: (alpha (6, m_i), beta (m_i,))}, one entry per frame.
void SolveArgs::parseConstraints(PyObject* obj) {
  if (!PyDict_Check(obj)) raise("constraints must be a dict {segment name or index: (alpha (6, m_i), beta (m_i,))}");
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = keyLabel("constraints", key);
    const FrameTarget t = addressing_->resolveMoving(key, label);
    check(frame(t.segment, point(t.link_in_tip.p), label));
    if ((!PyTuple_Check(value) && !PyList_Check(value)) || PySequence_Fast_GET_SIZE(value) != 2)
      raise(label + " must be a pair (alpha " +
            (batched() ? "(6, m_i) or (B, 6, m_i), beta (m_i,) or (B, m_i))" : "(6, m_i), beta (m_i,))"));
    keys.push_back(py::reinterpret_borrow<py::object>(key));
    starts.push_back(columns);
    addBlock(t.segment, PySequence_Fast_GET_ITEM(value, 0), PySequence_Fast_GET_ITEM(value, 1), label);
    if (t.merged) input.blocks.back().point = point(t.link_in_tip.p);
  }
}

void FrictionArg::setModelValues(const std::vector<vereshchagin::JointInfo>& joints) {
  const auto n = static_cast<Eigen::Index>(joints.size());
  model_values_.static_friction = model_values_.lower = model_values_.upper = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    model_values_.static_friction(k) = joints[k].friction;
    model_values_.lower(k) = joints[k].lower;
    model_values_.upper(k) = joints[k].upper;
  }
}

// True while the cached Friction still holds the very attribute objects it was parsed from. Its
// arrays are read-only views of immutable bytes (friction.py), so the same objects mean the same
// values; an attribute replaced (object.__setattr__) makes the next solve parse it again.
bool FrictionArg::unchanged(PyObject* obj) const {
  PyObject* dict = instanceDict(obj);
  if (dict == nullptr) return false;
  for (int k = 0; k < 6; ++k)
    if (PyDict_GetItem(dict, attrName(k)) != cache_attrs_[k].ptr()) return false;
  return true;
}

const vereshchagin::FrictionModel* FrictionArg::parse(PyObject* obj, unsigned int nj,
                                                      vereshchagin::FrictionModel& scratch) {
  if (obj == nullptr || obj == Py_None || PyBool_Check(obj)) return obj == Py_True ? &model_values_ : nullptr;
  static py::object friction_type = py::module_::import("vereshchagin.friction").attr("Friction");
  const bool cacheable = Py_TYPE(obj) == reinterpret_cast<PyTypeObject*>(friction_type.ptr());
  if (cacheable && cache_key_.ptr() == obj && unchanged(obj)) return &cache_;
  const py::object static_obj = py::reinterpret_steal<py::object>(PyObject_GetAttrString(obj, "static"));
  if (!static_obj) {
    if (!PyErr_ExceptionMatches(PyExc_AttributeError)) throw py::error_already_set();  // e.g. a property raised
    PyErr_Clear();
    raise("friction must be None, True or a vereshchagin.Friction(static=..., kinetic=..., velocity_tolerance=...)");
  }
  vereshchagin::FrictionModel& fm = cacheable ? cache_ : scratch;
  if (cacheable) cache_key_ = py::object();  // invalid until parsed
  const py::object none = py::none(), kin = py::getattr(obj, "kinetic", none), lower = py::getattr(obj, "lower", none),
                   upper = py::getattr(obj, "upper", none);
  const bool limits = !lower.is_none() || !upper.is_none();
  auto view = [](const py::object& o, const char* name) { return o.is_none() ? F64View() : asF64(o.ptr(), name); };
  const F64View st = asF64(static_obj.ptr(), "friction.static"), kv = view(kin, "friction.kinetic"),
                lo = view(lower, "friction.lower"), up = view(upper, "friction.upper");
  const vereshchagin::FrictionModel defaults;
  const double vt = scalarAttr(obj, "velocity_tolerance", "friction.velocity_tolerance", defaults.velocity_tolerance);
  const double lt =
      limits ? scalarAttr(obj, "limit_tolerance", "friction.limit_tolerance", defaults.limit_tolerance) : 0.0;
  check(vereshchagin::frictionFromArrays(fm, nj, st, kin.is_none() ? nullptr : &kv, vt, lower.is_none() ? nullptr : &lo,
                                         upper.is_none() ? nullptr : &up, lt));
  PyObject* dict = cacheable ? instanceDict(obj) : nullptr;
  if (dict == nullptr) return &fm;  // not cached
  for (int k = 0; k < 6; ++k) cache_attrs_[k] = py::reinterpret_borrow<py::object>(PyDict_GetItem(dict, attrName(k)));
  cache_key_ = py::reinterpret_borrow<py::object>(obj);
  return &fm;
}

// friction: one for every row, or in a batch a list or tuple of one per row.
void SolveArgs::parseFriction(FrictionArg& parser, PyObject* obj) {
  input.friction.clear();
  any_friction = false;
  if (!batched() || !(PyList_Check(obj) || PyTuple_Check(obj))) {
    if (const vereshchagin::FrictionModel* fm = parser.parse(obj, nj_, friction_scratch_)) input.friction.push_back(fm);
    any_friction = !input.friction.empty();
    return;
  }
  const Py_ssize_t n = PySequence_Fast_GET_SIZE(obj);
  check(batchAxis(n, "friction", "(a sequence of " + std::to_string(n) + ")"));
  friction_models_.resize(static_cast<std::size_t>(n));
  for (Py_ssize_t b = 0; b < n; ++b) {
    vereshchagin::FrictionModel& fm = friction_models_[b];
    const vereshchagin::FrictionModel* p = nullptr;
    try {
      p = parser.parse(PySequence_Fast_GET_ITEM(obj, b), nj_, fm);
    } catch (const SolverError& e) {
      raise("friction[" + std::to_string(b) + "]: " + e.what());
    }
    if (p != nullptr && p != &fm) fm = *p;  // the cache or the model's values: the next row may change them
    input.friction.push_back(p ? &fm : nullptr);
    any_friction |= p != nullptr;
  }
}

void SolveArgs::parse(PySolver& s, PyObject* const* a, bool batch) {
  start(batch, s.cppModel());
  nj_ = s.nj;
  ns_ = s.ns;
  addressing_ = s.addressing;
  keys.clear();
  starts.clear();
  keep_.clear();
  if (a[0] == nullptr || a[1] == nullptr) raise("solve() needs q and qd");
  input.q = vector(a[0], "q", nj_);
  input.q_dot = vector(a[1], "qd", nj_);
  PyObject* a_desired = given(a[kADesiredArg]) ? a[kADesiredArg] : nullptr;
  if (given(a[2])) {
    if (s.isTree()) raise(kTreeAlpha);
    if (a_desired && given(a[3]))
      raise("beta and a_desired given: a_desired (the tip's classical acceleration) replaces beta");
    addBlock(static_cast<int>(ns_) - 1, a[2],
             a_desired     ? a_desired
             : given(a[3]) ? a[3]
                           : nullptr,
             "", a_desired != nullptr);
    if (input.blocks.back().columns == 0) input.blocks.pop_back();  // no columns: nothing to constrain
  } else if (given(a[3]) || a_desired) {
    raise(std::string(a_desired ? "a_desired" : "beta") + " given without alpha");
  }
  if (given(a[4])) parseFExt(a[4]);
  if (given(a[5])) input.ff_torques = vector(a[5], "tau_ff", nj_);
  if (given(a[7])) parseConstraints(a[7]);
  parseFriction(s.friction, a[6]);
  // Pass-through weights: one per constraint column (their range: checked by vereshchagin::solve).
  if (given(a[8])) input.f_ext_pass_through = vector(a[8], "f_ext_pass_through", columns, /*scalar_ok=*/true);
  if (given(a[9])) input.ff_pass_through = vector(a[9], "tau_ff_pass_through", columns, /*scalar_ok=*/true);
}

}  // namespace vsbind
