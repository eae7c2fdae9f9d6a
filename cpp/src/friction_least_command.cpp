// Stage 2 of the friction max-min: among the optimal friction vectors the one with the least
// command (FrictionCore::leastCommand, its closed form on a line and its range-space active set).
#include <algorithm>
#include <cmath>

#include "dense_small.hpp"
#include "friction_core.hpp"

namespace vereshchagin {
namespace detail {

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
void FrictionCore::leastCommand(int k) {
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
  const int r = pivotedCholeskyLeft(Q_, rows_, ns, V_, eig_, piv_, kZeroCurvature * qscale_);
  if (r == ns) return;  // null(Q_StSt) = {0}: x* is the only optimum

  // Target t = tau_cmd - x on St, tau_cmd at the stage-1 optimum from its nu; start y = x*_St
  // (feasible). (No restrict on what the solvers below write.)
  const int m = hd_->res.m;
  nu_.head(m) = nu0_.head(m);
  nu_.head(m).noalias() -= dnu_.topLeftCorner(m, k) * Eigen::Map<const Eigen::VectorXd>(x, k);
  (void)hd_->commandTorquesOf(nu_.head(m), tau_cmd_);
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
  else if (!leastActiveSet(ns, r, yscale))
    degraded_ = 2;  // its bound hit: the iterate so far (the motion is the optimum's regardless)
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
void FrictionCore::leastOnLine(int ns, int r) {
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
int FrictionCore::projectOffRange(int ns, int r) {
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
bool FrictionCore::stepToBound(int ns, double step_tol) {
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
void FrictionCore::faceMultipliers(int r, int rf) {
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
int FrictionCore::releaseIndex(int ns, int r, double mult_tol, bool bland) const {
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
// False when the iteration bound was hit (the iterate so far is kept).
bool FrictionCore::leastActiveSet(int ns, int r, double yscale) {
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
  // face-optimal value fails to decrease, releases use Bland's smallest-index rule. That is the
  // exhaustive bound (max_iterations = 0); by default the real-time bound of iterationBound(ns)
  // (at most the exhaustive one). At the bound the iterate is returned as is (false): feasible,
  // never worse than x*, with the optimum's motion. (Observed on a 7-joint arm at rest under a 6-D
  // tool task: 3.5 iterations mean.)
  long bound = ns + 1;
  for (int i = 0; i < ns && bound < 100000000L; ++i) bound *= 3;
  const long max_iterations = std::min({bound, 100000000L, iterationBound(ns)});
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
    if (release < 0) return true;
    side_(release) = 0;
    tmp_(release) = 1.0;
  }
  return false;
}

}  // namespace detail
}  // namespace vereshchagin
