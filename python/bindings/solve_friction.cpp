// friction= of Solver.solve and solve_batch (FrictionArg, py_solver.hpp): the attributes viewed as
// arrays, their shapes checked by vereshchagin::frictionFromArrays with the Python names
// (friction.static, friction.kinetic, friction.lower / upper), values by vereshchagin::solve with
// the same names; a vereshchagin.Friction is parsed once and reused while its attributes are the
// same objects.
#include "py_solver.hpp"

namespace vsbind {

namespace {

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

void check(const std::string& why) {
  if (!why.empty()) raise(why);
}

double scalarAttr(PyObject* fr, const char* attr, const char* name, double fallback) {
  const py::object obj = py::getattr(fr, attr, py::none());
  return obj.is_none() ? fallback : scalarArg(obj, name);
}

}  // namespace

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

}  // namespace vsbind
