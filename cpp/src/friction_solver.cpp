// Static-friction max-min on top of the Popov-Vereshchagin solver. Math in friction_solver.hpp.
#include "vereshchagin/friction_solver.hpp"

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

#include "dense_small.hpp"
#include "model_validation.hpp"

namespace vereshchagin {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
// Curvatures (eigenvalues of Q, Cholesky pivots) below this fraction of Q's scale are zero.
constexpr double kZeroCurvature = 1e-10;
// Gradient entries (accelerations) below this fraction of the gradient's scale are zero.
constexpr double kGradientTolerance = 1e-11;
}

FrictionSolver::FrictionSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options)
    : hd_(chain, root_acc, options), free_(chain, root_acc, options) {
  nj_ = hd_.nrOfJoints();
  const int n = static_cast<int>(nj_);
  qdd_ = tau_cmd_ = friction_ = limit_ = tau0_ = qdd0_ = tau_cmd0_ = Eigen::VectorXd::Zero(n);
  q_keep_ = qd_keep_ = fstatic_ = Eigen::VectorXd::Zero(n);
  f_keep_ = ChainHdSolver::Matrix6X::Zero(6, hd_.nrOfSegments());
  status_.assign(n, Moving);
  rest_ = state_ = free_idx_ = rows_ = Eigen::VectorXi::Zero(n);
  Gc_ = Q_ = work_ = L_ = V_ = N_ = B_ = Eigen::MatrixXd::Zero(n, n);
  c_ = x_ = lo_ = hi_ = grad_ = p_ = d_ = tmp_ = tmp2_ = eig_ = invdiag_ = Eigen::VectorXd::Zero(n);
  const int mcap = hd_.maxConstraints();
  dnu_ = Eigen::MatrixXd::Zero(mcap, n);
  nu0_ = nu_ = beta_keep_ = Eigen::VectorXd::Zero(mcap);
  alfa_keep_ = ChainHdSolver::Matrix6X::Zero(6, mcap);
  seg_keep_ = Eigen::VectorXi::Zero(mcap);
}

int FrictionSolver::setOptions(const SolverOptions& options) {
  const int rc = hd_.setOptions(options);
  if (rc != ChainHdSolver::E_NOERROR) return fail(rc, "%s", hd_.errorMessage());
  free_.setOptions(options);
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
  return segments ? hd_.solve(q, q_dot, alfa, beta, *segments, f_ext, tau) : hd_.solve(q, q_dot, alfa, beta, f_ext, tau);
}

int FrictionSolver::solveImpl(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                              const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa,
                              const Eigen::Ref<const Eigen::VectorXd>& beta,
                              const Eigen::Ref<const Eigen::VectorXi>* segments,
                              const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                              const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  solved_ = false;
  const long n = nj_;
  const Eigen::VectorXd& fs = friction.static_friction;
  const Eigen::VectorXd& fk = friction.kinetic_friction.size() ? friction.kinetic_friction : friction.static_friction;
  if (fs.size() != n)
    return fail(E_INVALID_FRICTION, "friction.static_friction has %ld entries, expected %ld (joints)", (long)fs.size(), n);
  if (fk.size() != n)
    return fail(E_INVALID_FRICTION, "friction.kinetic_friction has %ld entries, expected %ld (joints) or 0", (long)fk.size(), n);
  if (!std::isfinite(friction.velocity_tolerance) || friction.velocity_tolerance < 0.0)
    return fail(E_INVALID_FRICTION, "friction.velocity_tolerance must be finite and >= 0, got %g", friction.velocity_tolerance);
  for (long j = 0; j < n; ++j) {
    if (!std::isfinite(fs(j)) || fs(j) < 0.0)
      return fail(E_INVALID_FRICTION, "friction.static_friction(%ld) must be finite and >= 0, got %g", j, fs(j));
    if (!std::isfinite(fk(j)) || fk(j) < 0.0 || fk(j) > fs(j))
      return fail(E_INVALID_FRICTION, "friction.kinetic_friction(%ld) must be finite and in [0, static_friction = %g], got %g", j, fs(j), fk(j));
  }
  const bool limits = friction.lower.size() != 0 || friction.upper.size() != 0;
  if (limits) {
    if (friction.lower.size() != n || friction.upper.size() != n)
      return fail(E_INVALID_FRICTION, "friction.lower and friction.upper must have %ld entries each (or both be empty)", n);
    if (!std::isfinite(friction.limit_tolerance) || friction.limit_tolerance < 0.0)
      return fail(E_INVALID_FRICTION, "friction.limit_tolerance must be finite and >= 0, got %g", friction.limit_tolerance);
    for (long j = 0; j < n; ++j)
      if (std::isnan(friction.lower(j)) || std::isnan(friction.upper(j)) || friction.lower(j) > friction.upper(j))
        return fail(E_INVALID_FRICTION, "friction.lower(%ld) must be <= friction.upper(%ld), neither NaN, got %g and %g",
                    j, j, friction.lower(j), friction.upper(j));
  }
  if (q.size() != n || q_dot.size() != n || (ff_torques.size() != n && ff_torques.size() != 0)) {
    // Let the hybrid-dynamics solver report the size problem with its message.
    const int rc = hdSolve(q, q_dot, alfa, beta, segments, f_ext, ff_torques);
    return fail(rc, "%s", hd_.errorMessage());
  }
  if (!q_dot.allFinite()) {
    const int rc = hdSolve(q, q_dot, alfa, beta, segments, f_ext, ff_torques);
    return fail(rc, "%s", hd_.errorMessage());
  }

  // Kinetic friction of moving joints as feed-forward; collect the resting joints with friction
  // or on a limit, and the bounds of their mu (friction torque -mu): [-f, f], opened to -inf at a
  // lower limit (the reaction pushes up) and to +inf at an upper limit.
  if (!q.allFinite()) {
    const int rc = hdSolve(q, q_dot, alfa, beta, segments, f_ext, ff_torques);
    return fail(rc, "%s", hd_.errorMessage());
  }
  int k = 0;
  for (long j = 0; j < n; ++j) {
    tau0_(j) = ff_torques.size() ? ff_torques(j) : 0.0;
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
  int rc = hdSolve(q, q_dot, alfa, beta, segments, f_ext, tau0_);
  if (rc != ChainHdSolver::E_NOERROR) return fail(rc, "%s", hd_.errorMessage());
  q_keep_ = q;
  qd_keep_ = q_dot;
  has_f_ = f_ext.cols() != 0;
  if (has_f_) f_keep_ = f_ext;
  fstatic_ = fs;
  iterations_ = 0;

  if (k > 0) {
    qdd0_ = hd_.qdd();
    tau_cmd0_ = hd_.commandTorques();
    nu0_.head(hd_.constraintCount()) = hd_.nu();
    // d qdd and d nu per resting joint; tau_cmd follows from nu (commandTorquesOf), so its columns
    // are not formed.
    rc = hd_.responseColumns(rest_.head(k), Gc_.leftCols(k), Tc_.leftCols(0), dnu_.leftCols(k));
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
    leastCommand(k);
    // The outputs are affine in the friction torques: update them from the columns (no new solve).
    qdd_ = qdd0_;
    qdd_.noalias() -= Gc_.leftCols(k) * x_.head(k);
    const int m = hd_.constraintCount();
    nu_.head(m) = nu0_.head(m);
    nu_.head(m).noalias() -= dnu_.topLeftCorner(m, k) * x_.head(k);
    hd_.commandTorquesOf(nu_.head(m), tau_cmd_);
  } else {
    qdd_ = hd_.qdd();
    tau_cmd_ = hd_.commandTorques();
    nu_.head(hd_.constraintCount()) = hd_.nu();
  }
  m_keep_ = hd_.constraintCount();
  alfa_keep_.leftCols(m_keep_) = alfa;
  beta_keep_.head(m_keep_) = beta;
  has_segments_ = segments != nullptr;
  if (has_segments_) seg_keep_.head(m_keep_) = *segments;
  k_ = k;
  link_acc_known_ = k == 0;

  // Friction torques and status.
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
  // The optimum is affine in finite friction bounds, but huge values can still overflow.
  if (!(detail::bounded(qdd_) && detail::bounded(tau_cmd_) && detail::bounded(friction_) && detail::bounded(limit_) &&
        detail::bounded(nu_.head(m_keep_))))
    return fail(ChainHdSolver::E_NONFINITE_RESULT,
                "the results overflow (Inf/NaN or beyond 1e150): friction or other inputs too large (max static "
                "friction %g)",
                n ? fs.cwiseAbs().maxCoeff() : 0.0);
  solved_ = true;
  return ChainHdSolver::E_NOERROR;
}

// Free-set step. Q_FF (nf x nf) is built in work_; p_ = a solution of Q_FF p = -g_F. Returns
// true with a zero-curvature descent direction in d_ when g_F has a component in null(Q_FF)
// (rank-revealing L D L^T below).
bool FrictionSolver::freeStep(int nf) {
  auto W = work_.topLeftCorner(nf, nf);
  for (int a = 0; a < nf; ++a)
    for (int b = 0; b < nf; ++b) W(a, b) = Q_(free_idx_(a), free_idx_(b));
  auto L = L_.topLeftCorner(nf, nf);
  auto perm = rows_.head(nf);
  auto inv = invdiag_.head(nf);
  // Definite at the curvature tolerance (the usual case): no pivoting. A failure at the last
  // column is already rank-revealing (every accepted pivot > tol, the 1 x 1 remainder <= tol);
  // a failure before it restarts with pivoting (W re-gathered: the attempt overwrote it).
  const double tol = kZeroCurvature * qscale_;
  int r = detail::ldlReciprocal(W, L, perm, inv, tol, false);
  if (r < nf - 1) {
    for (int a = 0; a < nf; ++a)
      for (int b = 0; b < nf; ++b) W(a, b) = Q_(free_idx_(a), free_idx_(b));
    r = detail::ldlReciprocal(W, L, perm, inv, tol, true);
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
  // argument above holds between them: at most (P + 1) (k + 1) 3^k + P iterations in all.
  constexpr int kPrimalDualRounds = 4;
  long bound = k + 1;
  for (int i = 0; i < k && bound < 100000000L; ++i) bound *= 3;
  bound = (kPrimalDualRounds + 1) * bound + kPrimalDualRounds;
  const long max_iterations = std::min(bound, 100000000L);
  int rounds_left = kPrimalDualRounds;
  bool face_optimal = false, bland = false;
  double last_face_value = kInf;
  free_full_rank_ = false;
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
            if (x(i) > hi_(i)) state(i) = 1, changed = true;
            else if (x(i) < lo_(i)) state(i) = -1, changed = true;
          } else if ((state(i) < 0 ? -grad_(i) : grad_(i)) > tol_g) {
            state(i) = 0, changed = true;  // wrong-sign multiplier: release
          }
        }
        if (!changed) return ChainHdSolver::E_NOERROR;  // KKT point
        for (int i = 0; i < k; ++i)
          x(i) = state(i) > 0 ? hi_(i) : (state(i) < 0 ? lo_(i) : std::min(hi_(i), std::max(lo_(i), x(i))));
        last_face_value = kInf;
        continue;
      }
      const auto dir = zero_curvature ? d_.head(nf) : p_.head(nf);
      double alpha = zero_curvature ? kInf : 1.0;
      int block = -1, side = 0;
      for (int a = 0; a < nf; ++a) {
        const int i = free_idx_(a);
        const double s = dir(a);
        if (s > 0.0 && hi_(i) < kInf) {
          const double t = (hi_(i) - x(i)) / s;
          if (t < alpha) alpha = std::max(t, 0.0), block = i, side = 1;
        } else if (s < 0.0 && lo_(i) > -kInf) {
          const double t = (lo_(i) - x(i)) / s;
          if (t < alpha) alpha = std::max(t, 0.0), block = i, side = -1;
        }
      }
      if (!std::isfinite(alpha))
        return fail(E_NOT_CONVERGED,
                    "the task drives a joint into its position limit: the limit reaction would be unbounded");
      for (int a = 0; a < nf; ++a) x(free_idx_(a)) += alpha * dir(a);
      if (block >= 0) {
        state(block) = side;
        x(block) = side > 0 ? hi_(block) : lo_(block);
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
    face_optimal = false;
  }
  return fail(E_NOT_CONVERGED, "friction optimisation did not converge in %ld active-set iterations", max_iterations);
}

// Stage 2: among the optimal friction vectors (same qdd), the one minimising ||tau_cmd||^2.
// On the optimal face only the sticking resting joints' mu may change, along null(Q_StSt), and
// there tau_cmd changes by exactly the change of mu (the motion is unchanged), so the problem is
// min ||x_St + t||^2 with t = tau_cmd at the stage-1 optimum, over x_St = x*_St + N z in the box:
// a least-distance problem in z (N orthonormal), solved by a primal active-set method.
void FrictionSolver::leastCommand(int k) {
  auto x = x_.head(k);
  grad_.head(k).noalias() = Q_.topLeftCorner(k, k).lazyProduct(x);
  grad_.head(k) -= c_.head(k);  // = -(accelerations of the resting joints)
  int ns = 0;
  for (int a = 0; a < k; ++a)
    if (std::abs(grad_(a)) <= 10.0 * kGradientTolerance * gscale_) rows_(ns++) = a;
  if (ns == 0) return;
  // Sticking joints all free at the stage-1 optimum, whose free block was positive definite:
  // Q_StSt is a principal block of it, so its null space is empty and the optimum is unique.
  if (free_full_rank_) {
    bool all_free = true;
    for (int a = 0; a < ns && all_free; ++a) all_free = state_(rows_(a)) == 0;
    if (all_free) return;
  }
  // Null space of Q_StSt from its pivoted Cholesky: columns [-L1^-T L2^T; I] (pivot order),
  // orthonormalised by modified Gram-Schmidt.
  auto W = work_.topLeftCorner(ns, ns);
  for (int a = 0; a < ns; ++a)
    for (int b = 0; b < ns; ++b) W(a, b) = Q_(rows_(a), rows_(b));
  auto Lc = L_.topLeftCorner(ns, ns);
  auto perm = state_.head(ns);  // state_ is free after stage 1
  const int r = detail::pivotedCholesky(W, Lc, perm, kZeroCurvature * qscale_);
  const int dn = ns - r;
  if (dn == 0) return;
  for (int e = 0; e < dn; ++e) {
    auto col = tmp2_.head(ns);  // pivot order
    col.setZero();
    col(r + e) = 1.0;
    // Solve L1^T v = -L2^T e_e for the first r entries.
    for (int i = r - 1; i >= 0; --i) {
      double v = -Lc(r + e, i);
      for (int c = i + 1; c < r; ++c) v -= Lc(c, i) * col(c);
      col(i) = v / Lc(i, i);
    }
    for (int a = 0; a < ns; ++a) N_(perm(a), e) = col(a);
  }
  for (int e = 0; e < dn; ++e) {
    for (int f = 0; f < e; ++f) {
      const double proj = N_.col(f).head(ns).dot(N_.col(e).head(ns));
      N_.col(e).head(ns) -= proj * N_.col(f).head(ns);
    }
    N_.col(e).head(ns) /= N_.col(e).head(ns).norm();
  }
  auto N = N_.topLeftCorner(ns, dn);
  // Target: x_St = -tau_cmd_St at the stage-1 optimum (tau_cmd = tau_cmd0 - Tc x).
  const int m = hd_.constraintCount();
  nu_.head(m) = nu0_.head(m);
  nu_.head(m).noalias() -= dnu_.topLeftCorner(m, k) * x;
  hd_.commandTorquesOf(nu_.head(m), tau_cmd_);  // at the stage-1 optimum
  auto t = tmp_.head(ns);
  for (int a = 0; a < ns; ++a) t(a) = -tau_cmd_(rest_(rows_(a)));  // desired change of x_St: tau_cmd_St + change = 0
  auto z0 = d_.head(dn);
  z0.noalias() = N.transpose() * t;
  auto z = p_.head(dn);
  z.setZero();
  // Working set: rows of N (indices into St) held at a bound; side -1 lower, +1 upper.
  int nw = 0;
  Eigen::VectorXi& wrow = free_idx_;
  Eigen::VectorXi& wside = state_;
  auto lowerRoom = [&](int a) { return lo_(rows_(a)) - x(rows_(a)); };
  auto upperRoom = [&](int a) { return hi_(rows_(a)) - x(rows_(a)); };
  double zscale = 1e-300;  // largest finite bound, or the target's size
  for (int i = 0; i < k; ++i) {
    if (std::isfinite(hi_(i))) zscale = std::max(zscale, std::abs(hi_(i)));
    if (std::isfinite(lo_(i))) zscale = std::max(zscale, std::abs(lo_(i)));
  }
  zscale = std::max(zscale, z0.cwiseAbs().maxCoeff());
  for (int it = 0; it < 50 + 20 * ns; ++it) {
    // Projection of z0 onto {z : N_W z = b_W}: zp = z0 - B^T (B B^T)^-1 (B z0 - b).
    auto zp = tmp2_.head(dn);
    zp = z0;
    auto y = eig_.head(nw);
    auto B = B_.topLeftCorner(nw, dn);
    auto BBt = work_.topLeftCorner(nw, nw);
    auto L = L_.topLeftCorner(nw, nw);
    if (nw > 0) {
      for (int w = 0; w < nw; ++w) B.row(w) = N.row(wrow(w));
      BBt.noalias() = B * B.transpose();
      if (!detail::choleskyCertified(BBt, L, 1e-13)) break;  // degenerate (rows of N have norm <= 1)
      for (int w = 0; w < nw; ++w) y(w) = N.row(wrow(w)).dot(z0) - (wside(w) < 0 ? lowerRoom(wrow(w)) : upperRoom(wrow(w)));
      detail::choleskySolve(L, y);
      zp.noalias() -= B.transpose() * y;
    }
    auto step = zp - z;
    if (step.cwiseAbs().maxCoeff() <= 1e-13 * zscale) {
      if (nw == 0) break;
      // Multipliers: z - z0 = B^T (sigma .* lambda), lambda >= 0 required.
      for (int w = 0; w < nw; ++w) y(w) = B.row(w).dot(z - z0);
      detail::choleskySolve(L, y);
      int drop = -1;
      double worst = -1e-12 * std::max(z0.cwiseAbs().maxCoeff(), 1e-300);
      for (int w = 0; w < nw; ++w) {
        const double lambda = (wside(w) < 0 ? 1.0 : -1.0) * y(w);
        if (lambda < worst) worst = lambda, drop = w;
      }
      if (drop < 0) break;
      wrow(drop) = wrow(nw - 1);
      wside(drop) = wside(nw - 1);
      --nw;
      continue;
    }
    double alpha = 1.0;
    int block = -1, side = 0;
    for (int a = 0; a < ns; ++a) {
      bool in_w = false;
      for (int w = 0; w < nw; ++w) in_w = in_w || wrow(w) == a;
      if (in_w) continue;
      const double s = N.row(a).dot(step), cur = N.row(a).dot(z);
      if (s > 1e-15) {
        const double tt = (upperRoom(a) - cur) / s;
        if (tt < alpha) alpha = std::max(tt, 0.0), block = a, side = 1;
      } else if (s < -1e-15) {
        const double tt = (lowerRoom(a) - cur) / s;
        if (tt < alpha) alpha = std::max(tt, 0.0), block = a, side = -1;
      }
    }
    z += alpha * step;
    if (block >= 0) {
      wrow(nw) = block;
      wside(nw) = side;
      ++nw;
    }
  }
  for (int a = 0; a < ns; ++a) {
    const int i = rows_(a);
    x(i) = std::min(hi_(i), std::max(lo_(i), x(i) + N.row(a).dot(z)));
  }
}

const ChainHdSolver::Matrix6X& FrictionSolver::linkAccelerations() {
  if (!link_acc_known_ && solved_) {
    // One solve with the optimal friction torques as feed-forward (inputs kept from solve()).
    tmp_ = tau0_;
    for (int a = 0; a < k_; ++a) tmp_(rest_(a)) -= x_(a);
    const Eigen::Ref<const Eigen::VectorXi> segs = seg_keep_.head(m_keep_);
    hdSolve(q_keep_, qd_keep_, alfa_keep_.leftCols(m_keep_), beta_keep_.head(m_keep_), has_segments_ ? &segs : nullptr,
            has_f_ ? f_keep_.leftCols(f_keep_.cols()) : f_keep_.leftCols(0), tmp_);
    link_acc_known_ = true;
  }
  return hd_.linkAccelerations();
}

double FrictionSolver::gaussValue() {
  if (!solved_) return std::numeric_limits<double>::quiet_NaN();
  // qdd_free: unconstrained motion under ff torques and kinetic friction (tau0_).
  const Eigen::Matrix<double, 6, 0> no_alfa;
  const Eigen::Matrix<double, 0, 1> no_beta;
  const int rc = has_f_ ? free_.solve(q_keep_, qd_keep_, no_alfa, no_beta, f_keep_, tau0_)
                        : free_.solve(q_keep_, qd_keep_, no_alfa, no_beta, f_keep_.leftCols(0), tau0_);
  if (rc != ChainHdSolver::E_NOERROR) return std::numeric_limits<double>::quiet_NaN();
  // H (qdd* - qdd_free) = tau_cmd* + friction and limit torques of the resting joints.
  double z0 = 0.0, dissipation = 0.0;
  for (unsigned int j = 0; j < nj_; ++j) {
    const bool resting = status_[j] != Moving;
    const double torque = tau_cmd_(j) + (resting ? friction_(j) + limit_(j) : 0.0);
    z0 += 0.5 * (qdd_(j) - free_.qdd()(j)) * torque;
    // A sticking joint has qdd = 0: its round-off residual times a huge f (up to 1e308) must not
    // overflow the sum.
    if (resting && status_[j] != Stick) dissipation += fstatic_(j) * std::abs(qdd_(j));
  }
  return z0 + dissipation;
}

}  // namespace vereshchagin
