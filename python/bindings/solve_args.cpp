// The one parser of Solver.solve's and Solver.solve_batch's arguments (SolveArgs, py_solver.hpp):
// each argument is checked once into rows with a stride (0: shared by every row; solve() is the
// one-row case that accepts no batch axis), and fillRow writes row b straight into a SolveInput.
#include "py_solver.hpp"

namespace vsbind {

namespace {

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
    rows = n;
    first_ = std::string(name) + " " + shape;
  } else if (n != rows) {
    raise(std::string(name) + " has a batch axis (axis 0) of " + std::to_string(n) + " rows (shape " + shape +
          "), but " + first_ + " has " + std::to_string(rows));
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

// Pass-through weights: one per constraint column, each in [0, 1].
Rows SolveArgs::weights(PyObject* obj, const char* name) {
  if (!given(obj)) return Rows();
  const Rows w = vector(obj, name, columns, /*scalar_ok=*/true);
  for (py::ssize_t b = 0; b < (w.stride ? rows : 1); ++b)
    for (int c = 0; c < columns; ++c)
      if (const double x = w.row(b)[c]; !(x >= 0.0 && x <= 1.0))
        raise((w.stride ? "batch row " + std::to_string(b) + ": " : std::string()) + name + "[" + std::to_string(c) +
              "] must be in [0, 1] (0: the constraint compensates that driver, 1: its effect passes through), got " +
              fmtDouble(x));
  return w;
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
  BlockArg& blk = blocks.emplace_back();
  blk.segment = segment;
  blk.cols = static_cast<int>(m);
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
  columns += blk.cols;
  if (label.empty()) return;  // solve's alpha: counted when constraints= is parsed
  segment_cols_[segment] += blk.cols;
  if (segment_cols_[segment] > 6)
    raise(label + ": more than 6 constraint columns on segment '" + addressing_->segmentName(segment) +
          "' (alpha and every key on it count)");
}

// f_ext: (n_segments, 6) rows [force, moment] (base axes, moment about each tip origin), or a
// dict {segment or link: (6,) wrench}, the moment about that frame's origin.
void SolveArgs::parseFExt(PyObject* obj) {
  if (!PyDict_Check(obj)) {
    const py::ssize_t shape[2] = {ns_, 6};
    f_ext_ = arg("f_ext", asF64(obj, "f_ext"), 2, shape, kFExtHint);
    return;
  }
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = keyLabel("f_ext", key);
    const FrameTarget t = addressing_->resolveMoving(key, label);
    WrenchArg& w = wrenches_.emplace_back();
    w.segment = t.segment;
    w.merged = t.merged;
    w.point = point(t.link_in_tip.p);
    w.wrench = vector(value, label.c_str(), 6);
  }
}

// constraints: {segment or link: (alpha (6, m_i), beta (m_i,))}, one entry per frame.
void SolveArgs::parseConstraints(PyObject* obj) {
  if (!PyDict_Check(obj)) raise("constraints must be a dict {segment name or index: (alpha (6, m_i), beta (m_i,))}");
  const std::size_t first = blocks.size();
  segment_cols_.assign(ns_, 0);
  if (first == 1 && blocks[0].segment >= 0) segment_cols_[blocks[0].segment] = blocks[0].cols;
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = keyLabel("constraints", key);
    const FrameTarget t = addressing_->resolveMoving(key, label);
    for (std::size_t k = first; k < blocks.size(); ++k)
      if (blocks[k].segment == t.segment && (blocks[k].frame - t.link_in_tip.p).Norm() == 0.0)
        raise(label + ": the same frame as " + keyLabel("constraints", keys[k - first].ptr()) +
              " (one entry per frame: put all its columns in one alpha)");
    if ((!PyTuple_Check(value) && !PyList_Check(value)) || PySequence_Fast_GET_SIZE(value) != 2)
      raise(label + " must be a pair (alpha " +
            (batch_ ? "(6, m_i) or (B, 6, m_i), beta (m_i,) or (B, m_i))" : "(6, m_i), beta (m_i,))"));
    keys.push_back(py::reinterpret_borrow<py::object>(key));
    starts.push_back(columns);
    addBlock(t.segment, PySequence_Fast_GET_ITEM(value, 0), PySequence_Fast_GET_ITEM(value, 1), label);
    blocks.back().frame = t.link_in_tip.p;
    if (t.merged) blocks.back().point = point(t.link_in_tip.p);
  }
}

// friction: one for every row, or in a batch a list or tuple of one per row.
void SolveArgs::parseFriction(FrictionArg& parser, PyObject* obj) {
  row_friction_.clear();
  any_friction = false;
  if (!batch_ || !(PyList_Check(obj) || PyTuple_Check(obj))) {
    friction_ = parser.parse(obj, nj_, friction_scratch_);
    any_friction = friction_ != nullptr;
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
    row_friction_.push_back(p ? &fm : nullptr);
    any_friction |= p != nullptr;
  }
}

void SolveArgs::parse(PySolver& s, PyObject* const* a, bool batch) {
  batch_ = batch;
  nj_ = s.nj;
  ns_ = s.ns;
  addressing_ = s.addressing;
  rows = 1;
  columns = 0;
  first_.clear();
  blocks.clear();
  keys.clear();
  starts.clear();
  wrenches_.clear();
  keep_.clear();
  f_ext_ = tau_ = f_ext_pass_ = tau_pass_ = Rows();
  if (a[0] == nullptr || a[1] == nullptr) raise("solve() needs q and qd");
  q_ = vector(a[0], "q", nj_);
  qd_ = vector(a[1], "qd", nj_);
  PyObject* a_desired = given(a[kADesiredArg]) ? a[kADesiredArg] : nullptr;
  if (given(a[2])) {
    if (s.isTree()) raise(kTreeAlpha);
    if (a_desired && given(a[3]))
      raise("beta and a_desired given: a_desired (the tip's classical acceleration) replaces beta");
    addBlock(static_cast<int>(ns_) - 1, a[2], given(a[3]) ? a[3] : nullptr, "", a_desired);
    if (blocks.back().cols == 0) blocks.pop_back();  // no columns: nothing to constrain
  } else if (given(a[3]) || a_desired) {
    raise(std::string(a_desired ? "a_desired" : "beta") + " given without alpha");
  }
  if (given(a[4])) parseFExt(a[4]);
  if (given(a[5])) tau_ = vector(a[5], "tau_ff", nj_);
  if (given(a[7])) parseConstraints(a[7]);
  parseFriction(s.friction, a[6]);
  if (columns > s.max_columns)
    raise("this solve has " + std::to_string(columns) + " constraint columns; the solver takes at most " +
          std::to_string(s.max_columns) +
          " in all (6 per segment, and Solver(..., max_constraints=) sizes its workspace)");
  f_ext_pass_ = weights(a[8], "f_ext_pass_through");
  tau_pass_ = weights(a[9], "tau_ff_pass_through");
}

void SolveArgs::fillRow(py::ssize_t b, vereshchagin::SolveInput& in) const {
  using MapV = Eigen::Map<const Eigen::VectorXd>;
  in.clear();
  in.q = MapV(q_.row(b), nj_);
  in.q_dot = MapV(qd_.row(b), nj_);
  if (f_ext_.data) in.f_ext = Eigen::Map<const vereshchagin::Matrix6X>(f_ext_.row(b), 6, ns_);  // (ns, 6) rows
  for (const WrenchArg& w : wrenches_) {
    const Eigen::Map<const vereshchagin::Vector6> wrench(w.wrench.row(b));
    if (!w.merged) {
      in.f_ext.col(w.segment) += wrench;
      continue;
    }
    vereshchagin::FrameWrench& out = in.wrenches.emplace_back();
    out.segment = w.segment;
    out.wrench = wrench;
    out.point = w.point;
  }
  if (tau_.data) in.ff_torques = MapV(tau_.row(b), nj_);
  in.friction = friction(b);
  const double* f_pass = f_ext_pass_.data ? f_ext_pass_.row(b) : nullptr;
  const double* t_pass = tau_pass_.data ? tau_pass_.row(b) : nullptr;
  int col = 0;
  for (const BlockArg& blk : blocks) {
    if (blk.segment < 0) {  // alpha on the last segment of a chain without segments: nothing can move
      col += blk.cols;
      continue;
    }
    vereshchagin::ConstraintBlock& out = in.constraints.emplace_back();
    out.segment = blk.segment;
    out.columns = blk.cols;
    out.point = blk.point;
    out.classical = blk.classical.data != nullptr;
    if (out.classical) out.classical_acceleration = Eigen::Map<const vereshchagin::Vector6>(blk.classical.row(b));
    const double *alpha = blk.alpha.row(b), *beta = out.classical ? nullptr : blk.beta.row(b);
    for (int c = 0; c < blk.cols; ++c, ++col) {
      for (int r = 0; r < 6; ++r) out.alfa(r, c) = alpha[r * blk.cols + c];
      out.beta(c) = beta ? beta[c] : 0.0;
      if (f_pass) out.f_ext_pass_through(c) = f_pass[col];
      if (t_pass) out.ff_pass_through(c) = t_pass[col];
    }
  }
}

}  // namespace vsbind
