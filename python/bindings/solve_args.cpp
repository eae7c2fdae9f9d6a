// The one parser of Solver.solve's and Solver.solve_batch's arguments (SolveArgs, py_solver.hpp):
// each argument's shape is checked once into rows with a stride of a vereshchagin::BatchInput (0:
// shared by every row; solve() is the one-row case that accepts no batch axis).
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

std::string keyLabel(const char* what, PyObject* key) {
  return std::string(what) + "[" + py::repr(key).cast<std::string>() + "]";
}

// "6, 2" for {6, 2}: the shape one row must have.
std::string shapeText(int ndim, const py::ssize_t* shape) {
  std::string s;
  for (int k = 0; k < ndim; ++k) s += (k ? ", " : "") + std::to_string(shape[k]);
  return ndim == 1 ? s + "," : s;
}

vereshchagin::Vector3 point(const KDL::Vector& p) {
  return vereshchagin::Vector3(p.x(), p.y(), p.z());
}

}  // namespace

void SolveArgs::batchAxis(py::ssize_t n, const char* name, const std::string& shape) {
  if (first_.empty()) {
    input.rows = n;
    first_ = std::string(name) + " " + shape;
  } else if (n != input.rows) {
    raise(std::string(name) + " has a batch axis (axis 0) of " + std::to_string(n) + " rows (shape " + shape +
          "), but " + first_ + " has " + std::to_string(input.rows));
  }
}

// `v` as rows of `shape` (ndim dimensions), in a batch also with a leading batch axis; finite.
Rows SolveArgs::arg(const char* name, F64View v, int ndim, const py::ssize_t* shape, Hint hint) {
  const int batched = batch_ && v.ndim == ndim + 1;
  bool fits = v.ndim == ndim + batched;
  for (int k = 0; fits && k < ndim; ++k) fits = v.shape[k + batched] == shape[k];
  if (!fits) {
    const std::string expect = hint == kAlphaHint ? "6, m" : shapeText(ndim, shape);
    raise(std::string(name) + " must have shape (" + expect + ")" +
          (batch_ ? " (shared by all rows) or (B, " + expect + ") (one per row)" : "") +
          (hint == kAlphaHint ? " (columns: unit wrenches [force; moment]) or (6,) for one column, got " : "") +
          (hint == kFExtHint ? ": one row [fx, fy, fz, mx, my, mz] per segment (base axes, moment about the "
                               "segment's tip origin), or a dict {segment: wrench (6,)}; got "
                             : "") +
          (hint == kNoHint ? ", got " : "") + v.shapeString());
  }
  Rows r{v.data, 0};
  if (batched) {
    r.stride = 1;
    for (int k = 0; k < ndim; ++k) r.stride *= shape[k];
    batchAxis(v.shape[0], name, v.shapeString());
  }
  const py::ssize_t n = v.size(), per_row = r.stride ? r.stride : n;
  for (py::ssize_t k = 0; k < n; ++k)
    if (!std::isfinite(v.data[k]))
      raise((batched ? "batch row " + std::to_string(k / per_row) + ": " : std::string()) + name +
            " contains NaN or Inf (flat index " + std::to_string(k % per_row) + ")");
  if (v.keep) keep_.push_back(std::move(v.keep));
  return r;
}

// An (n,) vector per row; with scalar_ok and n == 1 also a scalar (or (B,) in a batch).
Rows SolveArgs::vector(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok) {
  F64View v = asF64(obj, name);
  if (scalar_ok && n == 1 && v.ndim == 0) {
    v.ndim = 1;
    v.shape[0] = 1;
  } else if (scalar_ok && n == 1 && batch_ && v.ndim == 1 && v.shape[0] != 1) {
    v.ndim = 2;
    v.shape[1] = 1;
  }
  return arg(name, std::move(v), 1, &n);
}

// A block of alpha and beta (label: "" for solve's alpha/beta, else "constraints[key]").
void SolveArgs::addBlock(int segment, PyObject* alpha, PyObject* beta, const std::string& label, PyObject* classical) {
  const std::string an = label.empty() ? "" : label + " alpha", bn = label.empty() ? "" : label + " beta";
  const char *a_name = label.empty() ? "alpha" : an.c_str(), *b_name = label.empty() ? "beta" : bn.c_str();
  F64View a = asF64(alpha, a_name);
  if (a.ndim == 1 && a.shape[0] == 6) {  // one column
    a.ndim = 2;
    a.shape[1] = 1;
  }
  const py::ssize_t m = a.ndim >= 2 ? a.shape[a.ndim - 1] : -1, shape[2] = {6, m};
  if (m > 6) raise(a_name + std::string(" has ") + std::to_string(m) + " columns; at most 6 constraints per segment");
  vereshchagin::BlockRows& blk = input.blocks.emplace_back();
  blk.segment = segment;
  blk.columns = static_cast<int>(m);
  blk.alpha = arg(a_name, std::move(a), 2, shape, kAlphaHint);
  if (classical != nullptr) {  // task.py's wording: Task.solve passes its a_desired here
    F64View v = asF64(classical, "a_desired");
    for (py::ssize_t k = 0; k < v.size(); ++k)
      if (!std::isfinite(v.data[k])) raise("a_desired must be finite (no NaN or Inf), flat index " + std::to_string(k));
    const py::ssize_t six = 6;
    blk.classical = arg("a_desired", std::move(v), 1, &six);
  } else {
    if (beta == nullptr) raise("beta is required when alpha is given (shape (" + std::to_string(m) + ",))");
    blk.beta = vector(beta, b_name, m, /*scalar_ok=*/true);
  }
  columns += blk.columns;
  if (label.empty()) return;  // solve's alpha: counted when constraints= is parsed
  segment_cols_[segment] += blk.columns;
  if (segment_cols_[segment] > 6)
    raise(label + ": more than 6 constraint columns on segment '" + addressing_->segmentName(segment) +
          "' (alpha and every key on it count)");
}

// f_ext: (n_segments, 6) rows [force, moment] (base axes, moment about each tip origin), or a
// dict {segment or link: (6,) wrench}, the moment about that frame's origin.
void SolveArgs::parseFExt(PyObject* obj) {
  if (!PyDict_Check(obj)) {
    const py::ssize_t shape[2] = {ns_, 6};
    input.f_ext = arg("f_ext", asF64(obj, "f_ext"), 2, shape, kFExtHint);
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
  std::vector<vereshchagin::BlockRows>& blocks = input.blocks;
  segment_cols_.assign(ns_, 0);
  if (blocks.size() == 1 && blocks[0].segment >= 0) segment_cols_[blocks[0].segment] = blocks[0].columns;
  frames_.clear();
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = keyLabel("constraints", key);
    const FrameTarget t = addressing_->resolveMoving(key, label);
    for (std::size_t k = 0; k < keys.size(); ++k)
      if (blocks[blocks.size() - keys.size() + k].segment == t.segment && (frames_[k] - t.link_in_tip.p).Norm() == 0.0)
        raise(label + ": the same frame as " + keyLabel("constraints", keys[k].ptr()) +
              " (one entry per frame: put all its columns in one alpha)");
    if ((!PyTuple_Check(value) && !PyList_Check(value)) || PySequence_Fast_GET_SIZE(value) != 2)
      raise(label + " must be a pair (alpha " +
            (batch_ ? "(6, m_i) or (B, 6, m_i), beta (m_i,) or (B, m_i))" : "(6, m_i), beta (m_i,))"));
    keys.push_back(py::reinterpret_borrow<py::object>(key));
    starts.push_back(columns);
    frames_.push_back(t.link_in_tip.p);
    addBlock(t.segment, PySequence_Fast_GET_ITEM(value, 0), PySequence_Fast_GET_ITEM(value, 1), label);
    if (t.merged) blocks.back().point = point(t.link_in_tip.p);
  }
}

// friction: one for every row, or in a batch a list or tuple of one per row.
void SolveArgs::parseFriction(FrictionArg& parser, PyObject* obj) {
  input.friction.clear();
  any_friction = false;
  if (!batch_ || !(PyList_Check(obj) || PyTuple_Check(obj))) {
    if (const vereshchagin::FrictionModel* fm = parser.parse(obj, nj_, friction_scratch_)) input.friction.push_back(fm);
    any_friction = !input.friction.empty();
    return;
  }
  const Py_ssize_t n = PySequence_Fast_GET_SIZE(obj);
  batchAxis(n, "friction", "(a sequence of " + std::to_string(n) + ")");
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
  batch_ = batch;
  nj_ = s.nj;
  ns_ = s.ns;
  addressing_ = s.addressing;
  input.rows = 1;
  input.f_ext = input.ff_torques = input.f_ext_pass_through = input.ff_pass_through = Rows();
  input.blocks.clear();
  input.wrenches.clear();
  columns = 0;
  first_.clear();
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
    addBlock(static_cast<int>(ns_) - 1, a[2], given(a[3]) ? a[3] : nullptr, "", a_desired);
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
