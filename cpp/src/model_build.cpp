// The model of HdCore (hd_core.hpp) from a ModelSource: segment data, topology, degeneracy
// tolerances, and the checks of the robot (messages as HdSolver reports them). Built once per
// Model (model.cpp) and shared by every HdCore of it. Conventions in hd_solver.hpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <utility>

#include "hd_core.hpp"
#include "kdl_convert.hpp"
#include "model_validation.hpp"

namespace vereshchagin {
namespace detail {

namespace {

// Fills one HdModel; every failing step writes its message and returns the code.
class ModelBuilder {
 public:
  explicit ModelBuilder(HdModel& m) : model(m) {}
  int build();

 private:
  void topology();
  int segment(int i);
  void tolerances();  // SegmentModel::d_tolerance from the subtree sizes
  static void screwConstants(SegmentModel& s);
  int fail(int code, const char* fmt, ...);

  HdModel& model;
};

}  // namespace

int ModelBuilder::fail(int code, const char* fmt, ...) {
  std::array<char, 512> buf{};
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf.data(), buf.size(), fmt, args);
  va_end(args);
  model.error = code;
  model.message = buf.data();
  return code;
}

// Parent-array bookkeeping: subtree ranges, branching segments, the chain test.
void ModelBuilder::topology() {
  const int ns = static_cast<int>(model.ns);
  const std::vector<int>& parent = model.source.parent;
  model.subtree_end.assign(ns + 1, ns);
  model.branch_slot.assign(ns, -1);
  model.is_chain = true;
  std::vector<int> children(ns, 0);
  for (int i = 0; i < ns; ++i) {
    model.is_chain = model.is_chain && parent[i] == i - 1;
    if (parent[i] >= 0) ++children[parent[i]];
  }
  // Preorder: walking backwards, every child is done before its parent takes its subtree's end.
  for (int i = 0; i < ns; ++i) model.subtree_end[i] = i + 1;
  for (int i = ns - 1; i >= 0; --i)
    if (parent[i] >= 0) model.subtree_end[parent[i]] = std::max(model.subtree_end[parent[i]], model.subtree_end[i]);
  model.n_branch = 0;
  for (int i = 0; i < ns; ++i)
    if (children[i] >= 2) model.branch_slot[i] = model.n_branch++;
}

// Constant data of segment i; 0 or an error code.
int ModelBuilder::segment(int i) {
  const KDL::Segment& seg = model.source.segments[i];
  const KDL::Joint& joint = seg.getJoint();
  SegmentModel& s = model.seg[i];
  if (const char* why = detail::segmentGeometryProblem(seg))
    return fail(HdSolver::E_INVALID_MODEL, "segment %d ('%s'): %s", i, seg.getName().c_str(), why);
  const KDL::RigidBodyInertia& rbi = seg.getInertia();
  const double mass = rbi.getMass();
  const KDL::Vector cog = rbi.getCOG();
  const KDL::RotationalInertia Io = rbi.getRotationalInertia();  // about the tip origin
  Vector3 c(cog.x(), cog.y(), cog.z());
  Matrix3 I_origin = Eigen::Map<const Matrix3>(Io.data);
  if (!c.allFinite())
    return fail(HdSolver::E_INVALID_MODEL, "segment %d ('%s'): non-finite inertial parameters", i,
                seg.getName().c_str());
  // Rotational inertia about the centre of mass, checked as model.inertia_check says.
  const Matrix3 Sc = skew(c);
  const Matrix3 I_com = I_origin + mass * Sc * Sc;
  // Round-off scale of I_com: its two terms, each exact to a few ulps.
  const double round_off = std::max(I_origin.cwiseAbs().maxCoeff(), mass * c.squaredNorm());
  std::array<char, 320> why_buf{};
  if (const char* why =
          detail::inertiaProblem(mass, I_com, model.inertia_check, why_buf.data(), why_buf.size(), round_off))
    return fail(HdSolver::E_INVALID_MODEL, "segment %d ('%s'): %s", i, seg.getName().c_str(), why);
  s.I = rigidInertia(mass, c, 0.5 * (I_origin + I_origin.transpose()));
  s.X0 = toPose(seg.pose(0.0));
  s.joint = model.source.joint[i];
  if (s.joint < 0) {
    s.S.setZero();
    return 0;
  }
  model.joint_segment[s.joint] = i;
  s.rotor = joint.getInertia();
  if (!std::isfinite(s.rotor) || s.rotor < 0.0)
    return fail(HdSolver::E_INVALID_MODEL, "joint %d ('%s'): rotor inertia must be >= 0, got %g", s.joint,
                joint.getName().c_str(), s.rotor);
  // The joint axis is fixed in the child body, so in the tip frame it does not depend on q.
  const KDL::Twist t = seg.twist(0.0, 1.0);            // root axes, tip reference point
  const KDL::Rotation Rt = seg.pose(0.0).M.Inverse();  // root axes -> tip axes
  const KDL::Vector v = Rt * t.vel, w = Rt * t.rot;
  s.S << v.x(), v.y(), v.z(), w.x(), w.y(), w.z();
  s.w_norm = s.S.tail<3>().norm();
  s.v2 = s.S.head<3>().squaredNorm();
  s.w2 = s.S.tail<3>().squaredNorm();
  if (!s.S.allFinite() || s.S.norm() == 0.0)
    return fail(HdSolver::E_INVALID_MODEL, "joint %d ('%s'): joint axis is zero or not finite", s.joint,
                joint.getName().c_str());
  screwConstants(s);
  if ((s.S.array() != 0.0).count() == 1) s.S.cwiseAbs().maxCoeff(&s.axis);
  return 0;
}

// The constant factors of the joint's screw motion with X0 folded in (SegmentModel::RK, ...;
// the pose itself is HdCore::screwPose()).
void ModelBuilder::screwConstants(SegmentModel& s) {
  const Vector3 v = s.S.head<3>();
  if (s.w_norm == 0.0) {  // prismatic: X(q) = (X0.R, X0.p + X0.R v q)
    s.pq.noalias() = s.X0.R * v;
    return;
  }
  const Vector3 k = s.S.tail<3>() / s.w_norm;
  const Matrix3 K = skew(k);
  s.RK.noalias() = s.X0.R * K;
  s.RKK.noalias() = s.RK * K;
  const Vector3 kxv = k.cross(v) / s.w_norm;
  s.pK.noalias() = s.RK * kxv;
  s.pKK.noalias() = s.RKK * kxv;
  s.pq.noalias() = s.X0.R * (k * k.dot(v));
}

// The degeneracy tolerance of every joint, relative to what it moves (hd_solver.hpp, "Degenerate
// joints"): 1e-13 s_j with s_j = rotor_j + sum over the segments k of j's subtree of
// |v_j|^2 m_k + |w_j|^2 (trace|Ic_k| + m_k (d_j + l_jk + |c_k|)^2), S_j = [v_j; w_j], d_j = |v_j| / |w_j|
// the distance of a rotation axis from j's tip origin, l_jk the path length from j's tip frame to
// k's (per segment |X0.p| + 2 d: a tip origin moves at most 2 d about its axis). O(n x depth).
void ModelBuilder::tolerances() {
  const int ns = static_cast<int>(model.ns);
  std::vector<double> path(ns, 0.0), own(ns, 0.0), mass(ns, 0.0), reach(ns, 0.0), axis(ns, 0.0);
  for (int k = 0; k < ns; ++k) {
    const SegmentModel& sm = model.seg[k];
    const KDL::RigidBodyInertia& rbi = model.source.segments[k].getInertia();
    mass[k] = rbi.getMass();
    reach[k] = rbi.getCOG().Norm();
    const Vector3 c(rbi.getCOG().x(), rbi.getCOG().y(), rbi.getCOG().z());
    const Matrix3 I_com = sm.I.bottomRightCorner<3, 3>() + mass[k] * skew(c) * skew(c);
    own[k] = I_com.cwiseAbs().trace();
    axis[k] = sm.w_norm > 0.0 ? std::sqrt(sm.v2) / sm.w_norm : 0.0;
    const int p = model.parent(k);
    path[k] = (p >= 0 ? path[p] : 0.0) + sm.X0.p.norm() + 2.0 * axis[k];
  }
  for (int j = 0; j < ns; ++j) {
    SegmentModel& sj = model.seg[j];
    if (sj.joint < 0) continue;
    double size = sj.rotor;
    for (int k = j; k < model.subtree_end[j]; ++k) {
      const double dist = axis[j] + (path[k] - path[j]) + reach[k];
      size += sj.v2 * mass[k] + sj.w2 * (own[k] + mass[k] * dist * dist);
    }
    sj.d_tolerance = 1e-13 * std::max(size, std::numeric_limits<double>::min());
  }
}

int ModelBuilder::build() {
  const ModelSource& src = model.source;
  model.ns = static_cast<unsigned int>(src.segments.size());
  model.nj = 0;
  for (int j : src.joint) model.nj += j >= 0 ? 1 : 0;
  model.seg.assign(model.ns, SegmentModel());
  model.joint_segment.assign(model.nj, 0);
  topology();
  if (!src.problem.empty()) return fail(HdSolver::E_INVALID_MODEL, "%s", src.problem.c_str());
  if (const int rc = buildBase(model)) return rc;
  if (model.floating) model.is_chain = false;  // the base closes the several-segment path
  for (unsigned int i = 0; i < model.ns; ++i) {
    const int rc = segment(static_cast<int>(i));
    if (rc != 0) return rc;
  }
  tolerances();
  return 0;
}

std::shared_ptr<const HdModel> buildHdModel(ModelSource source, InertiaCheck check) {
  auto model = std::make_shared<HdModel>();
  model->source = std::move(source);
  model->inertia_check = check;
  if (ModelBuilder(*model).build() != 0) return model;
  // The sweep at a generic configuration, on a small workspace over the finished model.
  SolverOptions small;
  small.max_constraints = kMaxConstraints;
  HdCore core(model, Vector6::Zero(), small);
  const int rc = core.checkGenericConfiguration();
  if (rc != 0) {
    model->error = rc;
    model->message = core.message.data();
  }
  return model;
}

}  // namespace detail
}  // namespace vereshchagin
