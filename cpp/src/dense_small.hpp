// Small dense symmetric linear algebra on preallocated storage (no heap allocation): Cholesky
// with a certification threshold, and a cyclic Jacobi eigen-decomposition for the positive
// semi-definite matrices of the friction optimisation (dimension <= number of joints).
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace vereshchagin {
namespace detail {

using MatBlock = Eigen::Block<Eigen::MatrixXd>;
using VecBlock = Eigen::VectorBlock<Eigen::VectorXd>;

// A = L L^T into the lower triangle of L (k x k). Fails (false) when a pivot is not above
// min_pivot, i.e. when A is not safely positive definite at the caller's scale.
template <typename MA, typename ML>
bool choleskyCertified(const MA& A, ML& L, double min_pivot) {
  const int k = static_cast<int>(A.rows());
  for (int j = 0; j < k; ++j) {
    double d = A(j, j);
    for (int p = 0; p < j; ++p) d -= L(j, p) * L(j, p);
    if (!(d > min_pivot)) return false;
    const double ljj = std::sqrt(d);
    L(j, j) = ljj;
    for (int i = j + 1; i < k; ++i) {
      double v = A(i, j);
      for (int p = 0; p < j; ++p) v -= L(i, p) * L(j, p);
      L(i, j) = v / ljj;
    }
  }
  return true;
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

// Symmetric A (k x k, overwritten) -> eigenvalues in `values` (A's diagonal at the end) and
// orthonormal eigenvectors as the columns of V, by cyclic Jacobi rotations. Converges
// quadratically; at most 60 sweeps (bounded work).
template <typename MA, typename MV, typename VV>
void jacobiEigen(MA& A, MV& V, VV& values) {
  const int k = static_cast<int>(A.rows());
  V.setIdentity();
  for (int sweep = 0; sweep < 60; ++sweep) {
    double off = 0.0, diag = 0.0;
    for (int i = 0; i < k; ++i) {
      diag += A(i, i) * A(i, i);
      for (int j = i + 1; j < k; ++j) off += A(i, j) * A(i, j);
    }
    if (off <= 1e-32 * diag || off == 0.0) break;
    for (int p = 0; p < k; ++p) {
      for (int q = p + 1; q < k; ++q) {
        const double apq = A(p, q);
        if (apq == 0.0) continue;
        // Rotation zeroing A(p, q): tan(2 phi) = 2 apq / (aqq - app).
        const double theta = (A(q, q) - A(p, p)) / (2.0 * apq);
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int r = 0; r < k; ++r) {  // A <- A G (columns p, q)
          const double arp = A(r, p), arq = A(r, q);
          A(r, p) = c * arp - s * arq;
          A(r, q) = s * arp + c * arq;
        }
        for (int r = 0; r < k; ++r) {  // A <- G^T A (rows p, q)
          const double apr = A(p, r), aqr = A(q, r);
          A(p, r) = c * apr - s * aqr;
          A(q, r) = s * apr + c * aqr;
        }
        A(p, q) = A(q, p) = 0.0;
        for (int r = 0; r < k; ++r) {
          const double vrp = V(r, p), vrq = V(r, q);
          V(r, p) = c * vrp - s * vrq;
          V(r, q) = s * vrp + c * vrq;
        }
      }
    }
  }
  for (int i = 0; i < k; ++i) values(i) = A(i, i);
}

}  // namespace detail
}  // namespace vereshchagin
