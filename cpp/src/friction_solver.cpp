// Static-friction max-min on top of the Popov-Vereshchagin solver. Math in friction_solver.hpp.
#include "vereshchagin/friction_solver.hpp"

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <utility>

#include "dense_small.hpp"
#include "hd_core.hpp"
#include "model_validation.hpp"

namespace vereshchagin {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
// Curvatures (eigenvalues of Q, Cholesky pivots) below this fraction of Q's scale are zero.
constexpr double kZeroCurvature = 1e-10;
// Gradient entries (accelerations) below this fraction of the gradient's scale are zero.
constexpr double kGradientTolerance = 1e-11;
}  // namespace

FrictionSolver::FrictionSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options)
    : FrictionSolver(std::make_unique<ChainHdSolver>(chain, root_acc, options)) {}

FrictionSolver::FrictionSolver(const KDL::Tree& tree, const KDL::Twist& root_acc, const SolverOptions& options,
                               const std::string& root_segment)
    : FrictionSolver(std::make_unique<TreeHdSolver>(tree, root_acc, options, root_segment)) {}

FrictionSolver::FrictionSolver(std::unique_ptr<HdSolver> hd) : hd_owner_(std::move(hd)), hd_(*hd_owner_) {
  nj_ = hd_.nrOfJoints();
  const int n = static_cast<int>(nj_);
  qdd_ = tau_cmd_ = friction_ = limit_ = tau0_ = qdd0_ = tau_cmd0_ = ff_driver_ = Eigen::VectorXd::Zero(n);
  fstatic_ = Eigen::VectorXd::Zero(n);
  status_.assign(n, Moving);
  rest_ = state_ = free_idx_ = rows_ = Eigen::VectorXi::Zero(n);
  Gc_ = Q_ = work_ = L_ = Eigen::MatrixXd::Zero(n, n);
  V_ = U_ = R_ = Eigen::MatrixXd::Zero(n, n);
  ys_ = ts_ = lam_ = Eigen::VectorXd::Zero(n);
  side_ = cols_ = piv_ = Eigen::VectorXi::Zero(n);
  c_ = x_ = lo_ = hi_ = grad_ = p_ = d_ = tmp_ = tmp2_ = eig_ = invdiag_ = dpiv_ = Eigen::VectorXd::Zero(n);
  const int mcap = hd_.maxConstraints();
  dnu_ = Eigen::MatrixXd::Zero(mcap, n);
  nu0_ = nu_ = Eigen::VectorXd::Zero(mcap);
}

int FrictionSolver::setOptions(const SolverOptions& options) {
  const int rc = hd_.setOptions(options);
  if (rc != ChainHdSolver::E_NOERROR) return fail(rc, "%s", hd_.errorMessage());
  return rc;
}

int FrictionSolver::setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                                   const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through) {
  const int rc = hd_.setPassThrough(f_ext_pass_through, ff_pass_through);
  if (rc != ChainHdSolver::E_NOERROR) return fail(rc, "%s", hd_.errorMessage());
  solved_ = false;
  return rc;
}

int FrictionSolver::fail(int code, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(message_.data(), message_.size(), fmt, args);
  va_end(args);
  solved_ = false;
  return code;
}

int FrictionSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa,
                          const Eigen::Ref<const Eigen::VectorXd>& beta,
                          const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                          const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  return solveImpl(q, q_dot, alfa, beta, nullptr, f_ext, ff_torques, friction);
}

int FrictionSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa,
                          const Eigen::Ref<const Eigen::VectorXd>& beta,
                          const Eigen::Ref<const Eigen::VectorXi>& segments,
                          const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                          const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  return solveImpl(q, q_dot, alfa, beta, &segments, f_ext, ff_torques, friction);
}

int FrictionSolver::hdSolve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                            const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa,
                            const Eigen::Ref<const Eigen::VectorXd>& beta,
                            const Eigen::Ref<const Eigen::VectorXi>* segments,
                            const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                            const Eigen::Ref<const Eigen::VectorXd>& tau) {
  // The pass-through's feed-forward driver is ff_torques alone, not the friction in tau.
  hd_.core().ws.pt.driver = &ff_driver_;
  const int rc =
      segments ? hd_.solve(q, q_dot, alfa, beta, *segments, f_ext, tau) : hd_.solve(q, q_dot, alfa, beta, f_ext, tau);
  hd_.core().ws.pt.driver = nullptr;
  return rc;
}

// Stage 0: the friction model's sizes and values (0 or E_INVALID_FRICTION with a message).
int FrictionSolver::checkFriction(const FrictionModel& friction) {
  const long n = nj_;
  const Eigen::VectorXd& fs = friction.static_friction;
  const Eigen::VectorXd& fk = friction.kinetic_friction.size() ? friction.kinetic_friction : friction.static_friction;
  if (fs.size() != n)
    return fail(E_INVALID_FRICTION, "friction.static_friction has %ld entries, expected %ld (joints)", (long)fs.size(),
                n);
  if (fk.size() != n)
    return fail(E_INVALID_FRICTION, "friction.kinetic_friction has %ld entries, expected %ld (joints) or 0",
                (long)fk.size(), n);
  if (!std::isfinite(friction.velocity_tolerance) || friction.velocity_tolerance < 0.0)
    return fail(E_INVALID_FRICTION, "friction.velocity_tolerance must be finite and >= 0, got %g",
                friction.velocity_tolerance);
  for (long j = 0; j < n; ++j) {
    if (!std::isfinite(fs(j)) || fs(j) < 0.0)
      return fail(E_INVALID_FRICTION, "friction.static_friction(%ld) must be finite and >= 0, got %g", j, fs(j));
    if (!std::isfinite(fk(j)) || fk(j) < 0.0 || fk(j) > fs(j))
      return fail(E_INVALID_FRICTION,
                  "friction.kinetic_friction(%ld) must be finite and in [0, static_friction = %g], got %g", j, fs(j),
                  fk(j));
  }
  if (friction.lower.size() == 0 && friction.upper.size() == 0) return ChainHdSolver::E_NOERROR;
  if (friction.lower.size() != n || friction.upper.size() != n)
    return fail(E_INVALID_FRICTION, "friction.lower and friction.upper must have %ld entries each (or both be empty)",
                n);
  if (!std::isfinite(friction.limit_tolerance) || friction.limit_tolerance < 0.0)
    return fail(E_INVALID_FRICTION, "friction.limit_tolerance must be finite and >= 0, got %g",
                friction.limit_tolerance);
  for (long j = 0; j < n; ++j)
    if (std::isnan(friction.lower(j)) || std::isnan(friction.upper(j)) || friction.lower(j) > friction.upper(j))
      return fail(E_INVALID_FRICTION, "friction.lower(%ld) must be <= friction.upper(%ld), neither NaN, got %g and %g",
                  j, j, friction.lower(j), friction.upper(j));
  return ChainHdSolver::E_NOERROR;
}

// Stage 1: kinetic friction of moving joints as feed-forward (into tau0_); the resting joints
// with friction or on a limit into rest_, with the bounds of their mu (friction torque -mu):
// [-f, f], opened to -inf at a lower limit (the reaction pushes up) and to +inf at an upper one.
// Returns their number k.
int FrictionSolver::restingJoints(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                                  const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  const Eigen::VectorXd& fs = friction.static_friction;
  const Eigen::VectorXd& fk = friction.kinetic_friction.size() ? friction.kinetic_friction : friction.static_friction;
  const bool limits = friction.lower.size() != 0;
  int k = 0;
  for (long j = 0; j < static_cast<long>(nj_); ++j) {
    tau0_(j) = ff_driver_(j) = ff_torques.size() ? ff_torques(j) : 0.0;
    if (std::abs(q_dot(j)) > friction.velocity_tolerance) {
      tau0_(j) -= fk(j) * (q_dot(j) > 0.0 ? 1.0 : -1.0);
      continue;
    }
    const bool at_lower = limits && q(j) <= friction.lower(j) + friction.limit_tolerance;
    const bool at_upper = limits && q(j) >= friction.upper(j) - friction.limit_tolerance;
    if (fs(j) > 0.0 || at_lower || at_upper) {
      lo_(k) = at_lower ? -kInf : -fs(j);
      hi_(k) = at_upper ? kInf : fs(j);
      rest_(k++) = static_cast<int>(j);
    }
  }
  return k;
}

// Stage 2: the max-min over the k resting joints, from the solve without static friction in hd_:
// the box QP on Q = W G W^T, the least-command tie-break, and the outputs updated from the
// response columns (they are affine in the friction torques: no new solve).
int FrictionSolver::optimiseResting(int k) {
  qdd0_ = hd_.qdd();
  tau_cmd0_ = hd_.commandTorques();
  nu0_.head(hd_.constraintCount()) = hd_.nu();
  // d qdd and d nu per resting joint; tau_cmd follows from nu (commandTorquesOf), so its columns
  // are not formed.
  int rc = hd_.responseColumns(rest_.head(k), Gc_.leftCols(k), Tc_.leftCols(0), dnu_.leftCols(k));
  if (rc != ChainHdSolver::E_NOERROR) return fail(rc, "%s", hd_.errorMessage());
  for (int a = 0; a < k; ++a) {
    c_(a) = qdd0_(rest_(a));
    for (int b = 0; b < k; ++b) Q_(a, b) = 0.5 * (Gc_(rest_(a), b) + Gc_(rest_(b), a));
  }
  // Scale of Q for every "is it zero" decision: max over the resting joints of Q_jj and of
  // 1 / D_j <= (H^-1)_jj (a task can make Q vanish up to round-off; its entries are then no
  // scale for themselves).
  qscale_ = 0.0;
  for (int a = 0; a < k; ++a)
    qscale_ = std::max({qscale_, Q_(a, a), 1.0 / hd_.articulatedInertia(static_cast<unsigned int>(rest_(a)))});
  rc = boxQp(k);
  if (rc != ChainHdSolver::E_NOERROR) return rc;
  tau_cmd_known_ = false;
  leastCommand(k);
  qdd_ = qdd0_;
  qdd_.noalias() -= Gc_.leftCols(k) * x_.head(k);
  const int m = hd_.constraintCount();
  nu_.head(m) = nu0_.head(m);
  nu_.head(m).noalias() -= dnu_.topLeftCorner(m, k) * x_.head(k);
  if (!tau_cmd_known_) hd_.commandTorquesOf(nu_.head(m), tau_cmd_);  // (else kept by leastCommand)
  return ChainHdSolver::E_NOERROR;
}

// Stage 3: friction and limit torques and the status of every joint at the optimum (k resting
// joints in rest_ with their -mu in x_).
void FrictionSolver::frictionOutputs(const Eigen::Ref<const Eigen::VectorXd>& q_dot, const FrictionModel& friction,
                                     int k) {
  const long n = nj_;
  const Eigen::VectorXd& fs = friction.static_friction;
  const Eigen::VectorXd& fk = friction.kinetic_friction.size() ? friction.kinetic_friction : friction.static_friction;
  const double acc_scale = std::max(1.0, n ? qdd_.cwiseAbs().maxCoeff() : 0.0);  // (no joints: empty)
  int a = 0;
  for (long j = 0; j < n; ++j) {
    if (std::abs(q_dot(j)) > friction.velocity_tolerance) {
      friction_(j) = -fk(j) * (q_dot(j) > 0.0 ? 1.0 : -1.0);
      limit_(j) = 0.0;
      status_[j] = Moving;
      continue;
    }
    friction_(j) = 0.0;
    limit_(j) = 0.0;
    if (a < k && rest_(a) == j) {
      // Friction holds what it can (up to f_j); a limit reaction takes the rest.
      const double total = -x_(a++);
      friction_(j) = std::min(fs(j), std::max(-fs(j), total));
      limit_(j) = total - friction_(j);
    }
    const double acc = qdd_(j);
    status_[j] = std::abs(acc) <= 1e-9 * acc_scale ? Stick : (acc > 0.0 ? SlipPositive : SlipNegative);
  }
}

int FrictionSolver::solveImpl(const Eigen::Ref<const Eigen::VectorXd>& q,
                              const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                              const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa,
                              const Eigen::Ref<const Eigen::VectorXd>& beta,
                              const Eigen::Ref<const Eigen::VectorXi>* segments,
                              const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                              const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  solved_ = false;
  const long n = nj_;
  int rc = checkFriction(friction);
  if (rc != ChainHdSolver::E_NOERROR) return rc;
  if (q.size() != n || q_dot.size() != n || (ff_torques.size() != n && ff_torques.size() != 0) || !q_dot.allFinite() ||
      !q.allFinite()) {
    // Let the hybrid-dynamics solver report the size or value problem with its message.
    rc = hdSolve(q, q_dot, alfa, beta, segments, f_ext, ff_torques);
    return fail(rc, "%s", hd_.errorMessage());
  }
  const int k = restingJoints(q, q_dot, ff_torques, friction);
  rc = hdSolve(q, q_dot, alfa, beta, segments, f_ext, tau0_);
  if (rc != ChainHdSolver::E_NOERROR) return fail(rc, "%s", hd_.errorMessage());
  fstatic_ = friction.static_friction;
  iterations_ = 0;
  if (k > 0) {
    rc = optimiseResting(k);
    if (rc != ChainHdSolver::E_NOERROR) return rc;
  } else {
    qdd_ = hd_.qdd();
    tau_cmd_ = hd_.commandTorques();
    nu_.head(hd_.constraintCount()) = hd_.nu();
  }
  m_keep_ = hd_.constraintCount();
  k_ = k;
  link_acc_known_ = k == 0;
  frictionOutputs(q_dot, friction, k);
  // The optimum is affine in finite friction bounds, but huge values can still overflow.
  if (!(detail::bounded(qdd_) && detail::bounded(tau_cmd_) && detail::bounded(friction_) && detail::bounded(limit_) &&
        detail::bounded(nu_.head(m_keep_))))
    return fail(ChainHdSolver::E_NONFINITE_RESULT,
                "the results overflow (Inf/NaN or beyond 1e150): friction or other inputs too large (max static "
                "friction %g)",
                n ? friction.static_friction.cwiseAbs().maxCoeff() : 0.0);
  solved_ = true;
  return ChainHdSolver::E_NOERROR;
}

// Free-set step. Q_FF (nf x nf) is built in work_; p_ = a solution of Q_FF p = -g_F. Returns
// true with a zero-curvature descent direction in d_ when g_F has a component in null(Q_FF)
// (rank-revealing L D L^T below).
bool FrictionSolver::freeStep(int nf) {
  auto W = work_.topLeftCorner(nf, nf);
  auto L = L_.topLeftCorner(nf, nf);
  auto perm = rows_.head(nf);
  auto inv = invdiag_.head(nf);
  const double tol = kZeroCurvature * qscale_;
  int r = nf;
  if (factor_valid_ && factor_n_ == nf) {  // kept up to date by factorDelete()
    r = factor_r_;
    for (int a = 0; a < nf; ++a) perm(a) = a;
  } else {
    for (int a = 0; a < nf; ++a)
      for (int b = 0; b < nf; ++b) W(a, b) = Q_(free_idx_(a), free_idx_(b));
    // Definite at the curvature tolerance (the usual case): no pivoting. A failure at the last
    // column is already rank-revealing (every accepted pivot > tol, the 1 x 1 remainder <= tol);
    // a failure before it restarts with pivoting (W re-gathered: the attempt overwrote it).
    r = detail::ldlReciprocal(W, L, perm, inv, tol, false);
    factor_valid_ = r >= nf - 1;  // unpivoted: can follow the blocked steps (factorDelete)
    if (factor_valid_) {
      factor_n_ = nf;
      factor_r_ = r;
      if (r == nf - 1) remainder_ = W(nf - 1, nf - 1);
      for (int a = 0; a < r; ++a) dpiv_(a) = 1.0 / inv(a);
    } else {
      for (int a = 0; a < nf; ++a)
        for (int b = 0; b < nf; ++b) W(a, b) = Q_(free_idx_(a), free_idx_(b));
      r = detail::ldlReciprocal(W, L, perm, inv, tol, true);
    }
  }
  free_full_rank_ = r == nf;
  // Q_FF(perm, perm) = [L1; L2] D [L1; L2]^T (L1 r x r unit lower). With y = L1^-1 g1 and
  // w = g2 - L2 y: Newton step p = -[L1^-T D^-1 y; 0]; when w != 0 the descent direction
  // d = [L1^-T L2^T w; -w] has Q_FF d = 0 and g^T d = -|w|^2.
  auto gp = tmp_.head(nf);  // g in pivot order
  for (int a = 0; a < nf; ++a) gp(a) = grad_(free_idx_(perm(a)));
  auto y = tmp2_.head(nf);
  for (int i = 0; i < r; ++i) {
    double v = gp(i);
    for (int c = 0; c < i; ++c) v -= L(i, c) * y(c);
    y(i) = v;
  }
  // w = g2 - L2 y, kept in y's tail.
  double wmax = 0.0;
  for (int i = r; i < nf; ++i) {
    double v = gp(i);
    for (int c = 0; c < r; ++c) v -= L(i, c) * y(c);
    y(i) = v;
    wmax = std::max(wmax, std::abs(v));
  }
  const bool zero_curvature = wmax > kGradientTolerance * gscale_;
  // Entries of w at round-off level are zero: left in, a 1e-14 component of a joint with a
  // finite bound blocks the step after a huge ratio (1e14) and hides an unbounded direction.
  if (zero_curvature)
    for (int i = r; i < nf; ++i)
      if (std::abs(y(i)) <= kGradientTolerance * gscale_) y(i) = 0.0;
  // Back substitution L1^T u = rhs, rhs = -D^-1 y1 (Newton step) or L2^T w (descent direction).
  auto u = eig_.head(nf);
  for (int i = 0; i < r; ++i) {
    double v = -y(i) * inv(i);
    if (zero_curvature) {
      v = 0.0;
      for (int t = r; t < nf; ++t) v += L(t, i) * y(t);
    }
    u(i) = v;
  }
  for (int i = r - 1; i >= 0; --i) {
    double v = u(i);
    for (int c = i + 1; c < r; ++c) v -= L(c, i) * u(c);
    u(i) = v;
  }
  for (int i = r; i < nf; ++i) u(i) = zero_curvature ? -y(i) : 0.0;
  auto out = zero_curvature ? d_.head(nf) : p_.head(nf);
  for (int a = 0; a < nf; ++a) out(perm(a)) = u(a);
  return zero_curvature;
}

// A blocked step binds the free variable at position q of free_idx_: the unpivoted L D L^T of
// Q_FF (nf x nf, from freeStep(); rank nf, or nf - 1 with the last pivot's remainder) becomes
// that of Q_FF without row and column q. The rows below q receive d_q l l^T (l = L(q+1:nf, q))
// by the rank-one update of Gill, Golub, Murray and Saunders (method C1: the pivots only grow, so
// definite stays definite), then row and column q are dropped. O(nf^2) instead of a new
// factorisation; the factor is marked invalid (refactorised) whenever the free set changes
// otherwise.
void FrictionSolver::factorDelete(int q, int nf) {
  if (!factor_valid_ || factor_n_ != nf) {
    factor_valid_ = false;
    return;
  }
  auto L = L_.topLeftCorner(nf, nf);
  auto z = tmp2_.head(nf);
  const int r = factor_r_;
  double alpha = q < r ? dpiv_(q) : 0.0;  // (the deficient last variable: nothing to pass on)
  for (int i = q + 1; i < nf; ++i) z(i) = L(i, q);
  for (int j = q + 1; j < nf && alpha != 0.0; ++j) {
    const double p = z(j);
    const double dj = j < r ? dpiv_(j) : remainder_;
    const double dbar = dj + alpha * p * p;
    if (j < r) {
      dpiv_(j) = dbar;
    } else {
      remainder_ = dbar;
      break;  // the last row: nothing below it
    }
    const double beta = p * alpha / dbar;
    alpha = dj * alpha / dbar;
    for (int i = j + 1; i < nf; ++i) {
      z(i) -= p * L(i, j);
      L(i, j) += beta * z(i);
    }
  }
  // Drop row and column q.
  for (int i = q + 1; i < nf; ++i)
    for (int c = 0; c < q; ++c) L(i - 1, c) = L(i, c);
  for (int c = q + 1; c < nf; ++c)
    for (int i = c; i < nf; ++i) L(i - 1, c - 1) = L(i, c);
  for (int j = q + 1; j < nf; ++j) dpiv_(j - 1) = dpiv_(j);
  const int n1 = nf - 1;
  int r1 = q < r ? r - 1 : n1;  // deleting the deficient last variable leaves a definite factor
  if (r1 == n1 - 1 && remainder_ > kZeroCurvature * qscale_) {
    dpiv_(r1) = remainder_;  // the update made the last pivot definite
    r1 = n1;
  }
  factor_n_ = n1;
  factor_r_ = r1;
  for (int a = 0; a < r1; ++a) invdiag_(a) = 1.0 / dpiv_(a);
}

// grad_ = Q x - c (the negated accelerations of the resting joints at friction x).
void FrictionSolver::gradient(int k) {
  for (int i = 0; i < k; ++i) {
    double v = -c_(i);
    for (int j = 0; j < k; ++j) v += Q_(j, i) * x_(j);  // Q symmetric: column i, contiguous
    grad_(i) = v;
  }
}

// Stage 1: minimise 1/2 x^T Q x - c^T x over lo <= x <= hi by a primal active-set method.
int FrictionSolver::boxQp(int k) {
  auto x = x_.head(k);
  x.setZero();  // feasible: every box contains 0
  auto state = state_.head(k);
  state.setZero();  // 0 free, -1 at lower bound, +1 at upper bound
  // Scale of the gradient (accelerations), at Q's physical scale (not Q's entries, which a task
  // can make vanish): the frictionless accelerations, what the current friction iterate causes,
  // and the torques acting (feed-forward, kinetic friction, the frictionless motor command). Not
  // what the bounds could cause: a bound far beyond what is needed (say 1e305) made every
  // gradient look like round-off and stopped at x = 0 (no friction on a slipping joint). The
  // torques matter when a task fixes the resting joints and the bounds are zero or tiny: c is
  // then round-off.
  const double cmax = std::max(c_.head(k).cwiseAbs().maxCoeff(), qdd0_.cwiseAbs().maxCoeff());
  const double torque_scale = std::max(tau0_.cwiseAbs().maxCoeff(), tau_cmd0_.cwiseAbs().maxCoeff());
  double tol_g = 0.0;
  // Iteration bound. Between two face-optimal points each iteration binds one more variable (a
  // blocked step) or ends on the face optimum (a full step): at most k + 1 iterations. The
  // objective never increases, and it strictly decreases from one face-optimal point to the next
  // (a released variable has a multiplier of the wrong sign, so the new face's minimiser is
  // strictly lower) unless a zero-length step intervenes (degeneracy); so no working set is
  // face-optimal twice and there are at most 3^k working sets: (k + 1) 3^k iterations. When a
  // face-optimal value fails to decrease (degenerate cycling risk), releases switch to Bland's
  // smallest-index rule, the classical anti-cycling safeguard. (Observed: 2-6 iterations mean.)
  //
  // Primal-dual rounds (Hintermueller, Ito and Kunisch's active-set Newton step): on a face whose
  // block is definite, the face minimiser is computed anyway; instead of stopping at the first
  // bound on the way, the working set is re-guessed from all of its bound violations and from
  // the multipliers' signs, and the iterate is clamped back into the box (feasible again). A
  // round that finds no violation and no wrong-sign multiplier has found a KKT point: optimal.
  // At most kPrimalDualRounds rounds; each may raise the objective once, so the primal
  // argument above holds between them: at most (P + 1) (k + 1) 3^k + P iterations in all. No
  // rounds when the whole Q is singular (a task fixes accelerations): its nearly singular faces
  // have minimisers far outside the box, and the rounds then cost more than the primal steps.
  // (The free-set factor updates of factorDelete() change how a step is computed, not which.)
  constexpr int kPrimalDualRounds = 4;
  long bound = k + 1;
  for (int i = 0; i < k && bound < 100000000L; ++i) bound *= 3;
  bound = (kPrimalDualRounds + 1) * bound + kPrimalDualRounds;
  const long max_iterations = std::min(bound, 100000000L);
  int rounds_left = kPrimalDualRounds;
  bool face_optimal = false, bland = false;
  double last_face_value = kInf;
  free_full_rank_ = false;
  factor_valid_ = false;
  for (long it = 0; it < max_iterations; ++it) {
    iterations_ = static_cast<int>(std::min<long>(it + 1, 2147483647L));
    gscale_ = std::max({cmax, qscale_ * x.cwiseAbs().maxCoeff(), qscale_ * torque_scale, 1e-300});
    tol_g = kGradientTolerance * gscale_;
    gradient(k);
    int nf = 0;
    for (int i = 0; i < k; ++i)
      if (state(i) == 0) free_idx_(nf++) = i;
    if (nf > 0 && !face_optimal) {
      const bool zero_curvature = freeStep(nf);
      // A singular full problem (a task fixes some accelerations) leaves nearly singular faces
      // whose minimisers overshoot far: primal steps only then.
      if (it == 0 && !free_full_rank_) rounds_left = 0;
      if (!zero_curvature && free_full_rank_ && rounds_left > 0) {
        --rounds_left;
        for (int a = 0; a < nf; ++a) x(free_idx_(a)) += p_(a);  // the face minimiser (maybe outside)
        gradient(k);
        bool changed = false;
        for (int i = 0; i < k; ++i) {
          if (state(i) == 0) {
            if (x(i) > hi_(i))
              state(i) = 1, changed = true;
            else if (x(i) < lo_(i))
              state(i) = -1, changed = true;
          } else if ((state(i) < 0 ? -grad_(i) : grad_(i)) > tol_g) {
            state(i) = 0, changed = true;  // wrong-sign multiplier: release
          }
        }
        if (!changed) return ChainHdSolver::E_NOERROR;  // KKT point
        factor_valid_ = false;
        for (int i = 0; i < k; ++i)
          x(i) = state(i) > 0 ? hi_(i) : (state(i) < 0 ? lo_(i) : std::min(hi_(i), std::max(lo_(i), x(i))));
        last_face_value = kInf;
        continue;
      }
      const auto dir = zero_curvature ? d_.head(nf) : p_.head(nf);
      double alpha = zero_curvature ? kInf : 1.0;
      int block = -1, side = 0, block_pos = -1;
      for (int a = 0; a < nf; ++a) {
        const int i = free_idx_(a);
        const double s = dir(a);
        if (s > 0.0 && hi_(i) < kInf) {
          const double t = (hi_(i) - x(i)) / s;
          if (t < alpha) alpha = std::max(t, 0.0), block = i, side = 1, block_pos = a;
        } else if (s < 0.0 && lo_(i) > -kInf) {
          const double t = (lo_(i) - x(i)) / s;
          if (t < alpha) alpha = std::max(t, 0.0), block = i, side = -1, block_pos = a;
        }
      }
      if (!std::isfinite(alpha))
        return fail(E_NOT_CONVERGED,
                    "the task drives a joint into its position limit: the limit reaction would be unbounded");
      for (int a = 0; a < nf; ++a) x(free_idx_(a)) += alpha * dir(a);
      if (block >= 0) {
        state(block) = side;
        x(block) = side > 0 ? hi_(block) : lo_(block);
        factorDelete(block_pos, nf);
        face_optimal = false;
        continue;
      }
      face_optimal = true;  // full Newton step: optimal on this face
      continue;
    }
    // Optimal on the current face: the bound multipliers must have the right sign.
    const double value = 0.5 * x.dot(grad_.head(k)) - 0.5 * c_.head(k).dot(x);  // 1/2 x'Qx - c'x
    if (!(value < last_face_value)) bland = true;
    last_face_value = value;
    int release = -1;
    double worst = tol_g;
    for (int i = 0; i < k; ++i) {
      const double violation = state(i) < 0 ? -grad_(i) : (state(i) > 0 ? grad_(i) : 0.0);
      if (violation > worst) {
        worst = violation, release = i;
        if (bland) break;  // smallest index
      }
    }
    if (release < 0) return ChainHdSolver::E_NOERROR;
    state(release) = 0;
    factor_valid_ = false;
    face_optimal = false;
  }
  return fail(E_NOT_CONVERGED, "friction optimisation did not converge in %ld active-set iterations", max_iterations);
}

// Stage 2: among the optimal friction vectors (same qdd), the one minimising ||tau_cmd||^2.
// On the optimal face only the sticking resting joints' mu (set St: zero gradient) may change,
// along null(Q_StSt), and there tau_cmd changes by exactly the change of mu while tau_cmd - mu is
// fixed (the motion, hence the total joint torque, is unchanged). With t = (tau_cmd - x)_St at the
// stage-1 optimum x* (constant on the face) and y = x_St, the problem is the least-distance QP
//
//   min_y 1/2 |y + t|^2   s.t.   lo_St <= y <= hi_St,   V^T (y - x*_St) = 0,
//
// with Q_StSt = V V^T (pivoted Cholesky, V ns x r of rank r; directions of curvature below the
// zero-curvature tolerance count as null, as in stage 1). Solved in y (range-space primal active
// set; no null-space basis): W the coordinates held at a bound, F the free ones, y feasible. The
// face minimiser is y_F + d_F with d_F = -(I - P) (y_F + t_F), P the orthogonal projector onto
// range(V_F) (column-pivoted QR V_F = U R), so V_F^T d_F = 0 and d_W = 0 keep the equality. Then
// the ratio test on F (blocking coordinate joins W), or at the face optimum the multipliers
// g_i = y_i + t_i - (V lambda)_i, i in W, with V_F lambda = P (y_F + t_F) (R lambda = U^T (y + t)):
// g_i >= 0 at a lower bound, <= 0 at an upper one, else the worst violator is released.
// A blocking coordinate i has d_i != 0 with d orthogonal to range(V) and to the e_j, j in W, so
// e_i is independent of them: V_F keeps full column rank in exact arithmetic (the QR drops a
// column only when round-off makes it dependent to 1e-9 of sqrt(Q's scale)). A null space of
// dimension 1 (ns - r = 1) is a line: closed form instead (leastOnLine).
void FrictionSolver::leastCommand(int k) {
  // Sticking rows: zero gradient Q x - c (= minus the resting joints' accelerations).
  gradient(k);
  double* __restrict x = x_.data();  // raw views of the workspace (distinct buffers, no aliasing)
  const double* __restrict grad = grad_.data();
  const double gtol = 10.0 * kGradientTolerance * gscale_;
  int* __restrict st = rows_.data();
  int ns = 0;
  for (int a = 0; a < k; ++a)
    if (std::abs(grad[a]) <= gtol) st[ns++] = a;
  if (ns == 0) return;
  // Sticking joints all free at the stage-1 optimum, whose free block was positive definite:
  // Q_StSt is a principal block of it, so its null space is empty and the optimum is unique.
  if (free_full_rank_) {
    bool all_free = true;
    for (int a = 0; a < ns && all_free; ++a) all_free = state_(st[a]) == 0;
    if (all_free) return;
  }
  const int r = detail::pivotedCholeskyLeft(Q_, rows_, ns, V_, eig_, piv_, kZeroCurvature * qscale_);
  if (r == ns) return;  // null(Q_StSt) = {0}: x* is the only optimum

  // Target t = tau_cmd - x on St, tau_cmd at the stage-1 optimum from its nu; start y = x*_St
  // (feasible). (No restrict on what the solvers below write.)
  const int m = hd_.constraintCount();
  nu_.head(m) = nu0_.head(m);
  nu_.head(m).noalias() -= dnu_.topLeftCorner(m, k) * Eigen::Map<const Eigen::VectorXd>(x, k);
  hd_.commandTorquesOf(nu_.head(m), tau_cmd_);
  double* y = ys_.data();
  double* t = ts_.data();
  double* lo = p_.data();    // bounds on St
  double* hi = eig_.data();  // (eig_ was the factorisation's scratch)
  double yscale = 1e-300;    // torque scale of y and t (|y + t| <= |x* + t| bounds the optimum)
  for (int a = 0; a < ns; ++a) {
    const int i = st[a], j = rest_(i);
    const double cmd = tau_cmd_(j);  // tau_cmd_j at x*
    y[a] = x[i];
    t[a] = cmd - x[i];
    lo[a] = lo_(i);
    hi[a] = hi_(i);
    yscale = std::max({yscale, std::abs(x[i]), std::abs(cmd)});
  }
  if (r == ns - 1)
    leastOnLine(ns, r);
  else
    leastActiveSet(ns, r, yscale);
  // x_St <- y, clipped to the box (round-off overshoot of non-blocking entries); kept only if not
  // worse than x* (a safety net: the iteration never increases the objective).
  double v_start = 0.0, v_end = 0.0;
  for (int a = 0; a < ns; ++a) {
    y[a] = std::min(hi[a], std::max(lo[a], y[a]));
    v_start += (x[st[a]] + t[a]) * (x[st[a]] + t[a]);
    v_end += (y[a] + t[a]) * (y[a] + t[a]);
  }
  // On the optimal face the motion is unchanged, so tau_cmd - x stays fixed: tau_cmd moves by the
  // change of x on St (and not elsewhere) without another pass over the chain.
  if (v_end <= v_start)
    for (int a = 0; a < ns; ++a) {
      tau_cmd_(rest_(st[a])) += y[a] - x[st[a]];
      x[st[a]] = y[a];
    }
  tau_cmd_known_ = true;
}

// Stage 2 when null(Q_StSt) has dimension 1 (r = ns - 1; e.g. a 1-D task on a 7-joint arm at rest):
// y = x* + s n with V^T n = 0 is a line, the box an interval of s, so the optimum is the clipped
// minimiser s = clip(-n^T (x* + t) / n^T n). In pivot order V = [L1; l2^T] (L1 r x r lower
// triangular, l2 the row left out): n = [-L1^-T l2; 1]. Entries |n_a| <= 1e-12 max|n| are
// round-off (a coordinate the equality pins): they do not bound s (any overshoot is clipped).
void FrictionSolver::leastOnLine(int ns, int r) {
  const int n = static_cast<int>(nj_);
  const double* __restrict V = V_.data();
  const int* __restrict piv = piv_.data();
  double* __restrict y = ys_.data();
  const double* __restrict t = ts_.data();
  const double* __restrict lo = p_.data();
  const double* __restrict hi = eig_.data();
  double* __restrict nv = d_.data();
  int q = 0;  // the row not pivoted
  for (int a = 0; a < ns; ++a) nv[a] = 1.0;
  for (int j = 0; j < r; ++j) nv[piv[j]] = 0.0;
  while (nv[q] == 0.0) ++q;
  for (int i = r - 1; i >= 0; --i) {  // L1^T u = -l2, u(i) stored at row piv(i)
    double v = -V[q + i * n];
    for (int c = i + 1; c < r; ++c) v -= V[piv[c] + i * n] * nv[piv[c]];
    nv[piv[i]] = v / V[piv[i] + i * n];
  }
  double nn = 0.0, ng = 0.0, nmax = 0.0;
  for (int a = 0; a < ns; ++a) {
    nn += nv[a] * nv[a];
    ng += nv[a] * (y[a] + t[a]);
    nmax = std::max(nmax, std::abs(nv[a]));
  }
  double s_lo = -kInf, s_hi = kInf;
  for (int a = 0; a < ns; ++a) {
    if (!(std::abs(nv[a]) > 1e-12 * nmax)) continue;
    const double inv = 1.0 / nv[a];
    const double s1 = (lo[a] - y[a]) * inv, s2 = (hi[a] - y[a]) * inv;  // +-inf without a bound
    s_lo = std::max(s_lo, std::min(s1, s2));
    s_hi = std::min(s_hi, std::max(s1, s2));
  }
  const double s = std::min(s_hi, std::max(s_lo, -ng / nn));
  for (int a = 0; a < ns; ++a) y[a] += s * nv[a];
}

// Stage 2's projection (leastActiveSet): h = (I - P) fm .* (y + t), P the projector on range(V_F)
// (V with the held rows masked by fm), so that the step -h keeps V_F^T d = 0. r = 1: lam_[0] =
// v^T g / v^T v directly; else a column-pivoted modified Gram-Schmidt V_F = U R (column c of U
// and R stays at V's column index c; cols_ holds the pivot order) and w = U^T (y_F + t_F). U R =
// V_F holds to round-off even where U loses some orthogonality (~1e-16 cond(V_F)); the two sweeps
// make h orthogonal to range(U) = range(V_F) regardless. Returns the numerical rank rf of V_F.
int FrictionSolver::projectOffRange(int ns, int r) {
  const int n = static_cast<int>(nj_);
  const double* __restrict V = V_.data();
  double* __restrict U = U_.data();
  double* __restrict R = R_.data();
  const double* __restrict y = ys_.data();
  const double* __restrict t = ts_.data();
  double* __restrict h = d_.data();
  const double* __restrict fm = tmp_.data();
  double* __restrict w = tmp2_.data();
  int* __restrict cols = cols_.data();
  const double col_tol2 = 1e-18 * qscale_;  // (1e-9 sqrt(Q's scale))^2: a dependent column of V_F
  for (int a = 0; a < ns; ++a) h[a] = fm[a] * (y[a] + t[a]);
  int rf = 0;
  if (r == 1) {  // one equality (the usual case under a full tool task): P g = v (v^T g) / (v^T v)
    double vv = 0.0, vg = 0.0;
    for (int a = 0; a < ns; ++a) {
      const double v = fm[a] * V[a];
      vv += v * v;
      vg += v * h[a];
    }
    rf = vv > col_tol2 ? 1 : 0;
    lam_(0) = rf ? vg / vv : 0.0;
    for (int a = 0; a < ns; ++a) h[a] -= fm[a] * V[a] * lam_(0);
    return rf;
  }
  for (int c = 0; c < r; ++c) {
    cols[c] = c;
    for (int a = 0; a < ns; ++a) U[a + c * n] = fm[a] * V[a + c * n];
  }
  for (; rf < r; ++rf) {
    int best = -1;
    double best_norm2 = col_tol2;
    for (int q = rf; q < r; ++q) {
      const double* __restrict u = U + cols[q] * n;
      double s = 0.0;
      for (int a = 0; a < ns; ++a) s += u[a] * u[a];
      if (s > best_norm2) best_norm2 = s, best = q;
    }
    if (best < 0) break;  // the remaining columns are (numerically) dependent
    std::swap(cols[rf], cols[best]);
    const int c = cols[rf];
    double* __restrict u = U + c * n;
    const double rjj = std::sqrt(best_norm2), inv = 1.0 / rjj;
    R[rf + c * n] = rjj;
    for (int a = 0; a < ns; ++a) u[a] *= inv;
    for (int q = rf + 1; q < r; ++q) {
      double* __restrict e = U + cols[q] * n;
      double s = 0.0;
      for (int a = 0; a < ns; ++a) s += u[a] * e[a];
      for (int a = 0; a < ns; ++a) e[a] -= s * u[a];
      R[rf + cols[q] * n] = s;
    }
  }
  for (int j = 0; j < rf; ++j) w[j] = 0.0;
  for (int pass = 0; pass < 2; ++pass)
    for (int j = 0; j < rf; ++j) {
      const double* __restrict u = U + cols[j] * n;
      double s = 0.0;
      for (int a = 0; a < ns; ++a) s += u[a] * h[a];
      for (int a = 0; a < ns; ++a) h[a] -= s * u[a];
      w[j] += s;
    }
  return rf;
}

// Stage 2's step y <- y - alpha h (alpha <= 1, the ratio test against the St bounds p_ / eig_; a
// division only for a new candidate, the held entries of h are 0). Returns true when a bound
// blocked the step: that coordinate joins the working set (side_, fm) at its bound.
bool FrictionSolver::stepToBound(int ns, double step_tol) {
  double* __restrict y = ys_.data();
  const double* __restrict lo = p_.data();
  const double* __restrict hi = eig_.data();
  const double* __restrict h = d_.data();
  double alpha = 1.0;
  int block = -1, bside = 0;
  for (int a = 0; a < ns; ++a) {
    const double s = -h[a];
    if (s > step_tol) {
      const double room = hi[a] - y[a];  // +inf without a bound
      if (room < alpha * s) alpha = std::max(room / s, 0.0), block = a, bside = 1;
    } else if (s < -step_tol) {
      const double room = lo[a] - y[a];
      if (room > alpha * s) alpha = std::max(room / s, 0.0), block = a, bside = -1;
    }
  }
  for (int a = 0; a < ns; ++a) y[a] -= alpha * h[a];
  if (block < 0) return false;
  side_(block) = bside;
  tmp_(block) = 0.0;
  y[block] = bside > 0 ? hi[block] : lo[block];
  return true;
}

// Stage 2's face multipliers: lambda from R lambda = w (basic solution: columns dropped as
// dependent get 0; r = 1 has it already from projectOffRange).
void FrictionSolver::faceMultipliers(int r, int rf) {
  if (r <= 1) return;
  const int n = static_cast<int>(nj_);
  const double* __restrict R = R_.data();
  const double* __restrict w = tmp2_.data();
  double* __restrict lam = lam_.data();
  const int* __restrict cols = cols_.data();
  for (int c = 0; c < r; ++c) lam[c] = 0.0;
  for (int j = rf - 1; j >= 0; --j) {
    const int c = cols[j];
    double v = w[j];
    for (int l = j + 1; l < rf; ++l) v -= R[j + cols[l] * n] * lam[cols[l]];
    lam[c] = v / R[j + c * n];
  }
}

// Stage 2's release: the held coordinate whose multiplier has the wrong sign by the most (the
// smallest such index under Bland's rule), or -1 at the optimum.
int FrictionSolver::releaseIndex(int ns, int r, double mult_tol, bool bland) const {
  const int n = static_cast<int>(nj_);
  int release = -1;
  double worst = mult_tol;
  for (int a = 0; a < ns; ++a) {
    if (side_(a) == 0) continue;
    double g = ys_(a) + ts_(a);
    for (int c = 0; c < r; ++c) g -= V_.data()[a + c * n] * lam_(c);
    const double violation = side_(a) < 0 ? -g : g;
    if (violation > worst) {
      worst = violation, release = a;
      if (bland) break;  // smallest index
    }
  }
  return release;
}

// Stage 2 by the range-space primal active set (see leastCommand): on ys_ (from x*_St, feasible),
// ts_, the St bounds in p_ / eig_ and Q_StSt = V V^T (V_, rank r). Rows of the working set are
// masked (tmp_ = 0) rather than gathered: every loop runs over all ns rows without indirection.
void FrictionSolver::leastActiveSet(int ns, int r, double yscale) {
  for (int a = 0; a < ns; ++a) side_(a) = 0, tmp_(a) = 1.0;  // working set empty
  // A step entry at or below step_tol is round-off (a coordinate the equality pins): it does not
  // block; the overshoot it may cause (<= step_tol) is clipped at the end.
  const double step_tol = 1e-12 * yscale;
  const double mult_tol = kGradientTolerance * yscale;
  // Iteration bound (as stage 1's): between two face optima each iteration binds one more
  // coordinate or ends on the face optimum: at most ns + 1 iterations. The objective is strictly
  // convex and never increases along a step; from one face optimum to the next it strictly
  // decreases (a released coordinate has a multiplier of the wrong sign) unless a zero-length step
  // intervenes, so no working set (3^ns with sides) is face-optimal twice: (ns + 1) 3^ns. When a
  // face-optimal value fails to decrease, releases use Bland's smallest-index rule. At the bound
  // the iterate is returned as is: feasible and never worse than x*. (Observed on a 7-joint arm
  // at rest under a 6-D tool task: 3.5 iterations mean.)
  long bound = ns + 1;
  for (int i = 0; i < ns && bound < 100000000L; ++i) bound *= 3;
  const long max_iterations = std::min(bound, 100000000L);
  bool bland = false;
  double last_face_value = kInf;
  for (long it = 0; it < max_iterations; ++it) {
    const int rf = projectOffRange(ns, r);
    const double dmax = d_.head(ns).cwiseAbs().maxCoeff();
    if (dmax > step_tol && stepToBound(ns, step_tol)) continue;
    // Face optimum (full step, or none needed): its multipliers decide a release.
    faceMultipliers(r, rf);
    const double value = (ys_.head(ns) + ts_.head(ns)).squaredNorm();
    if (!(value < last_face_value)) bland = true;
    last_face_value = value;
    const int release = releaseIndex(ns, r, mult_tol, bland);
    if (release < 0) break;
    side_(release) = 0;
    tmp_(release) = 1.0;
  }
}

const ChainHdSolver::Matrix6X& FrictionSolver::linkAccelerations() {
  if (!link_acc_known_ && solved_) {
    // The optimum's joint accelerations through the last solve's kinematics (same q, q_dot): one
    // outward pass instead of a solve with the friction torques as feed-forward.
    hd_.setJointAccelerations(qdd_);
    link_acc_known_ = true;
  }
  return hd_.linkAccelerations();
}

double FrictionSolver::gaussValue() {
  if (!solved_) return std::numeric_limits<double>::quiet_NaN();
  // H (qdd* - qdd_free) = dtau = tau_cmd* + the friction and limit torques of the resting joints,
  // with qdd_free the unconstrained motion under ff torques and kinetic friction; so
  // Z0 = 1/2 dtau^T H^-1 dtau, from the articulated inertias of hd_'s last solve (same q).
  double dissipation = 0.0;
  for (unsigned int j = 0; j < nj_; ++j) {
    const bool resting = status_[j] != Moving;
    tmp_(j) = tau_cmd_(j) + (resting ? friction_(j) + limit_(j) : 0.0);
    // A sticking joint has qdd = 0: its round-off residual times a huge f (up to 1e308) must not
    // overflow the sum.
    if (resting && status_[j] != Stick) dissipation += fstatic_(j) * std::abs(qdd_(j));
  }
  if (hd_.inverseInertiaTimes(tmp_, tmp2_) != ChainHdSolver::E_NOERROR) return std::numeric_limits<double>::quiet_NaN();
  return 0.5 * tmp_.dot(tmp2_) + dissipation;
}

}  // namespace vereshchagin
