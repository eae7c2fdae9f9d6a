// Small dense symmetric linear algebra on preallocated storage (no heap allocation): Cholesky
// with a pivot threshold, and a pivoted (rank-revealing) Cholesky for the positive semi-definite
// matrices of the friction optimisation (dimension <= number of joints).
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

// Pivoted (rank-revealing) Cholesky of a symmetric positive semi-definite W (k x k, overwritten
// by its Schur complements): W(perm, perm) = L L^T with L (k x r) lower trapezoidal, stopping when
// the largest remaining diagonal entry is <= tol. Returns the rank r.
template <typename MW, typename ML, typename VP>
int pivotedCholesky(MW& W, ML& L, VP& perm, double tol) {
  const int k = static_cast<int>(W.rows());
  for (int i = 0; i < k; ++i) perm(i) = i;
  for (int j = 0; j < k; ++j) {
    int p = j;
    for (int i = j + 1; i < k; ++i)
      if (W(i, i) > W(p, p)) p = i;
    if (!(W(p, p) > tol)) return j;
    if (p != j) {  // symmetric swap of rows/columns j and p, and of the rows of L built so far
      W.row(j).swap(W.row(p));
      W.col(j).swap(W.col(p));
      for (int c = 0; c < j; ++c) std::swap(L(j, c), L(p, c));
      std::swap(perm(j), perm(p));
    }
    const double ljj = std::sqrt(W(j, j));
    L(j, j) = ljj;
    for (int i = j + 1; i < k; ++i) L(i, j) = W(i, j) / ljj;
    for (int i = j + 1; i < k; ++i)
      for (int c = j + 1; c <= i; ++c) {
        W(i, c) -= L(i, j) * L(c, j);
        W(c, i) = W(i, c);
      }
  }
  return k;
}

}  // namespace detail
}  // namespace vereshchagin
