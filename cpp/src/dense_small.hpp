// Small dense symmetric linear algebra on preallocated storage (no heap allocation): Cholesky
// with a pivot threshold and its multi-column solve, rank-revealing L D L^T and pivoted Cholesky
// for the positive semi-definite matrices of the friction optimisation (dimension <= joints),
// eigen-decompositions (Householder tridiagonalisation and implicit QR; cyclic Jacobi), and the
// smallest eigenvalue of a symmetric matrix.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace vereshchagin {
namespace detail {

using MatBlock = Eigen::Block<Eigen::MatrixXd>;
using VecBlock = Eigen::VectorBlock<Eigen::VectorXd>;

// A = L L^T into the lower triangle of L (k x k, column-major storage). Fails (false) when a
// pivot is not above min_pivot, i.e. when A is not safely positive definite at the caller's scale.
// Column j of L accumulates A(j.., j) - sum_p L(j.., p) L(j, p) in place with p in order (each
// entry's sum in the same order as a dot product's: the same values), down contiguous columns.
template <typename MA, typename ML>
bool choleskyCertified(const MA& A, ML& L, double min_pivot) {
  const int k = static_cast<int>(A.rows());
  for (int j = 0; j < k; ++j) {
    double* lj = &L(0, j);
    for (int i = j; i < k; ++i) lj[i] = A(i, j);
    for (int p = 0; p < j; ++p) {
      const double* lp = &L(0, p);
      const double ljp = lp[j];
      for (int i = j; i < k; ++i) lj[i] -= lp[i] * ljp;
    }
    const double d = lj[j];
    if (!(d > min_pivot)) return false;
    const double ljj = std::sqrt(d);
    lj[j] = ljj;
    for (int i = j + 1; i < k; ++i) lj[i] /= ljj;
  }
  return true;
}

// ||L^-1||_F^2 of a lower-triangular L (k x k), column by column of L^-1 by forward substitution;
// x: scratch of at least k entries. 1 / ||L^-1||_F^2 <= 1 / ||L^-1||_2^2 = lambda_min(L L^T).
template <typename ML, typename VX>
double inverseFrobeniusSquared(const ML& L, VX& x) {
  const int k = static_cast<int>(L.rows());
  double frob2 = 0.0;
  for (int c = 0; c < k; ++c) {
    for (int i = c; i < k; ++i) {
      double v = i == c ? 1.0 : 0.0;
      for (int p = c; p < i; ++p) v -= L(i, p) * x(p);
      x(i) = v / L(i, i);
      frob2 += x(i) * x(i);
    }
  }
  return frob2;
}

// An upper bound of ||L^-1||_2^2 for a lower-triangular L with a positive diagonal, in k^2
// operations where ||L^-1||_F^2 takes k^3 / 3: with M(L) the comparison matrix (|L(i, i)| on the
// diagonal, -|L(i, j)| off it), |L^-1| <= M(L)^-1 entrywise and M(L)^-1 >= 0 (N. J. Higham,
// Accuracy and Stability of Numerical Algorithms, 2nd ed., SIAM 2002, Theorem 8.12), so
// ||L^-1||_inf <= max_i (M^-1 1)_i, ||L^-1||_1 <= max_i (M^-T 1)_i, and ||L^-1||_2^2 <=
// ||L^-1||_1 ||L^-1||_inf. Both substitutions only add non-negative terms (relative round-off
// below 2 k eps, covered by the factor 1 + 1e-10). It can exceed ||L^-1||_2^2 by a factor growing
// with k (up to 2^k): callers fall back to inverseFrobeniusSquared() when it is not enough.
// x: scratch of at least k entries.
template <typename ML, typename VX>
double inverseNormBound(const ML& L, VX& x) {
  const int k = static_cast<int>(L.rows());
  double row_max = 0.0, col_max = 0.0;
  for (int i = 0; i < k; ++i) x(i) = 1.0;
  for (int j = 0; j < k; ++j) {  // x = M^-1 1, by columns
    const double xj = x(j) / L(j, j);
    x(j) = xj;
    row_max = std::max(row_max, xj);
    for (int i = j + 1; i < k; ++i) x(i) += std::abs(L(i, j)) * xj;
  }
  for (int i = k - 1; i >= 0; --i) {  // x = M^-T 1
    double v = 1.0;
    for (int p = i + 1; p < k; ++p) v += std::abs(L(p, i)) * x(p);
    x(i) = v / L(i, i);
    col_max = std::max(col_max, x(i));
  }
  return row_max * col_max * (1.0 + 1e-10);
}

// Per-eigenvalue multipliers of a symmetric positive semi-definite matrix's (pseudo-)inverse
// under a singularity policy: truncated (1 / lambda for lambda > cut, else 0) or damped least
// squares (lambda / (lambda^2 + damping^2)). Negative round-off eigenvalues count as 0. Returns
// the rank: the number of eigenvalues above cut.
template <typename VL, typename VI>
int policyMultipliers(const VL& lam, VI& inv, double cut, bool truncate, double damping) {
  int rank = 0;
  for (Eigen::Index k = 0; k < lam.size(); ++k) {
    const double l = std::max(lam(k), 0.0);
    const bool kept = l > 0.0 && l > cut;
    if (kept) ++rank;
    inv(k) = truncate ? (kept ? 1.0 / l : 0.0) : l / (l * l + damping * damping);
  }
  return rank;
}

// Solve L L^T x = b in place (b -> x).
template <typename ML, typename VB>
void choleskySolve(const ML& L, VB& b) {
  const int k = static_cast<int>(L.rows());
  for (int i = 0; i < k; ++i) {
    double v = b(i);
    for (int p = 0; p < i; ++p) v -= L(i, p) * b(p);
    b(i) = v / L(i, i);
  }
  for (int i = k - 1; i >= 0; --i) {
    double v = b(i);
    for (int p = i + 1; p < k; ++p) v -= L(p, i) * b(p);
    b(i) = v / L(i, i);
  }
}

// Solve L L^T X = B in place for every column of B (k x c) at once: the row recursions are shared
// by the columns (no per-column dependency chain), one reciprocal per pivot.
template <typename ML, typename MB>
void choleskySolveColumns(const ML& L, MB& B) {
  const int k = static_cast<int>(L.rows());
  const Eigen::Index nc = B.cols();
  for (int i = 0; i < k; ++i) {
    const double inv = 1.0 / L(i, i);
    for (Eigen::Index c = 0; c < nc; ++c) {
      double v = B(i, c);
      for (int p = 0; p < i; ++p) v -= L(i, p) * B(p, c);
      B(i, c) = v * inv;
    }
  }
  for (int i = k - 1; i >= 0; --i) {
    const double inv = 1.0 / L(i, i);
    for (Eigen::Index c = 0; c < nc; ++c) {
      double v = B(i, c);
      for (int p = i + 1; p < k; ++p) v -= L(p, i) * B(p, c);
      B(i, c) = v * inv;
    }
  }
}

// Right-looking square-root-free factorisation W(perm, perm) = L D L^T, L (k x r) unit lower
// trapezoidal (its unit diagonal is not stored), D = diag(1 / invdiag(0..r-1)). pivot = true: the
// largest remaining diagonal entry is the next pivot (rank-revealing; stops at rank r when it is
// <= tol). pivot = false: columns in order (perm = identity), stopping at the first pivot
// <= tol (returns its index). W (symmetric, k x k) is overwritten by its Schur complements.
template <typename MW, typename ML, typename VP, typename VD>
int ldlReciprocal(MW& W, ML& L, VP& perm, VD& invdiag, double tol, bool pivot) {
  const int k = static_cast<int>(W.rows());
  for (int i = 0; i < k; ++i) perm(i) = i;
  for (int j = 0; j < k; ++j) {
    int p = j;
    if (pivot)
      for (int i = j + 1; i < k; ++i)
        if (W(i, i) > W(p, p)) p = i;
    if (!(W(p, p) > tol)) return j;
    if (p != j) {  // symmetric swap of rows/columns j and p, and of L's rows built so far
      W.row(j).swap(W.row(p));
      W.col(j).swap(W.col(p));
      for (int c = 0; c < j; ++c) std::swap(L(j, c), L(p, c));
      std::swap(perm(j), perm(p));
    }
    const double inv = 1.0 / W(j, j);
    invdiag(j) = inv;
    for (int i = j + 1; i < k; ++i) L(i, j) = W(i, j) * inv;
    for (int c = j + 1; c < k; ++c) {
      const double wc = W(c, j);  // = L(c, j) d_j
      for (int i = c; i < k; ++i) W(i, c) -= L(i, j) * wc;
      if (pivot)
        for (int i = c + 1; i < k; ++i) W(c, i) = W(i, c);
    }
  }
  return k;
}

// Left-looking pivoted Cholesky of the principal submatrix S = A(idx, idx) (k x k, symmetric
// positive semi-definite), read in place (no copy, no Schur-complement matrix): S = V V^T + R with
// V (k x r) in idx's order (row a of V belongs to idx(a)), lower trapezoidal in pivot order, and
// R positive semi-definite with diagonal <= tol. Pivot j is the row of largest remaining diagonal
// (recorded in piv(j)); column j of V reads only A's column of that pivot:
//   V(a, j) = (S(a, p) - sum_{c<j} V(a, c) V(p, c)) / V(p, j),   V(p, j) = sqrt(d_p),
// with d_a = S(a, a) - sum_{c<=j} V(a, c)^2 the remaining diagonal (diag: scratch of k entries).
// Rows already pivoted get V(a, j) = 0. Returns the rank r (r columns of V written).
template <typename MA, typename VI, typename MV, typename VD, typename VP>
int pivotedCholeskyLeft(const MA& A, const VI& idx, int k, MV& V, VD& diag, VP& piv, double tol) {
  constexpr double kDone = -std::numeric_limits<double>::infinity();  // marks pivoted rows
  for (int a = 0; a < k; ++a) diag(a) = A(idx(a), idx(a));
  for (int j = 0; j < k; ++j) {
    int p = 0;
    for (int a = 1; a < k; ++a)
      if (diag(a) > diag(p)) p = a;
    if (!(diag(p) > tol)) return j;
    piv(j) = p;
    const double vpp = std::sqrt(diag(p)), inv = 1.0 / vpp;
    const int ip = idx(p);
    for (int a = 0; a < k; ++a) {
      if (a == p || diag(a) == kDone) {
        V(a, j) = 0.0;
        continue;
      }
      double v = A(idx(a), ip);
      for (int c = 0; c < j; ++c) v -= V(a, c) * V(p, c);
      v *= inv;
      V(a, j) = v;
      diag(a) -= v * v;
    }
    V(p, j) = vpp;
    diag(p) = kDone;
  }
  return k;
}

// With pivotedCholeskyLeft's V and piv of rank r, L1(i, j) = V(piv(i), j) (r x r, lower
// triangular): w <- L1^-1 w and w <- L1^-T w in place (w: r entries), for the particular solution
// of S x = b on the pivots (both in turn) and S's null directions (the second alone).
template <typename MV, typename VP, typename VW>
void pivotedForward(const MV& V, const VP& piv, int r, VW&& w) {
  for (int i = 0; i < r; ++i) {
    for (int j = 0; j < i; ++j) w(i) -= V(piv(i), j) * w(j);
    w(i) /= V(piv(i), i);
  }
}
template <typename MV, typename VP, typename VW>
void pivotedBackward(const MV& V, const VP& piv, int r, VW&& w) {
  for (int i = r - 1; i >= 0; --i) {
    for (int j = i + 1; j < r; ++j) w(i) -= V(piv(j), i) * w(j);
    w(i) /= V(piv(i), i);
  }
}

// Eigenvalues (into d, unsorted) of the symmetric tridiagonal matrix with diagonal d and
// off-diagonal e (e(i) couples i and i + 1; overwritten): implicit QR steps with the Wilkinson
// shift, each chasing its bulge down the unreduced block by Givens rotations, until every
// off-diagonal entry is negligible against its neighbours on the diagonal. Returns false if
// 30 k steps did not suffice (the diagonal is then still a backward-stable approximation).
// rotated(i, c, s) is told each rotation R = [c s; -s c] on rows and columns i, i + 1 (T <- R T
// R^T), for eigenvectors (symmetricEigen); the arithmetic on d and e does not depend on it.
template <typename VD, typename F>
bool tridiagonalQr(VD& d, VD& e, int k, F&& rotated) {
  const double eps = std::numeric_limits<double>::epsilon();
  int h = k - 1, steps = 0;
  while (h > 0) {
    if (std::abs(e(h - 1)) <= eps * (std::abs(d(h - 1)) + std::abs(d(h)))) {  // d(h) has converged
      e(h - 1) = 0.0;
      --h;
      continue;
    }
    if (++steps > 30 * k) return false;
    int l = h - 1;  // the unreduced block [l, h]
    while (l > 0 && std::abs(e(l - 1)) > eps * (std::abs(d(l - 1)) + std::abs(d(l)))) --l;
    const double delta = 0.5 * (d(h - 1) - d(h)), b = e(h - 1);
    const double root =
        std::abs(delta) < 1e150 && std::abs(b) < 1e150 ? std::sqrt(delta * delta + b * b) : std::hypot(delta, b);
    const double mu = d(h) - b * b / (delta + std::copysign(root, delta));
    double x = d(l) - mu, z = e(l);
    for (int i = l; i < h; ++i) {  // rotation R = [c s; -s c] on rows and columns i, i + 1
      const double r = std::abs(x) < 1e150 && std::abs(z) < 1e150 ? std::sqrt(x * x + z * z) : std::hypot(x, z);
      const double inv = r > 0.0 ? 1.0 / r : 0.0;
      const double c = r > 0.0 ? x * inv : 1.0, s = z * inv;
      if (i > l) e(i - 1) = r;  // R [x; z] = [r; 0]: the bulge at (i + 1, i - 1) is gone
      rotated(i, c, s);
      const double di = d(i), dj = d(i + 1), ei = e(i);
      d(i) = c * c * di + 2.0 * c * s * ei + s * s * dj;
      d(i + 1) = s * s * di - 2.0 * c * s * ei + c * c * dj;
      e(i) = c * s * (dj - di) + (c * c - s * s) * ei;
      if (i + 1 < h) {  // the new bulge at (i + 2, i)
        x = e(i);
        z = s * e(i + 1);
        e(i + 1) *= c;
      }
    }
  }
  return true;
}

template <typename VD>
bool tridiagonalEigenvalues(VD& d, VD& e, int k) {
  return tridiagonalQr(d, e, k, [](int, double, double) {});
}

// Smallest eigenvalue of the symmetric tridiagonal matrix T (diagonal d, off-diagonal e, k
// entries) by Laguerre's iteration on its characteristic polynomial p(x) = det(T - x I), from
// Gershgorin's lower bound. p has only real roots, so from the left of the smallest one the
// iterates increase monotonically to it, cubically near a simple root: x <- x + k / (f +
// sqrt((k - 1)(k g - f^2))) with f = sum_j 1 / (lambda_j - x) = -p'/p and g = sum_j
// 1 / (lambda_j - x)^2 = f^2 - p''/p, and p, p', p'' from the three-term recurrence of the
// leading minors (rescaled against overflow). d_scaled, e2_scaled: scratch of k entries each, for
// the diagonal and the squared off-diagonal of T / 2^s (2^s ~ T's scale), computed once. About
// five iterations of O(k) each, against the two QR sweeps per eigenvalue of
// tridiagonalEigenvalues(). False (lambda unset) if it has not converged in 16 iterations: a
// multiple smallest eigenvalue converges only linearly.
template <typename VD, typename VS>
bool smallestTridiagonalEigenvalue(const VD& d, const VD& e, int k, VS& d_scaled, VS& e2_scaled, double& lambda) {
  const double eps = std::numeric_limits<double>::epsilon();
  double x = std::numeric_limits<double>::infinity(), scale = 0.0;
  for (int i = 0; i < k; ++i) {
    const double r = (i > 0 ? std::abs(e(i - 1)) : 0.0) + (i + 1 < k ? std::abs(e(i)) : 0.0);
    x = std::min(x, d(i) - r);
    scale = std::max(scale, std::abs(d(i)) + r);
  }
  if (!(scale > 0.0) || !std::isfinite(scale)) return false;
  // Work on T / 2^s with 2^s ~ scale (exact: a power of two), so that e^2 neither overflows nor
  // underflows where it matters.
  int s = 0;
  std::frexp(scale, &s);
  for (int i = 0; i < k; ++i) {
    d_scaled(i) = std::ldexp(d(i), -s);
    const double ei = i + 1 < k ? std::ldexp(e(i), -s) : 0.0;
    e2_scaled(i) = ei * ei;
  }
  const double tol = 4.0 * eps;
  x = std::ldexp(x, -s) - tol;  // strictly below every eigenvalue
  bool converged = false;
  for (int it = 0; it < 16; ++it) {
    double p0 = 1.0, p0d = 0.0, p0dd = 0.0;               // P_{i-1} and its derivatives
    double p1 = d_scaled(0) - x, p1d = -1.0, p1dd = 0.0;  // P_i
    for (int i = 1; i < k; ++i) {
      const double t = d_scaled(i) - x, e2 = e2_scaled(i - 1);
      const double p2 = t * p1 - e2 * p0;
      const double p2d = t * p1d - p1 - e2 * p0d;
      const double p2dd = t * p1dd - 2.0 * p1d - e2 * p0dd;
      p0 = p1, p0d = p1d, p0dd = p1dd, p1 = p2, p1d = p2d, p1dd = p2dd;
      const double a = std::abs(p1);
      if (a > 1e100 || (a < 1e-100 && a > 0.0)) {  // rescale both minors alike (f, g are ratios)
        const double inv = 1.0 / a;
        p0 *= inv, p0d *= inv, p0dd *= inv, p1 *= inv, p1d *= inv, p1dd *= inv;
      }
    }
    // p > 0 and f > 0 below the smallest eigenvalue; otherwise x has reached it (to rounding).
    const double f = -p1d / p1, g = f * f - p1dd / p1;
    if (!(p1 > 0.0) || !(f > 0.0)) {
      converged = true;
      break;
    }
    const double disc = std::max((k - 1.0) * (k * g - f * f), 0.0);
    const double denom = f + std::sqrt(disc);
    if (!(denom > 0.0) || !std::isfinite(denom)) return false;
    const double step = k / denom;
    x += step;
    if (step <= tol) {
      converged = true;
      break;
    }
  }
  if (!converged || !std::isfinite(x)) return false;
  lambda = std::ldexp(x, s);
  return true;
}

// Householder reduction of a symmetric k x k matrix A (every entry read; overwritten) to
// tridiagonal form T = Q^T A Q, Q = H_0 ... H_{k-3}: the diagonal into d, the off-diagonal into
// e (e(i) couples i and i + 1). work: scratch of k x 4 (d, e, the Householder vector v, a
// product p). reflected(j, n, beta) is told each reflector H_j = I - beta v v^T on rows and
// columns j + 1 .. k - 1 (v = work.col(2).head(n); work.col(3) is free scratch then).
template <typename MA, typename MW, typename F>
void householderTridiagonal(MA& A, MW& work, F&& reflected) {
  const int k = static_cast<int>(A.rows());
  auto d = work.col(0), e = work.col(1), v = work.col(2), p = work.col(3);
  for (int j = 0; j + 2 < k; ++j) {  // zero A(j+2:, j) by H = I - beta v v^T on rows/columns j+1:
    const int n = k - j - 1;
    double xnorm2 = 0.0;
    for (int i = 0; i < n; ++i) xnorm2 += A(j + 1 + i, j) * A(j + 1 + i, j);
    const double x0 = A(j + 1, j), tail2 = xnorm2 - x0 * x0;
    if (!(tail2 > 0.0)) continue;  // already tridiagonal in this column
    const double alpha = x0 > 0.0 ? -std::sqrt(xnorm2) : std::sqrt(xnorm2);
    for (int i = 0; i < n; ++i) v(i) = A(j + 1 + i, j);
    v(0) -= alpha;
    const double beta = 1.0 / (xnorm2 - alpha * x0);  // 2 / (v^T v)
    double vp = 0.0;
    for (int i = 0; i < n; ++i) {  // p = beta A22 v
      double s = 0.0;
      for (int c = 0; c < n; ++c) s += A(j + 1 + i, j + 1 + c) * v(c);
      p(i) = beta * s;
      vp += v(i) * p(i);
    }
    const double half = 0.5 * beta * vp;
    for (int i = 0; i < n; ++i) p(i) -= half * v(i);  // w = p - (beta v^T p / 2) v
    for (int c = 0; c < n; ++c)                       // A22 -= v w^T + w v^T
      for (int i = 0; i < n; ++i) A(j + 1 + i, j + 1 + c) -= v(i) * p(c) + p(i) * v(c);
    A(j + 1, j) = alpha;
    reflected(j, n, beta);
  }
  for (int i = 0; i < k; ++i) {
    d(i) = A(i, i);
    e(i) = i + 1 < k ? A(i + 1, i) : 0.0;
  }
}

// Smallest eigenvalue of a symmetric k x k matrix A (overwritten): Householder reduction to
// tridiagonal form (eigenvalues only), then smallestTridiagonalEigenvalue() (if it does not
// converge, tridiagonalEigenvalues()). work: scratch of k x 4 (diagonal, off-diagonal,
// Householder vector, product). Backward stable: the result is within a few eps ||A|| of the
// exact one.
template <typename MA, typename MW>
double smallestEigenvalue(MA& A, MW& work) {
  const int k = static_cast<int>(A.rows());
  householderTridiagonal(A, work, [](int, int, double) {});
  auto d = work.col(0), e = work.col(1), v = work.col(2), p = work.col(3);
  double lambda = 0.0;
  if (smallestTridiagonalEigenvalue(d, e, k, v, p, lambda)) return lambda;  // v, p: free scratch now
  tridiagonalEigenvalues(d, e, k);
  return d.head(k).minCoeff();
}

// Eigen-decomposition of a symmetric k x k matrix A = V diag(lambda) V^T: Householder reduction
// to tridiagonal form with Q accumulated into V (V <- V H_j), then the implicit QR steps of
// tridiagonalQr() with each rotation accumulated (V <- V R^T). On return the diagonal of A holds
// the eigenvalues (unsorted; A's other entries zero) and the columns of V the orthonormal
// eigenvectors; backward stable (the eigenvalues within a few eps ||A|| of the exact ones).
// About (8/3) k^3 operations for the reduction and 6 k^2 per QR step (two steps per eigenvalue is
// typical), against about 8 k^3 per sweep of jacobiEigen(). work: scratch of k x 4. False if the
// QR steps did not converge (A and V are then garbage: the caller falls back to jacobiEigen()).
// V: column-major with contiguous columns.
template <typename MA, typename MV, typename MW>
bool symmetricEigen(MA& A, MV& V, MW& work) {
  static_assert(!(MV::Flags & Eigen::RowMajorBit), "symmetricEigen rotates contiguous columns of V");
  const int k = static_cast<int>(A.rows());
  V.setIdentity();
  auto v = work.col(2), y = work.col(3);
  householderTridiagonal(A, work, [&](int j, int n, double beta) {
    for (int r = 0; r < k; ++r) {  // V(:, j+1:) -= beta (V(:, j+1:) v) v^T
      double s = 0.0;
      for (int c = 0; c < n; ++c) s += V(r, j + 1 + c) * v(c);
      y(r) = beta * s;
    }
    for (int c = 0; c < n; ++c) {
      double* col = &V(0, j + 1 + c);
      const double vc = v(c);
      for (int r = 0; r < k; ++r) col[r] -= y(r) * vc;
    }
  });
  auto d = work.col(0), e = work.col(1);
  const bool ok = tridiagonalQr(d, e, k, [&](int i, double c, double s) {
    double* vi = &V(0, i);
    double* vj = &V(0, i + 1);
    for (int r = 0; r < k; ++r) {  // V <- V R^T on columns i, i + 1
      const double a = vi[r], b = vj[r];
      vi[r] = c * a + s * b;
      vj[r] = c * b - s * a;
    }
  });
  if (!ok) return false;
  A.setZero();
  for (int i = 0; i < k; ++i) A(i, i) = d(i);
  return true;
}

// Cyclic Jacobi eigen-decomposition of a symmetric k x k matrix A: rotations J_pq zero one
// off-diagonal pair at a time, A <- J^T A J, V <- V J. On return the diagonal of A holds the
// eigenvalues (unsorted) and the columns of V the orthonormal eigenvectors. Stops when the
// off-diagonal mass is below eps^2 of A's Frobenius norm squared, after at most max_sweeps sweeps
// (convergence is quadratic; 6-10 sweeps are typical). Returns the number of sweeps. A and V:
// column-major with contiguous columns (blocks of a MatrixXd).
template <typename MA, typename MV>
int jacobiEigen(MA& A, MV& V, int max_sweeps = 60) {
  static_assert(!(MA::Flags & Eigen::RowMajorBit) && !(MV::Flags & Eigen::RowMajorBit),
                "jacobiEigen rotates contiguous columns: column-major storage only");
  const int k = static_cast<int>(A.rows());
  V.setIdentity();
  const double total = A.squaredNorm();
  const double eps = std::numeric_limits<double>::epsilon();
  int sweep = 0;
  for (; sweep < max_sweeps; ++sweep) {
    double off = 0.0;
    for (int p = 0; p < k; ++p)
      for (int q = p + 1; q < k; ++q) off += 2.0 * A(p, q) * A(p, q);
    if (!(off > eps * eps * total)) break;
    for (int p = 0; p < k; ++p) {
      for (int q = p + 1; q < k; ++q) {
        const double apq = A(p, q);
        if (apq == 0.0) continue;
        const double theta = (A(q, q) - A(p, p)) / (2.0 * apq);
        const double t = std::abs(theta) > 1e150
                             ? 0.5 / theta
                             : (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        A(p, p) -= t * apq;
        A(q, q) += t * apq;
        A(p, q) = A(q, p) = 0.0;
        // Columns p and q (contiguous) first, then rows p and q from them (symmetry).
        double* cp = &A(0, p);
        double* cq = &A(0, q);
        const auto rotate = [c, s](double* x, double* y, int lo, int hi) {
          for (int r = lo; r < hi; ++r) {
            const double xr = x[r], yr = y[r];
            x[r] = c * xr - s * yr;
            y[r] = s * xr + c * yr;
          }
        };
        rotate(cp, cq, 0, p);
        rotate(cp, cq, p + 1, q);
        rotate(cp, cq, q + 1, k);
        for (int r = 0; r < k; ++r) {
          if (r == p || r == q) continue;
          A(p, r) = cp[r];
          A(q, r) = cq[r];
        }
        rotate(&V(0, p), &V(0, q), 0, k);
      }
    }
  }
  return sweep;
}

}  // namespace detail
}  // namespace vereshchagin
