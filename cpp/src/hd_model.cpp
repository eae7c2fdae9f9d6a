// HdCore's model: built from a ModelSource (segments in preorder with their parents and joint
// indices), validated, and the workspace sized for it; input and result checks. Conventions in
// hd_solver.hpp, types in hd_core.hpp.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

#include "hd_core.hpp"
#include "model_validation.hpp"

namespace vereshchagin {
namespace detail {

namespace {

Pose toPose(const KDL::Frame& f) {
  Pose X;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) X.R(r, c) = f.M(r, c);
    X.p(r) = f.p(r);
  }
  return X;
}

}  // namespace

HdCore::HdCore(const ModelSource& source, const Vector6& root_acc_in, const SolverOptions& opts)
    : options(opts), root_acc(root_acc_in) {
  model.source = source;
  buildModel();
  if (model_error == 0) {
    const int rc = setOptions(opts);
    if (rc != 0) model_error = rc;
  }
}

void HdCore::rebuild(const ModelSource& source) {
  model.source = source;
  buildModel();
}

int constraintCapacity(const SolverOptions& opts, unsigned int ns) {
  const int all = std::max<int>(kMaxConstraints, kMaxConstraints * static_cast<int>(ns));  // 6 per segment
  const int wanted = opts.max_constraints > 0 ? opts.max_constraints : SolverOptions::kDefaultConstraintCapacity;
  return std::min(all, wanted);
}

int HdCore::setOptions(const SolverOptions& opts) {
  if (!std::isfinite(opts.rcond) || opts.rcond < 0.0 || opts.rcond >= 1.0) {
    return fail(HdSolver::E_INVALID_OPTIONS, "options.rcond must be finite and in [0, 1), got %g", opts.rcond);
  }
  if (!std::isfinite(opts.damping) || opts.damping < 0.0 ||
      (opts.policy == SingularityPolicy::DampedLeastSquares && opts.damping <= 0.0)) {
    return fail(HdSolver::E_INVALID_OPTIONS,
                "options.damping must be finite and > 0 for the damped least-squares policy, got %g", opts.damping);
  }
  if (opts.max_constraints < 0)
    return fail(HdSolver::E_INVALID_OPTIONS, "options.max_constraints must be >= 0 (0: the default), got %d",
                opts.max_constraints);
  const bool rebuild_model = opts.inertia_check != options.inertia_check ||
                             constraintCapacity(opts, model.ns) != constraintCapacity(options, model.ns);
  options = opts;
  res.solved = false;
  if (rebuild_model) {
    buildModel();
    return model_error;
  }
  return 0;
}

int HdCore::fail(int code, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(message.data(), message.size(), fmt, args);
  va_end(args);
  return code;
}

// Parent-array bookkeeping: subtree ranges, branching segments, the chain test.
void HdCore::buildTopology() {
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

void HdCore::allocateWorkspace() {
  const unsigned int nj = model.nj, ns = model.ns;
  ws.seg.assign(ns, SegmentState());
  res.qdd = res.tau_cmd = Eigen::VectorXd::Zero(nj);
  ws.zero_joints = Eigen::VectorXd::Zero(nj);
  ResponseWorkspace& r = ws.response;
  r.width = std::max<long>(1, std::min<long>(nj, ResponseWorkspace::kMaxWidth));
  r.sdp = Eigen::MatrixXd::Zero(ns, r.width);
  r.axis = r.axis_inertia = Matrix6X::Zero(6, ns);
  r.offset = Matrix3X::Zero(3, ns);
  r.force = Matrix6X::Zero(6, std::max<long>(r.width, kMaxConstraints));
  r.tmp3 = Matrix3X::Zero(3, std::max<long>(r.width, kMaxConstraints));
  r.holder = Eigen::VectorXi::Zero(r.width);
  r.branch_acc = Matrix6X::Zero(6, static_cast<Eigen::Index>(r.width) * model.n_branch);
  res.link_acc = Matrix6X::Zero(6, ns + 1);
  res.link_acc_known = true;  // zeros until the first solve
  ws.zero_f_ext = Matrix6X::Zero(6, ns);
  ws.alfa_buf.setZero();
  ws.inertia_force = ws.inertia_acc = Matrix6X::Zero(6, ns);
  ws.inertia_joint = Eigen::VectorXd::Zero(nj);
  mcap = constraintCapacity(options, ns);
  PassThroughState& pt = ws.pt;
  pt.f = pt.t = pt.energy = pt.tmp = Eigen::VectorXd::Zero(mcap);
  pt.free = Eigen::VectorXd::Zero(nj);
  pt.m = -1;  // weights are per column of a model: cleared with it
  pt.f_any = pt.t_any = pt.used = false;
  res.general = false;
  CouplingGeneral& g = ws.general;
  g.order = Eigen::VectorXi::Zero(mcap);
  g.seg_count = Eigen::VectorXi::Zero(ns);
  g.active.assign(ns + 1, 0);
  g.anew = g.acur = Matrix6X::Zero(6, mcap);
  g.eg = Eigen::MatrixXd::Zero(mcap, std::max<unsigned int>(ns, 1));
  g.ug = g.nug = g.rhs = g.tmp = g.invg = Eigen::VectorXd::Zero(mcap);
  res.nu_user = Eigen::VectorXd::Zero(mcap);
  g.kg = g.cholg = g.vg = g.work_g = Eigen::MatrixXd::Zero(mcap, mcap);
  g.work_v = Eigen::MatrixXd::Zero(mcap, 4);  // smallestEigenvalue's scratch: 4 columns
  g.seg_force = Matrix6X::Zero(6, ns);
  r.cmd_per_nu = Eigen::MatrixXd::Zero(nj, mcap);
  r.energy = Eigen::MatrixXd::Zero(mcap, r.width);
  r.dnu = Eigen::MatrixXd::Zero(mcap, r.width);
  res.m = 0;
  res.rank = 0;
  res.sigma_min = 0.0;
  res.sigma_known = true;
}

// Constant data of segment i; 0 or an error code.
int HdCore::buildSegment(int i) {
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
  // Rotational inertia about the centre of mass, checked as options.inertia_check says.
  const Matrix3 Sc = skew(c);
  const Matrix3 I_com = I_origin + mass * Sc * Sc;
  // Round-off scale of I_com: its two terms, each exact to a few ulps.
  const double round_off = std::max(I_origin.cwiseAbs().maxCoeff(), mass * c.squaredNorm());
  std::array<char, 320> why_buf{};
  if (const char* why =
          detail::inertiaProblem(mass, I_com, options.inertia_check, why_buf.data(), why_buf.size(), round_off))
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
  return 0;
}

// The degeneracy tolerance of every joint, relative to what it moves (hd_solver.hpp, "Degenerate
// joints"): 1e-13 s_j with s_j = rotor_j + sum over the segments k of j's subtree of
// |v_j|^2 m_k + |w_j|^2 (trace|Ic_k| + m_k (d_j + l_jk + |c_k|)^2), S_j = [v_j; w_j], d_j = |v_j| / |w_j|
// the distance of a rotation axis from j's tip origin, l_jk the path length from j's tip frame to
// k's (per segment |X0.p| + 2 d: a tip origin moves at most 2 d about its axis). O(n x depth).
void HdCore::buildTolerances() {
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

void HdCore::buildModel() {
  model_error = 0;
  message[0] = '\0';
  res.solved = false;
  const ModelSource& src = model.source;
  model.ns = static_cast<unsigned int>(src.segments.size());
  model.nj = 0;
  for (int j : src.joint) model.nj += j >= 0 ? 1 : 0;
  model.seg.assign(model.ns, SegmentModel());
  model.joint_segment.assign(model.nj, 0);
  buildTopology();
  allocateWorkspace();
  if (!src.problem.empty()) {
    model_error = fail(HdSolver::E_INVALID_MODEL, "%s", src.problem.c_str());
    return;
  }
  for (unsigned int i = 0; i < model.ns; ++i) {
    const int rc = buildSegment(static_cast<int>(i));
    if (rc != 0) {
      model_error = rc;
      return;
    }
  }
  buildTolerances();

  // Reject robots whose joints have no inertia to move. Checked at a generic configuration (not
  // q = 0, where a body may sit on an axis by coincidence); a configuration-dependent loss of
  // inertia is reported by solve().
  Eigen::VectorXd q_generic(model.nj);
  for (unsigned int k = 0; k < model.nj; ++k) q_generic(k) = 0.7 + 0.61 * k;
  state_q = state_q_dot = nullptr;
  outwardSweep(q_generic, ws.zero_joints, ws.zero_f_ext);
  const int rc = model.is_chain ? inwardSweep(ws.alfa_buf.leftCols(0), ws.zero_joints)
                                : inwardSweepGeneral(ws.alfa_buf.leftCols(0), ws.zero_joints);
  if (rc != 0) model_error = rc;
}

int HdCore::checkInputs(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                        const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                        const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques,
                        int max_columns) {
  if (model_error != 0) return model_error;  // message still holds the model's problem
  const long nj = model.nj, ns = model.ns;
  constexpr int E_SIZE = KDL::SolverI::E_SIZE_MISMATCH, E_NF = HdSolver::E_NONFINITE_INPUT;
  if (q.size() != nj) return fail(E_SIZE, "q has %ld entries, expected %ld (joints)", (long)q.size(), nj);
  if (q_dot.size() != nj) return fail(E_SIZE, "q_dot has %ld entries, expected %ld (joints)", (long)q_dot.size(), nj);
  if (ff_torques.size() != nj && ff_torques.size() != 0)
    return fail(E_SIZE, "ff_torques has %ld entries, expected %ld (joints) or 0", (long)ff_torques.size(), nj);
  if (f_ext.cols() != ns && f_ext.cols() != 0)
    return fail(E_SIZE, "f_ext has %ld wrenches, expected %ld (segments) or 0", (long)f_ext.cols(), ns);
  if (alfa.cols() > max_columns)
    return fail(HdSolver::E_TOO_MANY_CONSTRAINTS,
                "alfa has %ld columns, at most %d constraints are supported (6 per segment, and at most "
                "SolverOptions::max_constraints in all)",
                (long)alfa.cols(), max_columns);
  if (beta.size() != alfa.cols())
    return fail(E_SIZE, "beta has %ld entries, expected %ld (one per alfa column)", (long)beta.size(),
                (long)alfa.cols());
  if (!q.allFinite()) return fail(E_NF, "q contains NaN or Inf");
  if (!q_dot.allFinite()) return fail(E_NF, "q_dot contains NaN or Inf");
  if (!ff_torques.allFinite()) return fail(E_NF, "ff_torques contains NaN or Inf");
  if (!f_ext.allFinite()) return fail(E_NF, "f_ext contains NaN or Inf");
  if (!alfa.allFinite()) return fail(E_NF, "alfa contains NaN or Inf");
  if (!beta.allFinite()) return fail(E_NF, "beta contains NaN or Inf");
  if (!root_acc.allFinite()) return fail(E_NF, "root acceleration contains NaN or Inf");
  return 0;
}

// Finite inputs can still overflow (|q_dot| ~ 1e160 squares to Inf): never return Inf or NaN,
// nor results beyond kMaxResult whose products (energies, powers) would overflow. An overflowing
// coupling matrix (kappa >= trace K; e.g. alfa columns of size 1e200) would be truncated to rank 0,
// silently dropping the task. Inf and NaN propagate outward through the link accelerations: the
// leaves tell (on a chain, the last segment).
int HdCore::checkBounded(const Eigen::Ref<const Eigen::VectorXd>& nu, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                         const Eigen::Ref<const Eigen::VectorXd>& beta, const Eigen::Ref<const Matrix6X>& f_ext,
                         const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  const int ns = static_cast<int>(model.ns);
  bool finite =
      std::isfinite(ws.kappa) && detail::bounded(res.qdd) && detail::bounded(res.tau_cmd) && detail::bounded(nu);
  for (int i = ns - 1; i >= 0 && finite; --i) {
    if (model.subtree_end[i] == i + 1) finite = detail::bounded(ws.seg[i].xdd);  // a leaf
    if (model.is_chain) break;
  }
  if (finite) return 0;
  return fail(HdSolver::E_NONFINITE_RESULT,
              "the results overflow (Inf/NaN or beyond 1e150): inputs too large (max |q_dot| %g, "
              "max |ff_torques| %g, max |f_ext| %g, max |beta| %g)",
              q_dot.size() ? q_dot.cwiseAbs().maxCoeff() : 0.0,
              ff_torques.size() ? ff_torques.cwiseAbs().maxCoeff() : 0.0,
              f_ext.size() ? f_ext.cwiseAbs().maxCoeff() : 0.0, beta.size() ? beta.cwiseAbs().maxCoeff() : 0.0);
}

namespace {

double maxAbs(const Eigen::Ref<const Eigen::VectorXd>* v) {
  return v && v->size() ? v->cwiseAbs().maxCoeff() : 0.0;
}

}  // namespace

// Joint i's articulated inertia failed the test of articulate(). A model problem (the joint moves
// nothing) or a state whose size let round-off take over (hd_solver.hpp, "Degenerate joints").
int HdCore::degenerate(int i) {
  const SegmentState& s = ws.seg[i];
  const int joint = model.seg[i].joint;
  const char* name = model.jointName(i).c_str();
  const double size = model.seg[i].d_tolerance / 1e-13;  // what the joint moves
  const bool physical = options.inertia_check == InertiaCheck::Physical;
  const double q_max = maxAbs(state_q), q_dot_max = maxAbs(state_q_dot);
  if (state_q != nullptr &&
      (!std::isfinite(s.D) || !s.IA.allFinite() || (physical && s.D < -model.seg[i].d_tolerance) || q_max > 1e15 ||
       s.IA.cwiseAbs().maxCoeff() > 1e8 * size))
    return fail(HdSolver::E_STATE_OUT_OF_RANGE,
                "the state is out of range: joint %d ('%s') gets an articulated inertia of %g where what it moves "
                "has size %g; round-off dominates at this state (max |q| %g, max |q_dot| %g): not a model problem, "
                "the state is not physical (a diverged simulation?)",
                joint, name, s.D, size, q_max, q_dot_max);
  if (options.inertia_check == InertiaCheck::JointSpace && s.D < 0.0)
    return fail(HdSolver::E_DEGENERATE_INERTIA,
                "joint %d ('%s') has articulated inertia D = %g <= 0 at this configuration: the model's "
                "joint-space inertia matrix is not positive definite here (inertia_check = joint_space "
                "accepts non-physical link inertias only where it is)",
                joint, name, s.D);
  return fail(HdSolver::E_DEGENERATE_INERTIA,
              "joint %d ('%s') has zero articulated inertia (%g): the bodies it moves have no "
              "mass or inertia about its axis and it has no rotor inertia",
              joint, name, s.D);
}

}  // namespace detail
}  // namespace vereshchagin
