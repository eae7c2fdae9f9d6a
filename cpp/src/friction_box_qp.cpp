// Stage 1 of the friction max-min: the box QP over the resting joints' friction torques by a
// primal active-set method (FrictionCore::boxQp and its free-set steps). Math in
// friction_solver.hpp.
#include <algorithm>
#include <cmath>

#include "dense_small.hpp"
#include "friction_core.hpp"

namespace vereshchagin {
namespace detail {

// Free-set step. Q_FF (nf x nf) is built in work_; p_ = a solution of Q_FF p = -g_F. Returns
// true with a zero-curvature descent direction in d_ when g_F has a component in null(Q_FF)
// (rank-revealing L D L^T below).
bool FrictionCore::freeStep(int nf) {
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
void FrictionCore::factorDelete(int q, int nf) {
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
void FrictionCore::gradient(int k) {
  for (int i = 0; i < k; ++i) {
    double v = -c_(i);
    for (int j = 0; j < k; ++j) v += Q_(j, i) * x_(j);  // Q symmetric: column i, contiguous
    grad_(i) = v;
  }
}

// Stage 1: minimise 1/2 x^T Q x - c^T x over lo <= x <= hi by a primal active-set method.
namespace {

constexpr int kPrimalDualRounds = 4;

}  // namespace

// boxQp's exhaustive iteration bound (derivation there): (P + 1) (k + 1) 3^k + P, capped at 1e8.
long exhaustiveIterationBound(int k) {
  long bound = k + 1;
  for (int i = 0; i < k && bound < 100000000L; ++i) bound *= 3;
  bound = (kPrimalDualRounds + 1) * bound + kPrimalDualRounds;
  return std::min(bound, 100000000L);
}

// The iterations one stage may spend (FrictionModel::max_iterations): the real-time default
// kDefaultIterationsPerJoint k + kDefaultIterationsBase (docs/friction.md, "Real-time bound"), the
// exhaustive bound for 0, else the number given (at most the exhaustive bound, which suffices).
long FrictionCore::iterationBound(int k) const {
  const long exhaustive = exhaustiveIterationBound(k);
  if (max_iterations_ == 0) return exhaustive;
  const long cap = max_iterations_ > 0 ? max_iterations_ : kDefaultIterationsPerJoint * k + kDefaultIterationsBase;
  return std::min(cap, exhaustive);
}

// Where boxQp's iteration count (iterations_, counted on from earlier rounds) must stop: at the
// instant iterationBound(k); over a step one budget for all rounds of the slide guess
// (friction_step_guess.cpp), iterationBound of the full problem's step_k_ unknowns, and with the
// exhaustive bound each round its own.
long FrictionCore::iterationEnd(int k) const {
  if (step_k_ < 0) return iterationBound(k);
  if (max_iterations_ == 0) return iterations_ + exhaustiveIterationBound(k);
  return iterationBound(step_k_);
}

int FrictionCore::boxQp(int k) {
  auto x = x_.head(k);
  x.setZero();               // feasible: every box contains 0
  state_.head(k).setZero();  // 0 free, -1 at lower bound, +1 at upper bound
  // Scale of the gradient (accelerations), at Q's physical scale (not Q's entries, which a task
  // can make vanish): the frictionless accelerations, what the current friction iterate causes,
  // and the torques acting (feed-forward, kinetic friction, the frictionless motor command). Not
  // what the bounds could cause: a bound far beyond what is needed (say 1e305) made every
  // gradient look like round-off and stopped at x = 0 (no friction on a slipping joint). The
  // torques matter when a task fixes the resting joints and the bounds are zero or tiny: c is
  // then round-off.
  const double cmax = std::max({c_.head(k).cwiseAbs().maxCoeff(), qdd0_.cwiseAbs().maxCoeff(), row_scale_});
  // (Over a step the feed-forward alone: tau0_ also holds the guessed slides' friction.)
  const Eigen::VectorXd& tau_ff = dt_ > 0.0 ? ff_driver_ : tau0_;
  const double torque_scale = std::max(tau_ff.cwiseAbs().maxCoeff(), tau_cmd0_.cwiseAbs().maxCoeff());
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
  const long max_iterations = iterationEnd(k), it0 = iterations_;
  bound_ = max_iterations;
  qp_unique_ = (k == 1 && boxQpOne(cmax, torque_scale, max_iterations)) ||
               (k == 2 && boxQpTwo(cmax, torque_scale, max_iterations));
  if (qp_unique_) return ChainHdSolver::E_NOERROR;
  int rounds_left = kPrimalDualRounds;
  bool face_optimal = false, bland = false;
  double last_face_value = kInf;
  free_full_rank_ = false;
  factor_valid_ = false;
  for (long it = it0; it < max_iterations; ++it) {
    iterations_ = static_cast<int>(std::min<long>(it + 1, 2147483647L));
    gscale_ = std::max({cmax, qscale_ * x.cwiseAbs().maxCoeff(), qscale_ * torque_scale, 1e-300});
    const double tol_g = kGradientTolerance * gscale_;
    gradient(k);
    int nf = 0;
    for (int i = 0; i < k; ++i)
      if (state_(i) == 0) free_idx_(nf++) = i;
    if (nf > 0 && !face_optimal) {
      const bool zero_curvature = freeStep(nf);
      // A singular full problem (a task fixes some accelerations) leaves nearly singular faces
      // whose minimisers overshoot far: primal steps only then.
      if (it == it0 && !free_full_rank_) rounds_left = 0;
      if (!zero_curvature && free_full_rank_ && rounds_left > 0) {
        --rounds_left;
        if (primalDualRound(k, nf, tol_g)) return ChainHdSolver::E_NOERROR;  // KKT point
        last_face_value = kInf;
        continue;
      }
      const int rc = primalStep(nf, zero_curvature, face_optimal);
      if (rc != 0) return rc;
      continue;
    }
    // Optimal on the current face: the bound multipliers must have the right sign.
    const double value = 0.5 * x.dot(grad_.head(k)) - 0.5 * c_.head(k).dot(x);  // 1/2 x'Qx - c'x
    if (!(value < last_face_value)) bland = true;
    last_face_value = value;
    const int release = wrongSignMultiplier(k, tol_g, bland);
    if (release < 0) return ChainHdSolver::E_NOERROR;
    state_(release) = 0;
    factor_valid_ = false;
    face_optimal = false;
  }
  degraded_ = 1;  // the bound is hit: the fallback (boxQpFallback) on the feasible iterate x
  boxQpFallback(k);
  return ChainHdSolver::E_NOERROR;
}

// k = 1 (over a time step usually the one joint whose slide guess was refuted): with curvature
// Q_00 above the zero-curvature tolerance the iterations below take the Newton step x = c / Q_00
// (as freeStep computes it, c times the pivot's reciprocal) in their first primal-dual round, and
// when it leaves the box clamp it to the bound and confirm the bound's multiplier in a second
// iteration. The same here, with the same iteration count and scales; a multiplier of the wrong
// sign at the bound (round-off can only make it tiny) leaves the case to the iterations.
bool FrictionCore::boxQpOne(double cmax, double torque_scale, long max_iterations) {
  const double q = Q_(0, 0), c = c_(0);
  if (!(q > kZeroCurvature * qscale_) || max_iterations - iterations_ < 2) return false;
  const double inv = 1.0 / q;
  double x = c * inv;
  int state = 0;
  if (x > hi_(0)) {
    x = hi_(0), state = 1;
  } else if (x < lo_(0)) {
    x = lo_(0), state = -1;
  }
  // (the scale of the iteration that ends: with x = 0 for the first, at the bound for the second)
  gscale_ = std::max({cmax, qscale_ * (state == 0 ? 0.0 : std::abs(x)), qscale_ * torque_scale, 1e-300});
  if (state != 0) {
    const double grad = -c + q * x;
    if ((state < 0 ? -grad : grad) > kGradientTolerance * gscale_) return false;
  }
  x_(0) = x;
  state_(0) = state;
  free_full_rank_ = true;
  factor_valid_ = false;
  iterations_ = static_cast<int>(std::min<long>(iterations_ + (state == 0 ? 1 : 2), 2147483647L));
  return true;
}

// k = 2 (two refuted slide guesses, both usually ending the step stuck): the first iteration's
// Newton step from x = 0 exactly as freeStep computes it (the unpivoted L D L^T of Q with
// reciprocal pivots, both pivots above the curvature tolerance); when it lands inside the box the
// primal-dual round finds no violation and no bound multiplier: a KKT point after one iteration.
// Anything else is left to the iterations (nothing of the workspace is touched before).
bool FrictionCore::boxQpTwo(double cmax, double torque_scale, long max_iterations) {
  const double tol = kZeroCurvature * qscale_;
  const double w00 = Q_(0, 0), w10 = Q_(1, 0);
  if (kPrimalDualRounds < 1 || max_iterations - iterations_ < 1 || !(w00 > tol)) return false;
  const double inv0 = 1.0 / w00, l10 = w10 * inv0;
  const double w11 = Q_(1, 1) - l10 * w10;
  if (!(w11 > tol)) return false;
  const double inv1 = 1.0 / w11;
  const double y0 = -c_(0), y1 = -c_(1) - l10 * y0;  // L y = g, g = -c at x = 0
  const double x1 = -y1 * inv1, x0 = -y0 * inv0 - l10 * x1;
  if (x0 > hi_(0) || x0 < lo_(0) || x1 > hi_(1) || x1 < lo_(1)) return false;
  gscale_ = std::max({cmax, 0.0, qscale_ * torque_scale, 1e-300});  // (the iteration's, at x = 0)
  x_(0) = x0, x_(1) = x1;
  state_(0) = state_(1) = 0;
  free_full_rank_ = true;
  factor_valid_ = false;
  iterations_ = static_cast<int>(std::min<long>(iterations_ + 1L, 2147483647L));
  return true;
}

// The real-time fallback when boxQp hits its bound: the last iterate x (inside the box: primal
// steps stop at bounds, primal-dual rounds clamp back into it) scaled by s in [0, 1] to the
// maximiser of the dual g(s x) = s c^T x - s^2/2 x^T Q x along the ray from 0, s = clip(c^T x /
// x^T Q x). The box contains 0 and is convex, so s x stays in it (every |mu_j| <= f_j, a limit's
// reaction on its side only); g(s x) >= max(g(0), g(x)); and c^T (s x) - (s x)^T Q (s x) >= 0: the
// friction torques do no positive work on the resulting accelerations (or end velocities over a
// step) in sum, sum_j mu_j (qdd_j + qd_j / dt) >= 0. docs/friction.md, "Real-time bound".
void FrictionCore::boxQpFallback(int k) {
  auto x = x_.head(k);
  gradient(k);  // Q x - c
  const double cx = c_.head(k).dot(x), xqx = x.dot(grad_.head(k)) + cx;
  const double s = xqx > 0.0 ? std::min(1.0, std::max(0.0, cx / xqx)) : (cx > 0.0 ? 1.0 : 0.0);
  if (s < 1.0) x *= s;
}

// A primal-dual round from the free set's minimiser p_ (boxQp): take the full step, re-guess the
// working set from every bound violation and wrong-sign multiplier, clamp x back into the box.
// True when nothing changed: x is a KKT point.
bool FrictionCore::primalDualRound(int k, int nf, double tol_g) {
  auto x = x_.head(k);
  auto state = state_.head(k);
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
  if (!changed) return true;
  factor_valid_ = false;
  for (int i = 0; i < k; ++i)
    x(i) = state(i) > 0 ? hi_(i) : (state(i) < 0 ? lo_(i) : std::min(hi_(i), std::max(lo_(i), x(i))));
  return false;
}

// A primal step along the free set's direction (the minimiser p_, or d_ of zero curvature) up to
// the first bound in the way, which joins the working set; face_optimal when no bound blocks (a
// full Newton step). E_NOT_CONVERGED when a zero-curvature direction meets no bound.
int FrictionCore::primalStep(int nf, bool zero_curvature, bool& face_optimal) {
  const auto dir = zero_curvature ? d_.head(nf) : p_.head(nf);
  double alpha = zero_curvature ? kInf : 1.0;
  int block = -1, side = 0, block_pos = -1;
  for (int a = 0; a < nf; ++a) {
    const int i = free_idx_(a);
    const double s = dir(a);
    if (s > 0.0 && hi_(i) < kInf) {
      const double t = (hi_(i) - x_(i)) / s;
      if (t < alpha) alpha = std::max(t, 0.0), block = i, side = 1, block_pos = a;
    } else if (s < 0.0 && lo_(i) > -kInf) {
      const double t = (lo_(i) - x_(i)) / s;
      if (t < alpha) alpha = std::max(t, 0.0), block = i, side = -1, block_pos = a;
    }
  }
  if (!std::isfinite(alpha))
    return fail(E_NOT_CONVERGED,
                "the task drives a joint into its position limit: the limit reaction would be unbounded");
  for (int a = 0; a < nf; ++a) x_(free_idx_(a)) += alpha * dir(a);
  if (block >= 0) {
    state_(block) = side;
    x_(block) = side > 0 ? hi_(block) : lo_(block);
    factorDelete(block_pos, nf);
    face_optimal = false;
    return 0;
  }
  face_optimal = true;  // full Newton step: optimal on this face
  return 0;
}

// At a face optimum: the bound whose multiplier has the wrong sign by the most (beyond tol_g), or
// with Bland's rule the first such; -1 if none (optimal).
int FrictionCore::wrongSignMultiplier(int k, double tol_g, bool bland) const {
  int release = -1;
  double worst = tol_g;
  for (int i = 0; i < k; ++i) {
    const double violation = state_(i) < 0 ? -grad_(i) : (state_(i) > 0 ? grad_(i) : 0.0);
    if (violation > worst) {
      worst = violation, release = i;
      if (bland) break;  // smallest index
    }
  }
  return release;
}

}  // namespace detail
}  // namespace vereshchagin
