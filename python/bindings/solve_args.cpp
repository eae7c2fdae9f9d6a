// Parsing of Solver.solve's arguments into a ParsedSolve: shapes, dtypes and values checked with
// messages that name the argument; nothing is copied that the solve can read in place.
#include <algorithm>
#include <limits>

#include "friction_args.hpp"
#include "py_solver.hpp"

namespace vsbind {

void ParsedSolve::clear() {
  q = qd = alpha = beta = f_ext = tau = f_ext_pass_through = tau_ff_pass_through = F64View();
  block_views.clear();
  blocks.clear();
  block_keys.clear();
  f_ext_dense.clear();  // keeps its capacity: no allocation in a control loop
  link_wrenches.clear();
  friction_owner = py::object();
  friction = nullptr;
  row = RowInputs();
}

F64View alphaView(PyObject* obj, const std::string& name) {
  F64View a = asF64(obj, name.c_str());
  if (a.ndim == 1 && a.shape[0] == 6) {  // one column
    a.ndim = 2;
    a.shape[1] = 1;
  }
  if (a.ndim != 2 || a.shape[0] != 6)
    raise(name + " must have shape (6, m) (columns: unit wrenches [force; moment]) or (6,) for one column, got " +
          a.shapeString());
  if (a.shape[1] > 6)
    raise(name + " has " + std::to_string(a.shape[1]) + " columns; at most 6 constraints per segment");
  requireFiniteView(a, name.c_str());
  return a;
}

namespace {

bool given(PyObject* obj) {
  return obj != nullptr && obj != Py_None;
}

std::string keyRepr(PyObject* key) {
  return py::repr(key).cast<std::string>();
}

}  // namespace

vereshchagin::InertiaCheck inertiaCheckArg(const std::string& value, const std::string& where) {
  if (value == "physical") return vereshchagin::InertiaCheck::Physical;
  if (value == "joint_space") return vereshchagin::InertiaCheck::JointSpace;
  raise(where +
        "inertia_check must be 'physical' (every body a rigid body) or 'joint_space' (identified models: "
        "any symmetric inertia, H(q) positive definite at each solve), got '" +
        value + "'");
}

void checkWeights(const double* w, py::ssize_t m, const std::string& name) {
  for (py::ssize_t c = 0; c < m; ++c)
    if (!(w[c] >= 0.0 && w[c] <= 1.0))
      raise(name + "[" + std::to_string(c) +
            "] must be in [0, 1] (0: the constraint compensates that driver, 1: "
            "its effect passes through), got " +
            fmtDouble(w[c]));
}

void PySolver::checkColumnCount(py::ssize_t columns) const {
  if (columns > max_columns_)
    raise("this solve has " + std::to_string(columns) + " constraint columns; the solver takes at most " +
          std::to_string(max_columns_) +
          " in all (6 per segment, and Solver(..., max_constraints=) sizes its workspace)");
}

void PySolver::parse(PyObject* const* a, ParsedSolve& p) {
  PyObject *q = a[0], *qd = a[1], *alpha = a[2], *beta = a[3], *f_ext = a[4], *tau_ff = a[5], *friction = a[6],
           *constraints = a[7];
  p.clear();
  if (q == nullptr || qd == nullptr) raise("solve() needs q and qd");
  p.q = vectorView(q, "q", nj);
  p.qd = vectorView(qd, "qd", nj);
  if (given(alpha)) {
    if (tree_) raise(kTreeAlpha);
    p.alpha = alphaView(alpha, "alpha");
    const py::ssize_t m = p.alpha.shape[1];
    if (!given(beta)) raise("beta is required when alpha is given (shape (" + std::to_string(m) + ",))");
    p.beta = vectorView(beta, "beta", m, /*scalar_ok=*/true);
    if (m > 0) {
      ConstraintBlock b;
      b.segment = static_cast<int>(ns) - 1;
      b.cols = static_cast<int>(m);
      b.alpha = p.alpha.data;
      b.beta = p.beta.data;
      p.blocks.push_back(b);
    }
  } else if (given(beta)) {
    raise("beta given without alpha");
  }
  if (given(f_ext)) parseFExt(f_ext, p);
  if (given(tau_ff)) p.tau = vectorView(tau_ff, "tau_ff", nj);
  if (given(constraints)) parseConstraints(constraints, p);
  parseFriction(friction, p);
  py::ssize_t columns = 0;
  for (const ConstraintBlock& b : p.blocks) columns += b.cols;
  checkColumnCount(columns);
  const char* weight_names[2] = {"f_ext_pass_through", "tau_ff_pass_through"};
  F64View* weights[2] = {&p.f_ext_pass_through, &p.tau_ff_pass_through};
  for (int k = 0; k < 2; ++k) {
    if (!given(a[8 + k])) continue;
    *weights[k] = vectorView(a[8 + k], weight_names[k], columns, /*scalar_ok=*/true);
    checkWeights(weights[k]->data, columns, weight_names[k]);
  }
  RowInputs& r = p.row;
  r.q = p.q.data;
  r.qd = p.qd.data;
  r.blocks = p.blocks.data();
  r.n_blocks = static_cast<int>(p.blocks.size());
  r.f_ext = p.f_ext.data;
  if (!p.f_ext_dense.empty() && p.f_ext.data == nullptr) r.f_ext = p.f_ext_dense.data();
  r.link_wrenches = p.link_wrenches.data();
  r.n_link_wrenches = static_cast<int>(p.link_wrenches.size());
  r.tau_ff = p.tau.data;
  r.friction = p.friction;
  r.f_ext_pass_through = p.f_ext_pass_through.data;
  r.tau_ff_pass_through = p.tau_ff_pass_through.data;
}

// f_ext: (n_segments, 6) rows [force, moment] (base axes, moment about each tip origin), or a
// dict {segment or link: (6,) wrench}, the moment about that frame's origin.
void PySolver::parseFExt(PyObject* f_ext, ParsedSolve& p) const {
  if (!PyDict_Check(f_ext)) {
    p.f_ext = asF64(f_ext, "f_ext");
    if (p.f_ext.ndim != 2 || p.f_ext.shape[0] != static_cast<py::ssize_t>(ns) || p.f_ext.shape[1] != 6)
      raise("f_ext must have shape (" + std::to_string(ns) +
            ", 6): one row [fx, fy, fz, mx, my, mz] per segment (base axes, moment about the segment's tip "
            "origin), or a dict {segment: wrench (6,)}; got " +
            p.f_ext.shapeString());
    requireFiniteView(p.f_ext, "f_ext");
    return;
  }
  p.f_ext_dense.assign(6 * ns, 0.0);
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(f_ext, &pos, &key, &value)) {
    const std::string label = "f_ext[" + keyRepr(key) + "]";
    const FrameTarget t = model_->resolveMoving(key, label);
    F64View w = vectorView(value, label.c_str(), 6);
    if (t.merged) {
      LinkWrench lw;
      lw.segment = t.segment;
      lw.offset = t.link_in_tip.p;
      lw.wrench = w.data;
      p.link_wrenches.push_back(lw);
      p.block_views.push_back(std::move(w));
      continue;
    }
    for (int k = 0; k < 6; ++k) p.f_ext_dense[6 * t.segment + k] += w.data[k];
  }
}

ConstraintKeys::ConstraintKeys(const Addressable& model, int n_segments, int alpha_columns)
    : model_(model), per_segment_(n_segments, 0) {
  if (alpha_columns > 0) per_segment_[n_segments - 1] = alpha_columns;
}

FrameTarget ConstraintKeys::resolve(PyObject* key, const std::string& label) {
  const FrameTarget t = model_.resolveMoving(key, label);
  for (std::size_t k = 0; k < targets_.size(); ++k)
    if (targets_[k].segment == t.segment && (targets_[k].link_in_tip.p - t.link_in_tip.p).Norm() == 0.0)
      raise(label + ": the same frame as constraints[" + keyRepr(keys_[k].ptr()) +
            "] (one entry per frame: put all its columns in one alpha)");
  targets_.push_back(t);
  keys_.push_back(py::reinterpret_borrow<py::object>(key));
  return t;
}

void ConstraintKeys::count(int segment, int cols, const std::string& label) {
  per_segment_[segment] += cols;
  if (per_segment_[segment] > 6)
    raise(label + ": more than 6 constraint columns on segment '" + model_.segmentName(segment) +
          "' (alpha and every key on it count)");
}

std::pair<PyObject*, PyObject*> ConstraintKeys::pair(PyObject* value, const std::string& label,
                                                     const std::string& shapes) {
  if ((!PyTuple_Check(value) && !PyList_Check(value)) || PySequence_Fast_GET_SIZE(value) != 2)
    raise(label + " must be a pair (alpha " + shapes + ")");
  return {PySequence_Fast_GET_ITEM(value, 0), PySequence_Fast_GET_ITEM(value, 1)};
}

void PySolver::parseConstraints(PyObject* constraints, ParsedSolve& p) const {
  if (!PyDict_Check(constraints))
    raise("constraints must be a dict {segment name or index: (alpha (6, m_i), beta (m_i,))}");
  p.block_views.reserve(p.block_views.size() + 2 * PyDict_Size(constraints));
  ConstraintKeys keys(*model_, static_cast<int>(ns), p.blocks.empty() ? 0 : p.blocks[0].cols);
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(constraints, &pos, &key, &value)) {
    const std::string label = "constraints[" + keyRepr(key) + "]";
    const FrameTarget t = keys.resolve(key, label);
    const auto [alpha, beta] = ConstraintKeys::pair(value, label, "(6, m_i), beta (m_i,)");
    F64View a = alphaView(alpha, label + " alpha");
    F64View b = vectorView(beta, (label + " beta").c_str(), a.shape[1], /*scalar_ok=*/true);
    keys.count(t.segment, static_cast<int>(a.shape[1]), label);
    ConstraintBlock blk;
    blk.segment = t.segment;
    blk.cols = static_cast<int>(a.shape[1]);
    blk.alpha = a.data;
    blk.beta = b.data;
    blk.offset = t.link_in_tip.p;
    blk.has_offset = t.merged;
    p.blocks.push_back(blk);
    p.block_views.push_back(std::move(a));
    p.block_views.push_back(std::move(b));
  }
  p.block_keys = keys.keys();
}

namespace {

// The attributes of a vereshchagin.Friction, in the order of PySolver::friction_cache_attrs_.
PyObject* frictionAttrName(int k) {
  static PyObject* names[6] = {PyUnicode_InternFromString("static"),
                               PyUnicode_InternFromString("kinetic"),
                               PyUnicode_InternFromString("velocity_tolerance"),
                               PyUnicode_InternFromString("lower"),
                               PyUnicode_InternFromString("upper"),
                               PyUnicode_InternFromString("limit_tolerance")};
  return names[k];
}

// The instance dict of a vereshchagin.Friction (a dataclass: its fields live there).
PyObject* instanceDict(PyObject* obj) {
  PyObject** dict = _PyObject_GetDictPtr(obj);
  return dict == nullptr ? nullptr : *dict;
}

}  // namespace

// True while the cached Friction still holds the very attribute objects it was parsed from. Its
// arrays are read-only views of immutable bytes (friction.py), so the same objects mean the same
// values; an attribute replaced (object.__setattr__) makes the next solve parse it again.
bool PySolver::frictionUnchanged(PyObject* friction) const {
  PyObject* dict = instanceDict(friction);
  if (dict == nullptr) return false;
  for (int k = 0; k < 6; ++k)
    if (PyDict_GetItem(dict, frictionAttrName(k)) != friction_cache_attrs_[k].ptr()) return false;
  return true;
}

void PySolver::rememberFriction(PyObject* friction) {
  PyObject* dict = instanceDict(friction);
  if (dict == nullptr) return;  // not cached
  for (int k = 0; k < 6; ++k)
    friction_cache_attrs_[k] = py::reinterpret_borrow<py::object>(PyDict_GetItem(dict, frictionAttrName(k)));
  friction_cache_key_ = py::reinterpret_borrow<py::object>(friction);
}

// friction: None/False (frictionless), True (the chain's values: static friction, limits), a
// vereshchagin.Friction (immutable: parsed once and reused while its attributes are the same
// objects) or any object with the same attributes (parsed every call).
bool PySolver::parseFriction(PyObject* friction, ParsedSolve& p) {
  if (!given(friction) || friction == Py_False) return false;
  if (friction == Py_True) {
    p.friction = &chain_friction_;
    return true;
  }
  if (PyBool_Check(friction)) return false;
  static py::object friction_type = py::module_::import("vereshchagin.friction").attr("Friction");
  const bool cacheable = Py_TYPE(friction) == reinterpret_cast<PyTypeObject*>(friction_type.ptr());
  if (cacheable && friction_cache_key_.ptr() == friction && frictionUnchanged(friction)) {
    p.friction = &friction_cache_;
    return true;
  }
  py::handle fr(friction);
  const py::object static_obj = py::reinterpret_steal<py::object>(PyObject_GetAttrString(friction, "static"));
  if (!static_obj) {
    if (!PyErr_ExceptionMatches(PyExc_AttributeError)) throw py::error_already_set();  // e.g. a property raised
    PyErr_Clear();
    raise("friction must be None, True or a vereshchagin.Friction(static=..., kinetic=..., velocity_tolerance=...)");
  }
  vereshchagin::FrictionModel& fm = cacheable ? friction_cache_ : p.friction_model;
  F64View fs = vectorView(static_obj.ptr(), "friction.static", nj);
  fm.static_friction = Eigen::Map<const Eigen::VectorXd>(fs.data, nj);
  const py::object kin = py::getattr(fr, "kinetic", py::none());
  if (kin.is_none()) {
    fm.kinetic_friction.resize(0);
  } else {
    F64View fk = vectorView(kin.ptr(), "friction.kinetic", nj);
    fm.kinetic_friction = Eigen::Map<const Eigen::VectorXd>(fk.data, nj);
  }
  const py::object tol = py::getattr(fr, "velocity_tolerance", py::none());
  fm.velocity_tolerance =
      tol.is_none() ? vereshchagin::FrictionModel().velocity_tolerance : scalarArg(tol, "friction.velocity_tolerance");
  const py::object lower = py::getattr(fr, "lower", py::none()), upper = py::getattr(fr, "upper", py::none());
  fm.lower.resize(0);
  fm.upper.resize(0);
  if (!lower.is_none() || !upper.is_none()) {
    fm.lower = Eigen::VectorXd::Constant(nj, -std::numeric_limits<double>::infinity());
    fm.upper = Eigen::VectorXd::Constant(nj, std::numeric_limits<double>::infinity());
    auto limitArg = [&](const py::object& obj, const char* name, Eigen::VectorXd& out) {
      if (obj.is_none()) return;
      F64View a = asF64(obj.ptr(), name);
      if (a.ndim != 1 || a.shape[0] != static_cast<py::ssize_t>(nj))
        raise(std::string(name) + " must have shape (" + std::to_string(nj) + ",), got " + a.shapeString());
      for (unsigned int j = 0; j < nj; ++j) {
        if (std::isnan(a.data[j])) raise(std::string(name) + " contains NaN");
        out(j) = a.data[j];
      }
    };
    limitArg(lower, "friction.lower", fm.lower);
    limitArg(upper, "friction.upper", fm.upper);
    const py::object ltol = py::getattr(fr, "limit_tolerance", py::none());
    fm.limit_tolerance =
        ltol.is_none() ? vereshchagin::FrictionModel().limit_tolerance : scalarArg(ltol, "friction.limit_tolerance");
  }
  if (cacheable) friction_cache_key_ = py::object();  // invalid until checked
  checkFriction(fm);
  if (cacheable) rememberFriction(friction);
  p.friction = &fm;
  return true;
}

}  // namespace vsbind
