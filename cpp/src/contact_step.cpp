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
// against its end velocity, which friction alone cannot reverse. The sticking trial and the
// all-active guess are instant-only; where the impulses are not unique the least-effort programme
// picks them as at the instant, on the end-velocity rows (contact_effort.cpp); the joint outputs
// (friction and limit torques, statuses) are this stage's (contact_joints.cpp).
#include <algorithm>
#include <cmath>

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

// The general problem; over a time step, if it has no answer (Lemke's pivoting ends on a ray, or
// the certificate fails), once more on the velocity-level rows alone. The points' rows a + v / dt
// carry their bias acceleration J' qd, which is not in the range of the contact Jacobians: with
// more force directions than joints some non-negative combination of them moves nothing yet meets
// a negative bias, and the problem has no answer. Without it the rows are J qd+ / dt (the end
// velocities at the start's Jacobian), the problem of Stewart-Trinkle and Anitescu-Potra, whose
// matrix makes every such combination harmless (q^T z = v^T J^T z = 0): Lemke's pivoting always
// finds an answer unless the task's constraints and the supports contradict each other.
int ContactStage::generalForces(DataImpl& d, const SolveInput& in) {
  layout(in, false);
  buildWorkInput(in, false);
  const bool convex = convexProblem(in);
  const int rc = forcesOfLcp(d, in, convex);
  if (rc == 0 || dt_ == 0.0 || rc != static_cast<int>(Error::NoContactSolution)) return rc;
  step_without_bias_ = true;
  layout(in, false);
  buildWorkInput(in, false);
  return forcesOfLcp(d, in, convex);
}

Status finiteStep(const Eigen::Ref<const Eigen::VectorXd>& q_next, const Eigen::Ref<const Eigen::VectorXd>& qd_next,
                  const Status& s, const char* message) {
  return q_next.allFinite() && qd_next.allFinite() ? s : Status(Error::NonfiniteResult, message);
}

}  // namespace detail

namespace {
const char* const kStepOverflow =
    "step(): the state after the step overflows (finite inputs, q_next or qd_next not finite): the velocities "
    "or the time step are too large";
}  // namespace

Status step(const Model& model, Data& data, const SolveInput& input, Eigen::Ref<Eigen::VectorXd> q_next,
            Eigen::Ref<Eigen::VectorXd> qd_next) {
  const long n = static_cast<long>(model.nrOfJoints());
  if (!(input.time_step > 0.0) || !std::isfinite(input.time_step))
    return Status(Error::OutOfRange, "step(): time_step must be finite and > 0 (s)");
  if (q_next.size() != model.nq() || qd_next.size() != model.nv())
    return Status(Error::SizeMismatch,
                  "step(): q_next and qd_next must have one entry per joint (nq and nv entries on a floating base)");
  const Status s = solve(model, data, input);
  if (!s) return s;
  const double dt = input.time_step;
  const Eigen::VectorXd& qdd = data.qdd();
  if (model.baseKind() != BaseKind::Fixed) {  // q (+) dt qd_next on SE(3) / SE(2)
    detail::floatingEndVelocity(data.impl(), input, qd_next);
    integrateConfiguration(model.baseKind(), input.q, qd_next, dt, q_next);
    return detail::finiteStep(q_next, qd_next, s, kStepOverflow);
  }
  const std::vector<JointStatus>& status = data.jointStatus();
  for (long j = 0; j < n; ++j) {  // a joint held by friction ends the step exactly at rest
    qd_next(j) = status[j] == JointStatus::Stick ? 0.0 : input.q_dot(j) + dt * qdd(j);
    q_next(j) = input.q(j) + dt * qd_next(j);
  }
  return detail::finiteStep(q_next, qd_next, s, kStepOverflow);
}

}  // namespace vereshchagin
