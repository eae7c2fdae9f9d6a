// The all-active guess of the contact stage (contact_stage.hpp), tried first: every touching
// support held along its normal and every resting point with friction held tangentially. When the
// forces that hold them are unique and admissible (a support pushes, a sticking force lies inside
// its polygon), the guess meets every contact condition and is the answer the full problem would
// give (a resting point with friction sticks whenever every such point can): the results follow
// (finishHeld: linear in the forces from the base solve and the responses, or a final sweep), the
// complementarity problem is not needed. Otherwise
// the stage goes on with the general method. A support sliding with friction (its force not along
// the direction it holds) or the damped policy skips the guess.
//
// The held forces come from one base solve (the input with the set-points' columns and known
// forces) and the response to a unit force along each held direction (Data's wrench response,
// O(n) each): the directions' accelerations are a = a0 + A f, A = J dqdd the contacts' Delassus
// matrix (symmetric, positive semi-definite) in the task-constrained motion. A pivoted Cholesky
// factor of A gives its rank, a particular solution of A f = -a0 and, when the held directions are
// redundant, A's null directions: the forces f0 + N y all hold the points, and the one of least
// motor effort, then of least contact force, is taken among the admissible ones (LexicographicQp).
// A support that would pull is dropped (its rows left out, no new sweep), once per support at most.
#include <algorithm>
#include <cmath>
#include <limits>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "dense_small.hpp"
#include "hd_core.hpp"
#include "model_validation.hpp"

namespace vereshchagin {
namespace detail {

// Every direction the guess may hold, once per solve: a touching support's normal (not
// separating), then a resting point's two tangents (with friction); their unit forces, wrenches
// about the segment's tip origin, acceleration rows J^T e and a0 (base solve's accelerations).
int ContactStage::heldDirections(DataImpl& d, const SolveInput& in) {
  const int n = nv_;
  int h = 0;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    const bool normal = in.contacts[k].isSupport() && p.kind != kSeparating;
    const bool tangents = p.kind == kTouching || p.kind == kSetPointRest;
    act_normal_(k) = normal ? h : -1;
    act_tangent_(k) = tangents ? h + (normal ? 1 : 0) : -1;
    const int count = (normal ? 1 : 0) + (tangents ? 2 : 0);
    if (count == 0) continue;
    Vector6 bias;
    pointKinematics(in.contacts[k], bias);
    const Vector3 acc = jac_.topRows<3>() * d.core.res.qdd + bias.head<3>();
    const Vector3 dirs[3] = {p.n, p.t1, p.t2};
    for (int c = normal ? 0 : 1; c < (tangents ? 3 : 1); ++c, ++h) {
      const Vector3& e = dirs[c];
      act_dirs_.col(h) = e;
      act_seg_(h) = in.contacts[k].segment;
      act_wrench_.col(h) << e, p.r.cross(e);
      act_rows_.col(h).head(n).noalias() = jac_.topRows<3>().transpose() * e;
      act_a0_(h) = e.dot(acc);
    }
  }
  return h;
}

// The directions' response (dqdd, dnu, the motors' torques per unit force) and Delassus matrix.
int ContactStage::heldResponse(DataImpl& d, int h) {
  HdCore& c = d.core;
  const int n = nv_, m = c.res.m;
  auto dqdd = act_dqdd_.topLeftCorner(n, h);
  auto T = act_cmd_.topLeftCorner(n, h);
  if (m > 0) {
    Eigen::Ref<Eigen::MatrixXd> dnu(act_dnu_.topLeftCorner(m, h));
    if (c.wrenchResponse(act_seg_.head(h), act_wrench_.leftCols(h), dqdd, &dnu) != 0) return -1;
    if (h <= m) {
      for (int i = 0; i < h; ++i)
        if (c.commandTorquesOf(act_dnu_.col(i).head(m), T.col(i)) != 0) return -1;
    } else {  // the torques are linear in nu: one pass per constraint column, then T = T_nu dnu
      auto Tnu = act_tnu_.topLeftCorner(n, m);
      auto e = act_enu_.head(m);
      for (int i = 0; i < m; ++i) {
        e.setZero();
        e(i) = 1.0;
        if (c.commandTorquesOf(e, Tnu.col(i)) != 0) return -1;
      }
      T.noalias() = Tnu.lazyProduct(act_dnu_.topLeftCorner(m, h));
    }
  } else {
    if (c.wrenchResponse(act_seg_.head(h), act_wrench_.leftCols(h), dqdd, nullptr) != 0) return -1;
    T.setZero();
  }
  auto A = act_del_.topLeftCorner(h, h);
  A.noalias() = act_rows_.topLeftCorner(n, h).transpose().lazyProduct(dqdd);
  for (int i = 0; i < h; ++i)  // symmetric to round-off: its mean
    for (int j = 0; j < i; ++j) A(i, j) = A(j, i) = 0.5 * (A(i, j) + A(j, i));
  act_tau0_.head(n) = c.res.tau_cmd;
  // The scale of A without the constraints (rank decisions are relative to it: the task may hold
  // a direction completely, A's entries then round-off): |J^T e|^2 sum_i D_i^-1, the articulated
  // inertias' inverse along the joints bounding the diagonal of M^-1 from above up to n.
  double inv_inertia = 0.0;
  for (unsigned int i = 0; i < c.model.ns; ++i)
    if (c.model.seg[i].joint >= 0) inv_inertia += c.ws.seg[i].Dinv;
  act_scale_ = 0.0;
  for (int i = 0; i < h; ++i)
    act_scale_ = std::max({act_scale_, A(i, i), act_rows_.col(i).head(n).squaredNorm() * inv_inertia});
  return 0;
}

// The active directions of this round (not dropped) into act_idx_, with Point::normal_col and
// stick_col renumbered as positions in it (the statuses read stick_col). Returns their number.
int ContactStage::activeDirections() {
  int k = 0;
  for (std::size_t c = 0; c < points_.size(); ++c) {
    Point& p = points_[c];
    p.normal_col = p.stick_col = -1;
    if (p.dropped) continue;
    if (act_normal_(c) >= 0) act_idx_(p.normal_col = k++) = act_normal_(c);
    if (act_tangent_(c) >= 0) {
      p.stick_col = k;
      act_idx_(k++) = act_tangent_(c);
      act_idx_(k++) = act_tangent_(c) + 1;
    }
  }
  return k;
}

// The forces of the active values x (act_idx_'s order) into `forces`. Returns -1 when they are
// admissible, else the support that pulls hardest (to drop), or -2 when a sticking force leaves
// its polygon (the guess fails).
int ContactStage::activeForces(const SolveInput& in, const Eigen::Ref<const Eigen::VectorXd>& x) {
  int worst = -1;
  double worst_fn = 0.0;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    const PointContact& pc = in.contacts[k];
    Vector3 f = p.fixed;
    if (p.normal_col >= 0) f += x(p.normal_col) * p.n;
    const double fn = p.n.dot(f), tol = 1e-12 * std::max(1.0, f.norm());
    if (fn < -tol && fn < worst_fn) {  // a support would pull
      worst = static_cast<int>(k);
      worst_fn = fn;
    }
    if (p.stick_col >= 0) {
      const Vector3 ft = x(p.stick_col) * p.t1 + x(p.stick_col + 1) * p.t2;
      if (!insidePolygon(p, ft, std::max(fn, 0.0), pc.mu, pc.facets) &&
          !(act_edge_tol_ > 0.0 && polygonExcess(p, ft, std::max(fn, 0.0), pc) <= act_edge_tol_ * std::max(1.0, fn)))
        return worst >= 0 ? worst : -2;
      f += ft;
    }
    // A support at zero normal force to round-off (its tangential force zero with it): no force.
    forces.col(k) = pc.isSupport() && fn <= 0.0 ? Vector3::Zero() : f;
  }
  return worst;
}

// How far the tangential force ft lies outside the polygon mu fn conv{d_j}: the largest
// e_i . ft - mu fn cos(pi / facets) over the edges (<= 0 inside).
double ContactStage::polygonExcess(const Point& p, const Vector3& ft, double fn, const PointContact& pc) {
  const double apothem = pc.mu * fn * std::cos(M_PI / pc.facets);
  double excess = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < pc.facets; ++i) excess = std::max(excess, edgeNormal(p, i, pc.facets).dot(ft) - apothem);
  return excess;
}

// A dropped support's point must not move into its surface: n . a >= 0 (to round-off), with the
// accelerations a = a0 + A f of the active values x.
bool ContactStage::droppedSeparate(const Eigen::Ref<const Eigen::VectorXd>& x, int k) {
  for (std::size_t c = 0; c < points_.size(); ++c) {
    if (!points_[c].dropped || act_normal_(c) < 0) continue;
    const int row = act_normal_(c);
    double an = act_a0_(row);
    for (int i = 0; i < k; ++i) an += act_del_(row, act_idx_(i)) * x(i);
    if (an < -1e-9 * std::max({1.0, std::abs(act_a0_(row)), std::abs(an)})) return false;
  }
  return true;
}

// The held points do not move along what they hold: |a0 + A f| on every active row within
// round-off of the accelerations (else the directions contradicted each other and the task).
bool ContactStage::heldRowsStill(const Eigen::Ref<const Eigen::VectorXd>& x, int k) {
  double scale = 1.0;
  for (int i = 0; i < k; ++i) scale = std::max(scale, std::abs(act_a0_(act_idx_(i))));
  for (int i = 0; i < k; ++i) {
    double a = act_a0_(act_idx_(i));
    for (int j = 0; j < k; ++j) a += act_del_(act_idx_(i), act_idx_(j)) * x(j);
    if (std::abs(a) > 1e-8 * scale) return false;
  }
  return true;
}

// The sticking trial's check (contact_forces.cpp): the held points (set-points, tangential
// columns) do not move along what they hold in the solved motion: false when the columns
// contradicted each other (the truncated pseudo-inverse then leaves them unmet).
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

// Pivoted Cholesky of S = A(idx, idx) (k active directions; pivots above rcond times A's scale,
// heldResponse()): S = V V^T, V lower trapezoidal in pivot order, L1(i, j) = V(piv(i), j). Into act_x_
// the solution of S x = -a0 on the pivots (zero elsewhere) and into act_null_ (k x (k - r)) S's
// null directions, one per position b not pivoted: z(b) = 1, z(piv) = -L1^-T V(b, :)^T. Returns
// the rank r.
int ContactStage::factorActive(int k, double rcond) {
  auto V = act_v_.topLeftCorner(k, k);
  const int r = k == 0 ? 0 : pivotedCholeskyLeft(act_del_, act_idx_, k, V, act_diag_, act_piv_, rcond * act_scale_);
  auto x = act_x_.head(k);
  auto w = act_w_.head(std::max(r, 1));
  x.setZero();
  for (int i = 0; i < r; ++i) w(i) = -act_a0_(act_idx_(act_piv_(i)));
  pivotedForward(V, act_piv_, r, w);
  pivotedBackward(V, act_piv_, r, w);
  for (int i = 0; i < r; ++i) x(act_piv_(i)) = w(i);
  int dn = 0;
  constexpr double kDone = -std::numeric_limits<double>::infinity();  // pivotedCholeskyLeft's mark
  for (int b = 0; b < k && r < k; ++b) {
    if (act_diag_(b) == kDone) continue;  // a pivot
    auto z = act_null_.col(dn++).head(k);
    z.setZero();
    z(b) = 1.0;
    for (int j = 0; j < r; ++j) w(j) = -V(b, j);
    pivotedBackward(V, act_piv_, r, w);
    for (int i = 0; i < r; ++i) z(act_piv_(i)) = w(i);
  }
  return r;
}

// The admissibility rows in the null coordinates y (R y >= r, forces x + N y): each held support
// pushes, each sticking force lies inside its polygon. Returns their number.
int ContactStage::activeRows(const SolveInput& in, int k, int dn) {
  const auto N = act_null_.topLeftCorner(k, dn);
  const auto x = act_x_.head(k);
  int rows = 0;
  for (std::size_t c = 0; c < points_.size(); ++c) {
    const Point& p = points_[c];
    const PointContact& pc = in.contacts[c];
    // f_n >= 0; implied by the polygon's rows when the point has them (their sum is
    // facets mu cos(pi / facets) f_n >= 0, the edge normals summing to zero).
    if (p.normal_col >= 0 && p.stick_col < 0) {
      act_r_.row(rows).head(dn) = N.row(p.normal_col);
      act_rhs_(rows++) = -x(p.normal_col);
    }
    if (p.stick_col < 0) continue;
    const int s = p.stick_col;
    const double mc = pc.mu * std::cos(M_PI / pc.facets);
    for (int i = 0; i < pc.facets; ++i) {  // mu cos(pi/k) f_n - e_i . f_t >= 0 (f_n = F for a set-point)
      const Eigen::Vector2d e = edgeCoords(i, pc.facets);
      auto row = act_r_.row(rows).head(dn);
      row = -e(0) * N.row(s) - e(1) * N.row(s + 1);
      double value = -e(0) * x(s) - e(1) * x(s + 1);
      if (p.normal_col >= 0) {
        row += mc * N.row(p.normal_col);
        value += mc * x(p.normal_col);
      } else {
        value += mc * pc.force;
      }
      act_rhs_(rows++) = -value;
    }
  }
  return rows;
}

// Redundant held directions: the forces x + N y all hold the points with the same motion. The one
// of least motor effort among the admissible ones, then the least contact forces (contact_effort's
// rule): min 1/2 ||tau0 + C y||^2 with tau0 the motors' torques at x and C = T N, then
// min 1/2 ||x + N y||^2 among its minimisers (LexicographicQp).
int ContactStage::redundantGuess(DataImpl& d, const SolveInput& in, int k, int dn) {
  const int n = nv_;
  const auto N = act_null_.topLeftCorner(k, dn);
  auto x = act_x_.head(k);
  auto tau0 = act_tau_.head(n);
  auto C = act_c_.topLeftCorner(n, dn);
  auto Tk = act_tk_.topLeftCorner(n, k);  // the active directions' torque columns
  for (int i = 0; i < k; ++i) Tk.col(i) = act_cmd_.col(act_idx_(i));
  tau0 = act_tau0_.head(n);
  tau0.noalias() += Tk * x;
  C.noalias() = Tk.lazyProduct(N);
  auto P = act_q_.topLeftCorner(dn, dn);
  P.noalias() = N.transpose().lazyProduct(N);
  auto pv = act_lin_.head(dn);
  pv.noalias() = N.transpose() * x;
  const int rows = activeRows(in, k, dn);
  auto y = act_y_.head(dn);
  if (lqp_.solve(C, tau0, P, pv, act_r_.topLeftCorner(rows, dn), act_rhs_.head(rows), y) != Lemke::kSolved) return 0;
  x.noalias() += N * y;
  // The least effort puts forces on polygon edges: accept them to the programme's round-off.
  act_edge_tol_ = 1e-9;
  const int admissible = activeForces(in, x);
  act_edge_tol_ = 0.0;
  if (admissible != -1) return 0;
  if (int rc = finishHeld(d, in)) return rc;
  reportStatus(in, true);
  return 1;
}

// The results of the held forces (`forces`, the active directions of activeDirections()). On a
// fixed base with supports only and no pass-through they are linear in the forces from the base
// solve and the held directions' responses (heldResponse): qdd, nu and the motors' torques move by
// each direction's response times the force's component along it (a contact's held directions
// are orthonormal: n, t1, t2), the segments' accelerations follow from qdd (accelerationsOf). The
// final sweep would give the same to round-off: the forces enter as wrenches, linearly, and its
// constraints and articulated inertias are the base solve's. Else (set-points: their columns
// become known forces; a floating base; pass-through) that sweep runs (solveWithForces).
int ContactStage::finishHeld(DataImpl& d, const SolveInput& in) {
  HdCore& c = d.core;
  bool linear = !c.model.floating && c.res.solved && !d.weights.f_any && !d.weights.t_any;
  for (std::size_t k = 0; k < points_.size() && linear; ++k) linear = in.contacts[k].isSupport();
  if (!linear) return solveWithForces(d, in);
  const int m = c.res.m;
  // Each force's components along its held directions, at their positions (act_w_: free now).
  auto coef = act_w_.head(act_idx_.size());
  coef.setZero();
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const Point& p = points_[k];
    const Vector3 f = forces.col(k);
    if (p.normal_col >= 0) coef(p.normal_col) = p.n.dot(f);
    if (p.stick_col >= 0) coef(p.stick_col) = p.t1.dot(f), coef(p.stick_col + 1) = p.t2.dot(f);
  }
  // The update's round-off, sum_i |coef_i| |dqdd_i| eps per term, must be negligible against the
  // accelerations (ill-conditioned held directions give forces far above the problem's scale,
  // whose responses cancel): else the sweep, which carries the forces through the dynamics.
  double terms = 0.0;
  for (int i = 0; i < coef.size(); ++i)
    if (coef(i) != 0.0) terms += std::abs(coef(i)) * act_dqdd_.col(act_idx_(i)).head(nv_).cwiseAbs().maxCoeff();
  const double scale = std::max(1.0, c.res.qdd.head(nv_).cwiseAbs().maxCoeff());
  if (!(terms * std::numeric_limits<double>::epsilon() * static_cast<double>(coef.size()) <= 1e-12 * scale))
    return solveWithForces(d, in);
  auto qdd = c.res.qdd.head(nv_);
  auto tau = c.res.tau_cmd.head(nv_);
  double* nu = c.res.general ? c.res.nu_user.data() : c.res.nu.data();
  for (int i = 0; i < coef.size(); ++i) {
    const double value = coef(i);
    if (value == 0.0) continue;
    const int h = act_idx_(i);
    qdd.noalias() += value * act_dqdd_.col(h).head(nv_);
    tau.noalias() += value * act_cmd_.col(h).head(nv_);
    for (int j = 0; j < m; ++j) nu[j] += value * act_dnu_(j, h);
  }
  // (beyond the sweep's bounds: the sweep, which reports it)
  if (!bounded(qdd) || !bounded(tau) || !bounded(Eigen::Map<const Eigen::VectorXd>(nu, m)))
    return solveWithForces(d, in);
  c.accelerationsOf(qdd);
  return 0;
}

void ContactStage::reserveActive(int directions, int rows) {
  const int n = nv_, h = std::max(directions, 1);
  if (act_del_.rows() < h) {
    act_seg_.resize(h), act_idx_.resize(h), act_piv_.resize(h);
    act_dirs_.resize(3, h), act_wrench_.resize(6, h);
    act_rows_.resize(n, h), act_dqdd_.resize(n, h), act_cmd_.resize(n, h), act_tk_.resize(n, h), act_c_.resize(n, h);
    act_del_.resize(h, h), act_v_.resize(h, h), act_null_.resize(h, h), act_q_.resize(h, h);
    act_a0_.resize(h), act_x_.resize(h), act_w_.resize(h), act_diag_.resize(h), act_lin_.resize(h), act_y_.resize(h);
    act_tau_.resize(n), act_tau0_.resize(n);
  }
  if (act_dnu_.cols() < act_del_.cols() || act_dnu_.rows() < work_.columns())
    act_dnu_.resize(std::max<Eigen::Index>(work_.columns(), act_dnu_.rows()), act_del_.cols());
  if (act_tnu_.cols() < work_.columns()) act_tnu_.resize(n, work_.columns()), act_enu_.resize(work_.columns());
  if (act_normal_.size() < static_cast<Eigen::Index>(points_.size()))
    act_normal_.resize(points_.size()), act_tangent_.resize(points_.size());
  if (act_r_.rows() < rows || act_r_.cols() < act_del_.cols()) {
    act_r_.resize(std::max<Eigen::Index>(rows, act_r_.rows()), act_del_.cols());
    act_rhs_.resize(act_r_.rows());
  }
  lqp_.reserve(static_cast<int>(act_del_.cols()), static_cast<int>(act_r_.rows()));
}

int ContactStage::tryAllActive(DataImpl& d, const SolveInput& in) {
  if (d.core.options.policy != SingularityPolicy::TruncatedPseudoInverse) return 0;
  int supports = 0, directions = 0, rows = 0;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    const PointContact& pc = in.contacts[k];
    if (points_[k].kind == kSliding && pc.mu > 0.0) return 0;
    points_[k].dropped = false;
    supports += pc.isSupport() ? 1 : 0;
    directions += 3;
    rows += 1 + pc.facets;
  }
  layout(in, true);                       // the set-points' known forces, the tangents
  buildWorkInput(in, false);              // the base solve: the set-points' columns and known forces
  if (runInput(d, work_) != 0) return 0;  // the general method reports what fails
  reserveActive(directions, rows);
  const int h = heldDirections(d, in);
  if (h > 0 && heldResponse(d, h) != 0) return 0;
  // Unique forces: drop the support that pulls hardest and solve again, at most once per support.
  for (int round = 0; round <= supports; ++round) {
    const int k = activeDirections();
    const int r = factorActive(k, d.core.options.rcond);
    const auto x = act_x_.head(k);
    if (r < k) {
      if (round > 0 || !heldRowsStill(x, k)) return 0;
      return redundantGuess(d, in, k, k - r);
    }
    const int drop = activeForces(in, x);
    if (drop == -2) return 0;
    if (drop >= 0) {
      points_[drop].dropped = true;
      continue;
    }
    if (round > 0 && !droppedSeparate(x, k)) return 0;
    for (std::size_t c = 0; c < points_.size(); ++c)
      if (points_[c].dropped) forces.col(c).setZero();
    if (int rc = finishHeld(d, in)) return rc;
    reportStatus(in, true);
    return 1;
  }
  return 0;
}

}  // namespace detail
}  // namespace vereshchagin
