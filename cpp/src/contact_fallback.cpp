// The contact stage's real-time fallback (contact_stage.hpp; docs/friction.md, "Real-time
// bound"): when Lemke's pivoting reaches its bound (SolveInput::contact_max_pivots) in the
// general problem, the solve still returns a result, with Error::Degraded, from a bounded number
// of sweeps instead of the exact answer:
//   - friction at the contacts and at the resting joints is left out (the moving joints keep their
//     known kinetic friction at the instant): no friction force or torque does work;
//   - every touching support (every support over a time step) is held along its normal, as a
//     constraint column: its normal row (acceleration, or end velocity over dt) is zero, so the
//     point does not move into its surface and its normal force does no work on that motion;
//   - a support that pulls is dropped and the rest held again, the one that pulls hardest first,
//     once per support at most, as long as no dropped support then moves into its surface (else
//     the last round's forces stand, which may pull: an adhesive force, never a penetration);
//   - the final sweep with these forces gives every result; set-points keep their normal force.
#include <algorithm>
#include <cmath>
#include <limits>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

namespace {

constexpr int E_DEGRADED = static_cast<int>(Error::Degraded);

}  // namespace

// One round: the held supports' normals as columns after the set-points'; their normal forces
// (-nu: tau_cmd = -J^T alfa nu) into `forces` (the others' zero beyond their known part). `worst`:
// the support that pulls hardest (-1: none); `penetration`: how far the supports (held or let go)
// move into their surfaces, the largest -n.row beyond round-off of the row's terms (0: none; a held
// row is zero unless the held normals, the bias accelerations and the task contradict each other).
// Returns 0 or an error code of the sweep.
int ContactStage::heldNormalsRound(DataImpl& d, const SolveInput& in, int& worst, double& penetration) {
  buildWorkInput(in, false);  // the set-points' columns and known forces, the joints' known torques
  int col = static_cast<int>(work_.constraints.size());
  for (std::size_t k = 0; k < points_.size(); ++k) {
    Point& p = points_[k];
    p.normal_col = -1;
    if (!in.contacts[k].isSupport() || p.kind == kSeparating || p.dropped) continue;
    addColumn(in.contacts[k].segment, p, in.contacts[k].point, p.n);
    p.normal_col = col++;
  }
  if (const int rc = runWork(d)) return rc;
  const auto nu = d.core.nu();
  worst = -1;
  penetration = 0.0;
  double worst_fn = 0.0;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    forces.col(k) = p.fixed;
    if (!in.contacts[k].isSupport() || p.kind == kSeparating) continue;
    Vector3 bias;  // the normal row: the acceleration, or the end velocity over dt
    const Vector3 a = pointAcceleration(in.contacts[k], d.core.res.qdd, bias);
    const double v = dt_ > 0.0 ? p.n.dot(p.v) / dt_ : 0.0, row = p.n.dot(a) + v;
    const double terms = std::max({1.0, bias.norm(), (a - bias).norm(), std::abs(v)});
    penetration = std::max(penetration, -row - 1e-9 * terms);
    if (p.normal_col < 0) continue;
    const double fn = -nu(p.normal_col);
    forces.col(k) += fn * p.n;
    if (fn < worst_fn) worst = static_cast<int>(k), worst_fn = fn;
  }
  return 0;
}

int ContactStage::degradedForces(DataImpl& d, const SolveInput& in) {
  HdCore& c = d.core;
  for (const JointUnknown& u : joints_) joint_tau_(u.joint) = 0.0;  // no friction at the resting joints
  joints_.clear();
  step_without_bias_ = false;
  layout(in, false);  // the set-points' known forces (normal at rest, against the sliding otherwise)
  nz_ = 0;            // no complementarity problem (jointOutputs' scale: the accelerations')
  for (Point& p : points_) p.dropped = false;
  int supports = 0;
  for (const PointContact& pc : in.contacts) supports += pc.isSupport() ? 1 : 0;
  // The rounds' forces: a round without penetration replaces the previous one (it pulls less); once
  // one was safe, the first that penetrates ends the rounds; before, the least penetration stands.
  double best = std::numeric_limits<double>::infinity();
  for (int round = 0; round <= supports; ++round) {
    int worst = -1;
    double penetration = 0.0;
    if (const int rc = heldNormalsRound(d, in, worst, penetration)) return rc;
    if (penetration <= 0.0 || penetration < best) {
      saved_forces_.leftCols(count) = forces.leftCols(count);
      best = std::max(penetration, 0.0);
    } else if (best == 0.0) {
      break;
    }
    if (worst < 0) break;  // nothing pulls
    points_[worst].dropped = true;
  }
  forces.leftCols(count) = saved_forces_.leftCols(count);
  if (const int rc = solveWithForces(d, in)) return rc;
  for (std::size_t k = 0; k < points_.size(); ++k) {  // statuses of the final motion
    const Point& p = points_[k];
    Vector3 bias;
    Vector3 a = pointAcceleration(in.contacts[k], c.res.qdd, bias);
    if (dt_ > 0.0) a += p.v / dt_;
    const Vector3 at = a - p.n.dot(a) * p.n;
    status[k] = in.contacts[k].isSupport() && !pushes(p, forces.col(k)) ? ContactStatus::Separating
                : at.norm() <= 1e-9 * std::max(1.0, bias.norm())        ? ContactStatus::Sticking
                                                                        : ContactStatus::Sliding;
  }
  outcome = ContactOutcome::Consistent;
  if (joint_friction_ || dt_ > 0.0) jointOutputs(d, in);
  return c.fail(E_DEGRADED,
                "contacts: the real-time bound of %d pivots of the complementarity problem was hit; the fallback "
                "holds the touching supports along their normals without friction at the contacts or the resting "
                "joints (docs/friction.md, \"Real-time bound\")",
                capped_);
}

}  // namespace detail
}  // namespace vereshchagin
