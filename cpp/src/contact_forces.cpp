// The contact forces (contact_stage.hpp, steps 2-4): response columns of the unknown force
// directions, the complementarity problem (acceleration level, polygonal Coulomb cones with
// maximum dissipation), Lemke's pivoting with its certificate, the final solve and the statuses.
//
// Unknowns z and their complementary w, per contact role (a = the point's acceleration):
//   kFull (a resting support with friction): z = (f_n, beta_1..beta_k, gamma), force
//     f_n n + sum_j beta_j d_j, w = (n.a, gamma + d_j.a (j = 1..k), mu f_n - sum_j beta_j);
//   kNormalOnly (a sliding or frictionless support, or in the sticking trial a resting one): z =
//     f_n, force f_n dir (dir = n + mu d*, d* the vertex most opposed to the velocity), w = n.a;
//   kTangentOnly (a resting set-point with friction): z = (beta_1..beta_k, gamma), force
//     F n + sum_j beta_j d_j, w = (gamma + d_j.a, mu F - sum_j beta_j) (its normal is a column).
// gamma > 0 means the point starts to slide: the force sits where it opposes a_t most.
//
// Which answer when several exist: a resting point with friction sticks whenever every such point
// can (the sticking trial: tangential constraint columns, the normal forces by the convex
// problem, every tangential force inside its polygon); otherwise the full problem's answer.
#include <algorithm>
#include <cmath>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

namespace {

constexpr int E_NO_SOLUTION = static_cast<int>(Error::NoContactSolution);

}  // namespace

// The unknowns' force directions as wrench columns, their response, and the acceleration rows.
void ContactStage::prepareColumns(DataImpl& d, const SolveInput& in) {
  const int n = nv_;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    const PointContact& pc = in.contacts[k];
    if (p.ncol == 0) continue;
    // Columns and rows: kNormalOnly (dir; n), kFull (n, t1, t2), kTangentOnly (t1, t2).
    const Vector3 cols[3] = {p.role == kNormalOnly ? p.dir : p.n, p.t1, p.t2};
    const Vector3 rows[3] = {p.n, p.t1, p.t2};
    const int first = p.role == kTangentOnly ? 1 : 0;
    Vector6 bias;
    pointKinematics(pc, bias);
    for (int c = 0; c < p.ncol; ++c) {
      const Vector3& e = cols[first + c];
      col_segment_(p.col + c) = pc.segment;
      col_wrench_.col(p.col + c) << e, p.r.cross(e);
      rows_jac_.col(p.row + c).head(n).noalias() = jac_.topRows<3>().transpose() * rows[first + c];
      // Over a time step the row is the end velocity over dt, v+ / dt = a + v / dt to first order
      // (a = J qdd + bias the point's acceleration, v = J qd).
      const double row_v = dt_ > 0.0 ? rows[first + c].dot(p.v) / dt_ : 0.0;
      // (The velocity-level retry leaves the bias out: contact_step.cpp.)
      rows_bias_(p.row + c) = (step_without_bias_ ? 0.0 : rows[first + c].dot(bias.head<3>())) + row_v;
    }
  }
  auto dqdd = dqdd_.leftCols(ncol_);
  (void)d.core.wrenchResponse(col_segment_.head(ncol_contacts_), col_wrench_.leftCols(ncol_contacts_),
                              dqdd_.leftCols(ncol_contacts_), nullptr);
  prepareJointColumns(d);
  const auto Jt = rows_jac_.topLeftCorner(n, nrow_);  // one column per row: no strided products
  acc_per_col_.topLeftCorner(nrow_, ncol_).noalias() = Jt.transpose() * dqdd;
  rows0_.head(nrow_).noalias() = Jt.transpose() * d.core.res.qdd;
  rows0_.head(nrow_) += rows_bias_.head(nrow_);
}

// M and q of the complementarity problem (see the top of this file).
void ContactStage::assembleLcp(const SolveInput& in) {
  auto coef = coef_.topLeftCorner(ncol_, nz_);  // column force per unit unknown
  coef.setZero();
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    const int facets = in.contacts[k].facets;
    if (p.role == kNormalOnly || p.role == kFull) coef(p.col, p.var) = 1.0;
    if (p.role != kFull && p.role != kTangentOnly) continue;
    const int beta0 = p.role == kFull ? p.var + 1 : p.var, t1 = p.role == kFull ? p.col + 1 : p.col;
    for (int j = 0; j < facets; ++j) {  // d_j in the (t1, t2) columns
      const Eigen::Vector2d d = vertexCoords(j, facets);
      coef(t1, beta0 + j) = d(0);
      coef(t1 + 1, beta0 + j) = d(1);
    }
  }
  jointCoefficients();
  auto rz = rows_per_z_.topLeftCorner(nrow_, nz_);
  rz.noalias() = acc_per_col_.topLeftCorner(nrow_, ncol_) * coef;
  auto M = lcp_m_.topLeftCorner(nz_, nz_);
  auto q = lcp_q_.head(nz_);
  M.setZero();
  q.setZero();
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    const PointContact& pc = in.contacts[k];
    if (p.role == kNormalOnly || p.role == kFull) {  // n.a
      M.row(p.var) = rz.row(p.row);
      q(p.var) = rows0_(p.row);
    }
    if (p.role != kFull && p.role != kTangentOnly) continue;
    const bool full = p.role == kFull;
    const int beta0 = full ? p.var + 1 : p.var, gamma = beta0 + pc.facets, t1 = full ? p.row + 1 : p.row;
    for (int j = 0; j < pc.facets; ++j) {  // gamma + d_j . a_t
      const Eigen::Vector2d d = vertexCoords(j, pc.facets);
      const double cj = d(0), sj = d(1);
      M.row(beta0 + j) = cj * rz.row(t1) + sj * rz.row(t1 + 1);
      M(beta0 + j, gamma) += 1.0;
      q(beta0 + j) = cj * rows0_(t1) + sj * rows0_(t1 + 1);
      M(gamma, beta0 + j) = -1.0;  // mu f_n - sum beta
    }
    if (full)
      M(gamma, p.var) = pc.mu;
    else
      q(gamma) = pc.mu * pc.force;
  }
  assembleJointLcp();
}

// Lemke's pivoting, then the certificate: z >= 0, w = M z + q >= 0, z_i w_i = 0 (to round-off).
int ContactStage::solveLcp(HdCore& c, bool convex) {
  const auto M = lcp_m_.topLeftCorner(nz_, nz_);
  const auto q = lcp_q_.head(nz_);
  auto z = z_.head(nz_), w = w_.head(nz_);
  int pivots = 0;
  const int limit = max_pivots_ > 0 ? max_pivots_ : 50 + 20 * nz_;
  Lemke::Result r = lemke_.solve(M, q, z, w, limit, pivots);
  if (r == Lemke::kRay) r = perturbedLcp(limit);
  if (r == Lemke::kPivotLimit) {
    capped_ = limit;  // (the general problem then takes the fallback: contact_fallback.cpp)
    return c.fail(E_NO_SOLUTION, "contacts: the complementarity problem did not finish within %d pivots", limit);
  }
  if (r == Lemke::kRay)
    return c.fail(E_NO_SOLUTION,
                  convex ? "contacts: no contact forces meet the contact conditions (the constraints and the "
                           "supports contradict each other)"
                         : "contacts: no consistent contact forces were found (with friction at the supports the "
                           "problem can have none: Painleve's paradox)");
  const double scale = std::max({1.0, q.cwiseAbs().maxCoeff(), (w - q).cwiseAbs().maxCoeff()});  // w - q = M z
  const double tol = 1e-9 * scale;
  lcp_scale_ = scale;
  for (int i = 0; i < nz_; ++i)
    if (w(i) < -tol || std::abs(w(i) * z(i)) > tol * std::max(1.0, std::abs(z(i))))
      return c.fail(E_NO_SOLUTION, "contacts: the certificate of the contact forces failed at unknown %d", i);
  return 0;
}

// Lemke's pivoting once more after a ray, on q + delta_i with delta_i = 1e-10 (i + 1) / N times the
// problem's scale: distinct, positive and far below the certificate's tolerance (1e-9 of it). On
// the degenerate problems of several supports with more force directions than the joints can tell
// apart (many ties in the ratio test), round-off can decide a tie against the lexicographic order
// and end the pivoting on a ray that exact arithmetic would not meet; the perturbation breaks the
// ties. The answer is then the basis found evaluated at the problem's own q (B^-1 q: no trace of
// the perturbation where that basis is feasible), and the certificate judges it.
Lemke::Result ContactStage::perturbedLcp(int limit) {
  const auto M = lcp_m_.topLeftCorner(nz_, nz_);
  const auto q = lcp_q_.head(nz_);
  auto qp = lcp_qp_.head(nz_), z = z_.head(nz_), w = w_.head(nz_);
  const double delta = 1e-10 * std::max({1.0, q.cwiseAbs().maxCoeff(), M.cwiseAbs().maxCoeff()}) / nz_;
  for (int i = 0; i < nz_; ++i) qp(i) = q(i) + delta * (i + 1);
  int pivots = 0;
  const Lemke::Result r = lemke_.solve(M, qp, z, w, limit, pivots);
  if (r == Lemke::kSolved) lemke_.basicSolution(M, q, z, w);  // its basis at the problem's own q
  return r;
}

// The known forces plus those of z, into `forces`; the unknown parts added to work_'s wrenches.
void ContactStage::applyForces(const SolveInput& in) {
  const auto z = z_.head(nz_);
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    Vector3 f = Vector3::Zero();
    for (int c = 0; c < p.ncol; ++c) f += coef_.row(p.col + c).head(nz_).dot(z) * col_wrench_.col(p.col + c).head<3>();
    forces.col(k) = p.fixed + f;
    if (p.ncol > 0 && !f.isZero(0.0)) addForce(in.contacts[k], f);
  }
  if (nz_ > 0) applyJointTorques();
}

// The problem of the current layout on work_: base solve, response, complementarity, forces.
int ContactStage::forcesOfLcp(DataImpl& d, const SolveInput& in, bool convex) {
  if (int rc = runWork(d)) return rc;
  if (nz_ > 0) {
    prepareColumns(d, in);
    assembleLcp(in);
    if (int rc = solveLcp(d.core, convex)) return rc;
  }
  applyForces(in);
  return 0;
}

int ContactStage::trySticking(DataImpl& d, const SolveInput& in) {
  layout(in, true);
  buildWorkInput(in, true);
  if (forcesOfLcp(d, in, true) != 0) return 0;  // no normal forces with every resting point held
  if (int rc = runWork(d)) return rc;           // with the normal forces: the tangential ones in nu
  const auto nu = d.core.nu();
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    if (p.stick_col < 0) continue;
    const PointContact& pc = in.contacts[k];
    const Vector3 ft = -nu(p.stick_col) * p.t1 - nu(p.stick_col + 1) * p.t2;  // tau_cmd = -J^T alfa nu
    if (!insidePolygon(p, ft, p.n.dot(forces.col(k)), pc.mu, pc.facets)) return 0;
    forces.col(k) += ft;
  }
  // Held columns that contradict the task (a task column along a held direction) are met only in
  // the least-squares sense: the points must really stick.
  if (!heldPointsStill(in, d.core.res.qdd)) return 0;
  if (int rc = solveWithForces(d, in)) return rc;  // the final sweep: no tangential columns
  return 1;
}

void ContactStage::reportStatus(const SolveInput& in, bool stuck) {
  // gamma (an acceleration) above round-off of the problem's accelerations: starts to slide.
  const double gamma_tol = stuck || nz_ == 0 ? 0.0 : 1e-9 * std::max(1.0, lcp_q_.head(nz_).cwiseAbs().maxCoeff());
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    ContactStatus s = ContactStatus::Sliding;
    if (in.contacts[k].isSupport() && !pushes(p, forces.col(k)))
      s = ContactStatus::Separating;
    else if (stuck && p.stick_col >= 0)
      s = ContactStatus::Sticking;
    else if (p.role == kFull || p.role == kTangentOnly)
      s = z_(p.var + p.nvar - 1) > gamma_tol ? ContactStatus::Sliding : ContactStatus::Sticking;  // gamma
    status[k] = s;
  }
  outcome = points_.empty()     ? ContactOutcome::None
            : convexProblem(in) ? ContactOutcome::Unique
                                : ContactOutcome::Consistent;
}

int ContactStage::solve(DataImpl& d, const SolveInput& in) {
  if (int rc = classify(d.core, in)) return rc;
  joint_friction_ = in.friction != nullptr;
  dt_ = in.time_step;
  joints_.clear();
  step_without_bias_ = false;
  max_pivots_ = in.contact_max_pivots;
  if (dt_ > 0.0) stepKinds(in);
  if (joint_friction_) {
    if (int rc = checkJointFriction(d, in)) return rc;
    classifyJoints(in);
  } else if (dt_ == 0.0) {
    if (const int rc = tryAllActive(d, in); rc != 0) return rc < 0 ? rc : 0;
  }
  bool stickable = false;
  for (const Point& p : points_) stickable = stickable || p.kind == kTouching || p.kind == kSetPointRest;
  stickable = stickable && dt_ == 0.0;  // (over a time step: the general problem)
  if (stickable) {
    const int rc = trySticking(d, in);
    if (rc < 0) return rc;
    if (rc == 1) {
      reportStatus(in, true);
      return finish(d, in);
    }
  }
  capped_ = 0;  // (a bound hit by the sticking trial is not the general problem's)
  if (int rc = generalForces(d, in)) return capped_ > 0 && rc == E_NO_SOLUTION ? degradedForces(d, in) : rc;
  if (nz_ > 0)
    if (int rc = runWork(d)) return rc;
  reportStatus(in, false);
  return finish(d, in);
}

int ContactStage::finish(DataImpl& d, const SolveInput& in) {
  if (int rc = leastEffort(d, in)) return rc;  // (at the instant and over a time step)
  if (joint_friction_ || dt_ > 0.0) jointOutputs(d, in);
  return 0;
}

}  // namespace detail
}  // namespace vereshchagin
