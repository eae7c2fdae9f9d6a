// Joint friction and joint limits together with contacts (contact_stage.hpp). The friction
// stage's max-min (friction_solver.hpp) and the contact conditions are solved as one
// complementarity problem: each resting joint with static friction f_j or on a limit has an
// unknown torque tau_j on the joint, bounded by [lo, hi] (-f_j .. f_j; hi = +inf at a lower limit,
// lo = -inf at an upper one), with maximum dissipation: qdd_j > 0 gives tau_j = lo, qdd_j < 0
// gives tau_j = hi, a torque strictly inside the bounds gives qdd_j = 0. Unknowns z per joint
// (a = qdd_j, affine in z like the contact points' accelerations):
//   both bounds finite: tau_j = lo + u, z = (u, s), w = (a + s, (hi - lo) - u): s is a's negative
//     part, u reaches hi - lo when a < 0;
//   lo finite only (a lower limit): tau_j = lo + u, z = u, w = a;
//   hi finite only (an upper limit): tau_j = hi - v, z = v, w = -a;
//   neither (both limits): tau_j = u1 - u2, z = (u1, u2), w = (a, -a).
// Moving joints get their kinetic friction -fk_j sign(qd_j) as a known torque. Every solve of the
// stage runs without the friction stage, with these torques added to ff_torques while the
// input's ff_torques alone drive the pass-through. Where the joints' torques are not unique, the
// least-effort programme (contact_effort.cpp) trades them with the contact forces for the least
// motor command (the friction stage's least-command rule, here together with the contacts). The
// joint outputs (friction and limit torques, statuses, the Gauss value) are this stage's.
#include <algorithm>
#include <cmath>
#include <limits>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "friction_core.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

int ContactStage::checkJointFriction(DataImpl& d, const SolveInput& in) {
  FrictionCore& f = d.friction();
  if (const int rc = f.checkFriction(*in.friction)) return d.core.fail(rc, "%s", f.message_.data());
  return 0;
}

void ContactStage::classifyJoints(const SolveInput& in) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  joints_.clear();
  for (int v = 0; v < nbv_; ++v) {  // a floating base: no friction, no limit, no motor
    ff_user_(v) = in.ff_torques.size() ? in.ff_torques(v) : 0.0;
    joint_tau_(v) = 0.0;
  }
  for (int j = 0; j < static_cast<int>(model_.nrOfJoints()); ++j) {
    const int v = nbv_ + j;  // joint j's entry of q_dot, qdd and the torques
    ff_user_(v) = in.ff_torques.size() ? in.ff_torques(v) : 0.0;
    joint_tau_(v) = 0.0;
    const JointFriction jf = jointFriction(*in.friction, j, in.q(nbq_ + j), in.q_dot(v));
    if (jf.moving && dt_ == 0.0) {  // at the instant: kinetic friction against the velocity
      joint_tau_(v) = -jf.f * (in.q_dot(v) > 0.0 ? 1.0 : -1.0);
      continue;
    }
    // At rest, or over a time step (friction against the end velocity, kinetic while moving).
    if (!jf.unknown(dt_)) continue;
    JointUnknown u;
    u.joint = j;
    u.f = jf.f;
    u.lo = jf.at_upper ? -inf : -jf.f;
    u.hi = jf.at_lower ? inf : jf.f;
    u.row_bias = dt_ > 0.0 ? in.q_dot(v) / dt_ : 0.0;
    joints_.push_back(u);  // within the capacity reserved for every joint
  }
}

double ContactStage::offset(const JointUnknown& u) {
  return std::isfinite(u.lo) ? u.lo : std::isfinite(u.hi) ? u.hi : 0.0;
}

void ContactStage::layoutJoints() {
  ncol_contacts_ = ncol_;
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    JointUnknown& u = joints_[i];
    u.nvar = std::isfinite(u.lo) == std::isfinite(u.hi) ? 2 : 1;
    joint_tau_(nbv_ + u.joint) = offset(u);  // the problem's base solve: z = 0
    u.var = nz_, u.col = ncol_, u.row = nrow_;
    joint_index_(static_cast<Eigen::Index>(i)) = u.joint;
    nz_ += u.nvar, ++ncol_, ++nrow_;
  }
}

// The joints' response columns (qdd per unit torque on each resting joint) and rows (qdd_j).
void ContactStage::prepareJointColumns(DataImpl& d) {
  const int kj = static_cast<int>(joints_.size());
  if (kj == 0) return;
  (void)d.core.responseColumns(joint_index_.head(kj), dqdd_.middleCols(ncol_contacts_, kj), joint_dtau_.leftCols(kj),
                               nullptr);
  for (const JointUnknown& u : joints_) {
    rows_jac_.col(u.row).setZero();
    rows_jac_(nbv_ + u.joint, u.row) = 1.0;
    rows_bias_(u.row) = u.row_bias;
  }
}

void ContactStage::jointCoefficients() {
  for (const JointUnknown& u : joints_) {
    const bool lo = std::isfinite(u.lo), hi = std::isfinite(u.hi);
    coef_(u.col, u.var) = lo || !hi ? 1.0 : -1.0;    // u (or u1), or v at an upper limit
    if (!lo && !hi) coef_(u.col, u.var + 1) = -1.0;  // u2
  }
}

// The joints' rows of M and q (see the top of this file); M and q zero there before.
void ContactStage::assembleJointLcp() {
  auto rz = rows_per_z_.topLeftCorner(nrow_, nz_);
  auto M = lcp_m_.topLeftCorner(nz_, nz_);
  auto q = lcp_q_.head(nz_);
  for (const JointUnknown& u : joints_) {
    const bool lo = std::isfinite(u.lo), hi = std::isfinite(u.hi);
    const double sign = lo || !hi ? 1.0 : -1.0;  // w = a, or -a at an upper limit
    M.row(u.var) = sign * rz.row(u.row);
    q(u.var) = sign * rows0_(u.row);
    if (lo && hi) {  // w_u = a + s, w_s = (hi - lo) - u
      M(u.var, u.var + 1) += 1.0;
      M(u.var + 1, u.var) = -1.0;
      q(u.var + 1) = u.hi - u.lo;
    } else if (!lo && !hi) {  // w_u2 = -a
      M.row(u.var + 1) = -rz.row(u.row);
      q(u.var + 1) = -rows0_(u.row);
    }
  }
}

// The joints' torques of z into joint_tau_ and work_'s ff_torques.
void ContactStage::applyJointTorques() {
  const auto z = z_.head(nz_);
  for (const JointUnknown& u : joints_) {
    const int v = nbv_ + u.joint;
    joint_tau_(v) = offset(u) + coef_.row(u.col).head(nz_).dot(z);
    work_.ff_torques(v) = ff_user_(v) + joint_tau_(v);
  }
}

int ContactStage::runWork(DataImpl& d) {
  d.core.ws.pt.driver = joint_friction_ ? &ff_user_ : nullptr;
  const int rc = runInput(d, work_);
  d.core.ws.pt.driver = nullptr;
  return rc;
}

void ContactStage::jointOutputs(DataImpl& d, const SolveInput& in) {
  joint_friction = joint_tau_.tail(joint_friction.size());  // kinetic friction of the moving joints (at the
                                                            // instant), else 0
  joint_limit.setZero();
  std::fill(d.status_per_joint.begin(), d.status_per_joint.end(), JointStatus::Moving);
  q_dot_ = in.q_dot;
  if (!joint_friction_) {
    joint_friction.setZero();
    return;
  }
  const FrictionModel& fm = *in.friction;
  const Eigen::VectorXd& qdd = d.core.res.qdd;
  // Round-off of the rows (qdd_j, or v+_j / dt): the complementarity problem's scale.
  const double a_tol = 1e-9 * (nz_ > 0 ? lcp_scale_ : std::max(1.0, qdd.cwiseAbs().maxCoeff()));
  for (const JointUnknown& u : joints_) {
    const int j = u.joint, v = nbv_ + j;
    const double f = u.f, t = joint_tau_(v);
    joint_friction(j) = std::clamp(t, -f, f);  // beyond the friction bound: the limit's reaction
    joint_limit(j) = t - joint_friction(j);
    const double row = qdd(v) + u.row_bias;  // the acceleration, or the end velocity over dt
    const bool moving = std::abs(in.q_dot(v)) > fm.velocity_tolerance;
    d.status_per_joint[j] = std::abs(row) <= a_tol ? JointStatus::Stick
                            : moving               ? JointStatus::Moving
                            : row > 0              ? JointStatus::SlipPositive
                                                   : JointStatus::SlipNegative;
  }
}

double ContactStage::gaussValue(DataImpl& d) {
  HdCore& c = d.core;
  if (!c.res.solved) return std::numeric_limits<double>::quiet_NaN();
  // H (qdd - qdd_free) = the command plus the unknown joints' torques (qdd_free: the motion under
  // ff_torques, the contact forces and, at the instant, the moving joints' kinetic friction).
  gauss_tau_ = c.res.tau_cmd;
  double dissipation = 0.0;
  for (const JointUnknown& u : joints_) {
    const int v = nbv_ + u.joint;  // (a floating base's rows first)
    gauss_tau_(v) += joint_tau_(v);
    if (d.status_per_joint[u.joint] == JointStatus::Stick) continue;  // (round-off times a huge f)
    const double f = u.f;
    dissipation += f * std::abs(c.res.qdd(v) + u.row_bias);
  }
  if (nbv_ > 0) return 0.5 * floatingInverseInertiaDot(gauss_tau_) + dissipation;
  c.inverseInertia(gauss_tau_, gauss_out_);
  return 0.5 * gauss_tau_.dot(gauss_out_) + dissipation;
}

}  // namespace detail
}  // namespace vereshchagin
