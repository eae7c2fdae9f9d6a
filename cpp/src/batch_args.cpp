// BatchArgs (batch_args.hpp): arrays checked into the rows of a BatchInput, with the messages of
// the Python package's Solver.solve and solve_batch.
#include "vereshchagin/batch_args.hpp"

#include <cmath>
#include <limits>

namespace vereshchagin {

namespace {

// "6, 2" for {6, 2}: the shape one row must have ("7," for one dimension).
std::string shapeText(int ndim, const long* shape) {
  std::string s;
  for (int k = 0; k < ndim; ++k) s += (k ? ", " : "") + std::to_string(shape[k]);
  return ndim == 1 ? s + "," : s;
}

std::string shapeMessage(const char* name, const ArrayArg& a, int ndim, const long* shape, ShapeHint hint, bool batch) {
  const std::string expect = hint == ShapeHint::Alpha ? "6, m" : shapeText(ndim, shape);
  return std::string(name) + " must have shape (" + expect + ")" +
         (batch ? " (shared by all rows) or (B, " + expect + ") (one per row)" : "") +
         (hint == ShapeHint::Alpha ? " (columns: unit wrenches [force; moment]) or (6,) for one column, got " : "") +
         (hint == ShapeHint::FExt ? ": one row [fx, fy, fz, mx, my, mz] per segment (base axes, moment about the "
                                    "segment's tip origin), or a dict {segment: wrench (6,)}; got "
                                  : "") +
         (hint == ShapeHint::None ? ", got " : "") + a.shapeString();
}

// A joint limit vector: (n,), no NaN, into `out` (sized n); nullptr leaves `out` as it is.
std::string limitFrom(const ArrayArg* a, const char* name, long n, Eigen::VectorXd& out) {
  if (a == nullptr) return {};
  if (a->ndim != 1 || a->shape[0] != n)
    return std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + a->shapeString();
  for (long j = 0; j < n; ++j) {
    if (std::isnan(a->data[j])) return std::string(name) + " contains NaN";
    out(j) = a->data[j];
  }
  return {};
}

}  // namespace

std::string frictionFromArrays(FrictionModel& out, long n, const ArrayArg& static_friction, const ArrayArg* kinetic,
                               double velocity_tolerance, const ArrayArg* lower, const ArrayArg* upper,
                               double limit_tolerance) {
  using MapV = Eigen::Map<const Eigen::VectorXd>;
  if (std::string why = vectorMessage(static_friction, "friction.static", n); !why.empty()) return why;
  out.static_friction = MapV(static_friction.data, n);
  out.kinetic_friction.resize(0);
  if (kinetic != nullptr) {
    if (std::string why = vectorMessage(*kinetic, "friction.kinetic", n); !why.empty()) return why;
    out.kinetic_friction = MapV(kinetic->data, n);
  }
  out.velocity_tolerance = velocity_tolerance;
  out.lower.resize(0);
  out.upper.resize(0);
  if (lower == nullptr && upper == nullptr) return {};
  out.lower = Eigen::VectorXd::Constant(n, -std::numeric_limits<double>::infinity());
  out.upper = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  if (std::string why = limitFrom(lower, "friction.lower", n, out.lower); !why.empty()) return why;
  if (std::string why = limitFrom(upper, "friction.upper", n, out.upper); !why.empty()) return why;
  out.limit_tolerance = limit_tolerance;
  return {};
}

std::string endBlockArgs(bool alpha, bool beta, bool a_desired, bool tree) {
  if (alpha && tree)
    return "alpha and beta constrain a chain's last segment; a Tree has no last segment: pass constraints={segment or "
           "link name: (alpha, beta)}";
  if (alpha && beta && a_desired)
    return "beta and a_desired given: a_desired (the tip's classical acceleration) replaces beta";
  if (!alpha && (beta || a_desired)) return std::string(a_desired ? "a_desired" : "beta") + " given without alpha";
  return {};
}

FrictionModel modelFriction(const Model& model) {
  return frictionOfJoints(model.jointInfos());
}

FrictionModel frictionOfJoints(const std::vector<JointInfo>& joints) {
  const auto n = static_cast<Eigen::Index>(joints.size());
  FrictionModel out;
  out.static_friction = out.lower = out.upper = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    out.static_friction(k) = joints[k].friction;
    out.lower(k) = joints[k].lower;
    out.upper(k) = joints[k].upper;
  }
  return out;
}

void BatchArgs::start(bool batch, const Model& model) {
  batch_ = batch;
  model_ = &model;
  input.rows = 1;
  input.q = input.q_dot = input.f_ext = input.ff_torques = StridedRows();
  input.f_ext_pass_through = input.ff_pass_through = StridedRows();
  input.blocks.clear();
  input.wrenches.clear();
  input.friction.clear();
  columns = 0;
  first_.clear();
  segment_cols_.clear();
  n_frames_ = 0;
}

std::string BatchArgs::batchAxis(long n, const char* name, const std::string& shape) {
  if (first_.empty()) {
    input.rows = n;
    first_ = std::string(name) + " " + shape;
  } else if (n != input.rows) {
    return std::string(name) + " has a batch axis (axis 0) of " + std::to_string(n) + " rows (shape " + shape +
           "), but " + first_ + " has " + std::to_string(input.rows);
  }
  return {};
}

std::string BatchArgs::rows(StridedRows& out, const char* name, const ArrayArg& a, int ndim, const long* shape,
                            ShapeHint hint) {
  const int batched = batch_ && a.ndim == ndim + 1;
  bool fits = a.ndim == ndim + batched;
  for (int k = 0; fits && k < ndim; ++k) fits = a.shape[k + batched] == shape[k];
  if (!fits) return shapeMessage(name, a, ndim, shape, hint, batch_);
  out = StridedRows{a.data, 0};
  if (batched) {
    out.stride = 1;
    for (int k = 0; k < ndim; ++k) out.stride *= shape[k];
    if (std::string why = batchAxis(a.shape[0], name, a.shapeString()); !why.empty()) return why;
  }
  const long n = a.size(), per_row = out.stride ? out.stride : n;
  for (long k = 0; k < n; ++k)
    if (!std::isfinite(a.data[k]))
      return (batched ? "batch row " + std::to_string(k / per_row) + ": " : std::string()) + name +
             " contains NaN or Inf (flat index " + std::to_string(k % per_row) + ")";
  return {};
}

std::string BatchArgs::vector(StridedRows& out, const char* name, ArrayArg a, long n, bool scalar_ok) {
  if (scalar_ok && n == 1 && a.ndim == 0) {
    a.ndim = 1;
    a.shape[0] = 1;
  } else if (scalar_ok && n == 1 && batch_ && a.ndim == 1 && a.shape[0] != 1) {
    a.ndim = 2;
    a.shape[1] = 1;
  }
  return rows(out, name, a, 1, &n);
}

std::string BatchArgs::frame(int segment, const Vector3& point, const std::string& label) {
  for (std::size_t k = 0; k < n_frames_; ++k)
    if (frames_[k].segment == segment && frames_[k].point == point)
      return label + ": the same frame as " + frames_[k].label +
             " (one entry per frame: put all its columns in one alpha)";
  if (n_frames_ == frames_.size()) frames_.emplace_back();
  KeyedFrame& f = frames_[n_frames_++];
  f.segment = segment;
  f.point = point;
  f.label.assign(label);  // reuses the string's storage
  return {};
}

std::string BatchArgs::block(int segment, ArrayArg alpha, const char* name) {
  if (alpha.ndim == 1 && alpha.shape[0] == 6) {  // one column
    alpha.ndim = 2;
    alpha.shape[1] = 1;
  }
  const long m = alpha.ndim >= 2 ? alpha.shape[alpha.ndim - 1] : -1, shape[2] = {6, m};
  if (m > 6) return std::string(name) + " has " + std::to_string(m) + " columns; at most 6 constraints per segment";
  BlockRows& blk = input.blocks.emplace_back();
  blk.segment = segment;
  blk.columns = static_cast<int>(m);
  return rows(blk.alpha, name, alpha, 2, shape, ShapeHint::Alpha);
}

std::string BatchArgs::setPoint(const ArrayArg* a, bool classical, const char* name, const std::string& label) {
  BlockRows& blk = input.blocks.back();
  if (classical) {  // task.py's wording: Task.solve passes its a_desired here
    for (long k = 0; k < a->size(); ++k)
      if (!std::isfinite(a->data[k]))
        return "a_desired must be finite (no NaN or Inf), flat index " + std::to_string(k);
    const long six = 6;
    if (std::string why = rows(blk.classical, "a_desired", *a, 1, &six); !why.empty()) return why;
  } else {
    if (a == nullptr) return "beta is required when alpha is given (shape (" + std::to_string(blk.columns) + ",))";
    if (std::string why = vector(blk.beta, name, *a, blk.columns, true); !why.empty()) return why;
  }
  columns += blk.columns;
  if (label.empty()) return {};  // the end segment's alpha: counted with the first keyed block
  if (segment_cols_.empty()) {
    segment_cols_.assign(model_->nrOfSegments(), 0);
    const BlockRows& first = input.blocks.front();
    if (input.blocks.size() > 1 && first.segment >= 0 && n_frames_ == 1) segment_cols_[first.segment] = first.columns;
  }
  segment_cols_[blk.segment] += blk.columns;
  if (segment_cols_[blk.segment] > 6)
    return label + ": more than 6 constraint columns on segment '" + model_->segmentNames()[blk.segment] +
           "' (alpha and every key on it count)";
  return {};
}

}  // namespace vereshchagin
