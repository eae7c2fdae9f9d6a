// The contact stage over a time step (SolveInput::time_step > 0, contact_stage.hpp): the same
// complementarity problem as at the instant, with every condition on the velocities at the end of
// the step, qd+ = q_dot + dt qdd, instead of the accelerations. A contact point's row is its end
// velocity over dt to first order, a + v / dt (a = J qdd + bias its acceleration, v = J q_dot: the
// instant's row plus v / dt); a joint's row qdd_j + q_dot_j / dt.
// So every support is an unknown whatever its velocity now (it may be hit, or leave), its friction
// polygon's force sits against its end velocity (maximum dissipation), a set-point's normal column
// ends the step with zero normal velocity, and every joint with friction is an unknown bounded by
// its static friction at rest and its kinetic friction while moving: a joint whose holding torque
// stays within the bound ends the step at zero velocity, a sliding one gets the full friction
// against its end velocity, which friction alone cannot reverse. The sticking trial, the
// all-active guess and the least-effort programme are instant-only; the joint outputs (friction
// and limit torques, statuses) are this stage's (the friction stage is instant-only too).
#include <algorithm>
#include <cmath>
#include <limits>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

void ContactStage::stepKinds(const SolveInput& in) {
  for (std::size_t k = 0; k < points_.size(); ++k) {
    Point& p = points_[k];
    const PointContact& pc = in.contacts[k];
    p.slide_dir.setZero();  // the vertex is the problem's, not the velocity's
    if (pc.isSupport())
      p.kind = pc.mu > 0.0 ? kTouching : kSliding;  // (frictionless: the normal alone)
    else
      p.kind = pc.mu > 0.0 ? kSetPointRest : kSetPointSliding;
  }
}

void ContactStage::stepOutputs(DataImpl& d, const SolveInput& in) {
  step_friction.setZero();
  step_limit.setZero();
  std::fill(d.status_per_joint.begin(), d.status_per_joint.end(), JointStatus::Moving);
  step_qd_ = in.q_dot;
  if (!joint_friction_) return;
  const FrictionModel& fm = *in.friction;
  const Eigen::VectorXd& fs = fm.static_friction;
  const Eigen::VectorXd& fk = fm.kinetic_friction.size() ? fm.kinetic_friction : fm.static_friction;
  const Eigen::VectorXd& qdd = d.core.res.qdd;
  // Round-off of the rows (v+ / dt): the complementarity problem's scale (none: the motion's).
  const double a_tol = 1e-9 * (nz_ > 0 ? lcp_scale_ : std::max(1.0, qdd.cwiseAbs().maxCoeff()));
  for (const JointUnknown& u : joints_) {
    const int j = u.joint;
    const bool moving = std::abs(in.q_dot(j)) > fm.velocity_tolerance;
    const double f = moving ? fk(j) : fs(j), t = joint_tau_(j);
    step_friction(j) = std::clamp(t, -f, f);  // beyond the friction bound: the limit's reaction
    step_limit(j) = t - step_friction(j);
    // Ends the step at rest: its end velocity is round-off of the step's velocity change.
    const double v = in.q_dot(j) + dt_ * qdd(j);
    const bool stuck = std::abs(v) <= dt_ * a_tol;
    d.status_per_joint[j] = stuck    ? JointStatus::Stick
                            : moving ? JointStatus::Moving
                            : v > 0  ? JointStatus::SlipPositive
                                     : JointStatus::SlipNegative;
  }
}

double ContactStage::stepGaussValue(DataImpl& d) {
  HdCore& c = d.core;
  if (!c.res.solved) return std::numeric_limits<double>::quiet_NaN();
  gauss_tau_ = c.res.tau_cmd + step_friction + step_limit;  // H (qdd - qdd_free)
  c.inverseInertia(gauss_tau_, gauss_out_);
  double dissipation = 0.0;
  for (const JointUnknown& u : joints_) {
    if (d.status_per_joint[u.joint] == JointStatus::Stick) continue;  // (round-off times a huge f)
    const double f = std::isfinite(u.hi) ? u.hi : std::isfinite(u.lo) ? -u.lo : 0.0;
    dissipation += f * std::abs(step_qd_(u.joint) / dt_ + c.res.qdd(u.joint));
  }
  return 0.5 * gauss_tau_.dot(gauss_out_) + dissipation;
}

}  // namespace detail

Status step(const Model& model, Data& data, const SolveInput& input, Eigen::Ref<Eigen::VectorXd> q_next,
            Eigen::Ref<Eigen::VectorXd> qd_next) {
  const long n = static_cast<long>(model.nrOfJoints());
  if (!(input.time_step > 0.0) || !std::isfinite(input.time_step))
    return Status(Error::OutOfRange, "step() needs a finite SolveInput::time_step > 0 (s)");
  if (q_next.size() != n || qd_next.size() != n)
    return Status(Error::SizeMismatch, "step(): q_next and qd_next must have one entry per joint");
  const Status s = solve(model, data, input);
  if (!s) return s;
  const double dt = input.time_step;
  const Eigen::VectorXd& qdd = data.qdd();
  const std::vector<JointStatus>& status = data.jointStatus();
  for (long j = 0; j < n; ++j) {  // a joint held by friction ends the step exactly at rest
    qd_next(j) = status[j] == JointStatus::Stick ? 0.0 : input.q_dot(j) + dt * qdd(j);
    q_next(j) = input.q(j) + dt * qd_next(j);
  }
  return s;
}

}  // namespace vereshchagin
