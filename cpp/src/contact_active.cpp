// The all-active guess of the contact stage (contact_stage.hpp), tried first: every touching
// support held along its normal and every resting point with friction held tangentially, as
// constraint columns of one solve. When those columns and the task's are independent (the forces
// are then unique) and every force the columns carry is admissible (a support pushes, a sticking
// force lies inside its polygon), the guess meets every contact condition and is the answer the
// full problem would give (a resting point with friction sticks whenever every such point can):
// the final sweep follows, the complementarity problem and the least-effort programme are not
// needed. Otherwise the stage goes on with the general method. A support sliding with friction
// (its force not along the direction it holds) or the damped policy (columns not held exactly)
// skips the guess.
#include <algorithm>
#include <cmath>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

// The guess's columns: buildWorkInput's (set-points, then two tangential columns per resting point
// with friction), then one normal column per touching support not dropped (Point::dropped: it and
// its tangential columns left out).
void ContactStage::buildActiveInput(const SolveInput& in) {
  layout(in, true);
  for (Point& p : points_)
    if (p.dropped) p.stick_col = -1;
  int stick_col = user_columns;  // renumber the tangential columns without the dropped points'
  for (const Point& p : points_) stick_col += p.kind == kSetPointRest || p.kind == kSetPointSliding ? 1 : 0;
  for (Point& p : points_)
    if (p.stick_col >= 0) p.stick_col = (stick_col += 2) - 2;
  buildWorkInput(in, true);
  int col = work_.columns();
  for (std::size_t k = 0; k < points_.size(); ++k) {
    Point& p = points_[k];
    p.normal_col = -1;
    if (!in.contacts[k].isSupport() || p.kind == kSeparating || p.dropped) continue;
    ConstraintBlock b;
    b.segment = in.contacts[k].segment;
    b.columns = 1;
    b.alfa.col(0) << p.n, Vector3::Zero();
    b.point = in.contacts[k].point;
    b.classical = true;  // the point's normal acceleration held at zero
    work_.constraints.push_back(b);
    p.normal_col = col++;
  }
}

// The forces the guess's columns carry (ON the robot: -alfa nu), into `forces`. Returns -1 when
// they are admissible, else the support that pulls hardest (to drop), or -2 when a sticking force
// leaves its polygon (the guess fails).
int ContactStage::activeForces(const SolveInput& in, const Eigen::Ref<const Eigen::VectorXd>& nu) {
  int worst = -1;
  double worst_fn = 0.0;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    const PointContact& pc = in.contacts[k];
    Vector3 f = p.fixed;
    if (p.normal_col >= 0) f -= nu(p.normal_col) * p.n;
    const double fn = p.n.dot(f), tol = 1e-12 * std::max(1.0, f.norm());
    if (fn < -tol && fn < worst_fn) {  // a support would pull
      worst = static_cast<int>(k);
      worst_fn = fn;
    }
    if (p.stick_col >= 0) {
      const Vector3 ft = -nu(p.stick_col) * p.t1 - nu(p.stick_col + 1) * p.t2;
      if (!insidePolygon(p, ft, std::max(fn, 0.0), pc.mu, pc.facets)) return worst >= 0 ? worst : -2;
      f += ft;
    }
    // A support at zero normal force to round-off (its tangential force zero with it): no force.
    forces.col(k) = pc.isSupport() && fn <= 0.0 ? Vector3::Zero() : f;
  }
  return worst;
}

// A dropped support's point must not move into its surface in the solved motion.
bool ContactStage::droppedSeparate(const SolveInput& in, const Eigen::VectorXd& qdd) {
  for (std::size_t k = 0; k < points_.size(); ++k) {
    if (!points_[k].dropped) continue;
    Vector3 bias;
    const Vector3 a = pointAcceleration(in.contacts[k], qdd, bias);
    if (points_[k].n.dot(a) < -1e-9 * std::max(1.0, a.norm())) return false;
  }
  return true;
}

// The held points (normal columns, set-points, tangential columns) do not move along what they
// hold in the solved motion: false when the columns contradicted each other (the truncated
// pseudo-inverse then leaves them unmet).
bool ContactStage::heldPointsStill(const SolveInput& in, const Eigen::VectorXd& qdd) {
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    const bool normal = p.normal_col >= 0 || !in.contacts[k].isSupport();
    if (!normal && p.stick_col < 0) continue;
    Vector3 bias;
    const Vector3 a = pointAcceleration(in.contacts[k], qdd, bias);
    const double tol = 1e-8 * std::max(1.0, bias.norm());
    if (normal && std::abs(p.n.dot(a)) > tol) return false;
    if (p.stick_col >= 0 && (std::abs(p.t1.dot(a)) > tol || std::abs(p.t2.dot(a)) > tol)) return false;
  }
  return true;
}

// The admissibility rows of the forces in the null coordinates y (R y >= r): each held support
// pushes, each sticking force lies inside its polygon. Returns their number.
int ContactStage::activeRows(const SolveInput& in, int dn) {
  const auto N = act_null_.leftCols(dn);
  const auto nu0 = act_nu_.head(N.rows());
  int k = 0;
  // One row a . nu + b >= 0 with a = (coefficients at columns cols[0..3)), into R and r.
  const auto row = [&](const int* cols, const double* a, int terms, double b) {
    act_r_.row(k).head(dn).setZero();
    double value = b;
    for (int t = 0; t < terms; ++t) {
      act_r_.row(k).head(dn) += a[t] * N.row(cols[t]);
      value += a[t] * nu0(cols[t]);
    }
    act_rhs_(k++) = -value;
  };
  for (std::size_t c = 0; c < points_.size(); ++c) {
    const Point& p = points_[c];
    const PointContact& pc = in.contacts[c];
    if (p.normal_col >= 0) {  // f_n = -nu_n >= 0
      const double minus = -1.0;
      row(&p.normal_col, &minus, 1, 0.0);
    }
    if (p.stick_col < 0) continue;
    const double mc = pc.mu * std::cos(M_PI / pc.facets);
    for (int i = 0; i < pc.facets; ++i) {  // mu cos(pi/k) f_n - e_i . f_t >= 0, f_t = -(nu_1 t1 + nu_2 t2)
      const Eigen::Vector2d e = edgeCoords(i, pc.facets);
      if (p.normal_col >= 0) {
        const int cols[3] = {p.normal_col, p.stick_col, p.stick_col + 1};
        const double a[3] = {-mc, e(0), e(1)};
        row(cols, a, 3, 0.0);
      } else {  // a set-point: f_n = F
        const int cols[2] = {p.stick_col, p.stick_col + 1};
        const double a[2] = {e(0), e(1)};
        row(cols, a, 2, mc * pc.force);
      }
    }
  }
  return k;
}

// Redundant held columns (K rank-deficient): the guess's multipliers nu0 are one answer of many
// (nu0 + N y, N K's null directions, all with the same motion). The one of least motor effort
// among those whose forces are admissible, then the least contact forces (contact_effort.cpp's
// rule): min 1/2 ||tau0 + C y||^2, tau0 and C the motors' share (the task's and the set-points'
// columns) of nu0 and N; then min sum ||f||^2 among its minimisers (LexicographicQp).
int ContactStage::redundantGuess(DataImpl& d, const SolveInput& in) {
  HdCore& c = d.core;
  const int m = c.res.m, n = static_cast<int>(model_.nrOfJoints());
  int rows = 0, motor = user_columns;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    rows += (points_[k].normal_col >= 0 ? 1 : 0) + (points_[k].stick_col >= 0 ? in.contacts[k].facets : 0);
    motor += in.contacts[k].isSupport() ? 0 : 1;
  }
  reserveActive(m, rows);
  const int dn = c.nullMultipliers(act_null_.topRows(m));
  if (dn <= 0 || !heldPointsStill(in, c.res.qdd)) return 0;
  auto nu = act_nu_.head(m), masked = act_masked_.head(m);
  nu = c.nu();
  auto C = act_cmd_.topLeftCorner(n, dn);
  // The motors' torque of multipliers `x`: its task and set-point columns only.
  const auto motorTorque = [&](const auto& x, auto&& tau) {
    masked = x;
    masked.tail(m - motor).setZero();
    return c.commandTorquesOf(masked, tau) == 0;
  };
  for (int j = 0; j < dn; ++j)
    if (!motorTorque(act_null_.col(j).head(m), C.col(j))) return 0;
  if (!motorTorque(nu, act_tau_.head(n))) return 0;
  // Second rule: the least contact forces, sum ||f||^2 = sum of the surface columns' nu^2 (+ const).
  const auto Ns = act_null_.block(motor, 0, m - motor, dn);
  auto P = act_q_.topLeftCorner(dn, dn);
  P.noalias() = Ns.transpose() * Ns;
  auto pv = act_lin_.head(dn);
  pv.noalias() = Ns.transpose() * nu.tail(m - motor);
  const int k = activeRows(in, dn);
  auto y = act_y_.head(dn);
  if (lqp_.solve(C, act_tau_.head(n), P, pv, act_r_.topLeftCorner(k, dn), act_rhs_.head(k), y) != Lemke::kSolved)
    return 0;
  nu.noalias() += act_null_.topLeftCorner(m, dn) * y;
  if (activeForces(in, nu) != -1) return 0;
  if (int rc = solveWithForces(d, in)) return rc;
  reportStatus(in, true);
  return 1;
}

void ContactStage::reserveActive(int m, int rows) {
  const int n = static_cast<int>(model_.nrOfJoints());
  if (act_null_.rows() < m) {
    act_null_.resize(m, m);
    act_nu_.resize(m), act_masked_.resize(m), act_lin_.resize(m), act_y_.resize(m);
    act_q_.resize(m, m);
    act_cmd_.resize(n, m);
    act_tau_.resize(n);
  }
  if (act_r_.rows() < rows || act_r_.cols() < act_null_.cols()) {
    act_r_.resize(rows, act_null_.cols());
    act_rhs_.resize(rows);
  }
  lqp_.reserve(static_cast<int>(act_null_.cols()), static_cast<int>(act_r_.rows()));
}

int ContactStage::tryAllActive(DataImpl& d, const SolveInput& in) {
  if (d.core.options.policy != SingularityPolicy::TruncatedPseudoInverse) return 0;
  int supports = 0;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    if (points_[k].kind == kSliding && in.contacts[k].mu > 0.0) return 0;
    points_[k].dropped = false;
    supports += in.contacts[k].isSupport() ? 1 : 0;
  }
  // Unique forces: drop the support that pulls hardest and solve again, at most once per support.
  for (int round = 0; round <= supports; ++round) {
    buildActiveInput(in);
    if (runInput(d, work_) != 0) return 0;  // the general method reports what fails
    const HdCore& c = d.core;
    if (c.res.rank < c.res.m) return round == 0 ? redundantGuess(d, in) : 0;
    const int drop = activeForces(in, c.nu());
    if (drop == -2) return 0;
    if (drop >= 0) {
      points_[drop].dropped = true;
      continue;
    }
    if (round > 0 && !droppedSeparate(in, c.res.qdd)) return 0;
    for (std::size_t k = 0; k < points_.size(); ++k)
      if (points_[k].dropped) forces.col(k).setZero();
    if (int rc = solveWithForces(d, in)) return rc;
    reportStatus(in, true);
    return 1;
  }
  return 0;
}

}  // namespace detail
}  // namespace vereshchagin
