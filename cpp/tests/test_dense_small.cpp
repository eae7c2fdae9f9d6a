// The solver's own small dense eigenvalue routines (cpp/src/dense_small.hpp) against Eigen's
// SelfAdjointEigenSolver, on symmetric matrices of every kind the coupling matrix can take:
// random spectra with condition numbers up to 1e16, all eigenvalues equal, a repeated smallest
// eigenvalue (where Laguerre's iteration converges only linearly and hands over to the QR
// sweeps), rank-deficient and zero matrices, diagonal ones, at scales 1e-100 .. 1e100.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <doctest/doctest.h>
#include <Eigen/Dense>

#include "../src/dense_small.hpp"

namespace {

Eigen::MatrixXd randomSymmetric(std::mt19937& rng, int k, int kind) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const Eigen::MatrixXd Q =
      Eigen::HouseholderQR<Eigen::MatrixXd>(Eigen::MatrixXd::NullaryExpr(k, k, [&] { return U(rng); })).householderQ();
  const double cond = std::pow(10.0, 16.0 * std::abs(U(rng)));
  Eigen::VectorXd lam(k);
  for (int i = 0; i < k; ++i) lam(i) = std::pow(cond, -std::abs(U(rng)));
  if (kind == 1) lam.setConstant(0.1 + std::abs(U(rng)));               // all equal
  if (kind == 2) lam.head(std::min(k, 3)).setConstant(lam.minCoeff());  // repeated smallest
  if (kind == 3) lam.head(k / 2).setZero();                             // rank deficient
  const double scale = kind == 4 ? 1.0 : std::pow(10.0, 100.0 * U(rng));
  Eigen::MatrixXd A = scale * Q * lam.asDiagonal() * Q.transpose();
  A = (0.5 * (A + A.transpose())).eval();
  if (kind == 5) {  // diagonal, signs mixed
    A.setZero();
    for (int i = 0; i < k; ++i) A(i, i) = scale * U(rng);
  }
  if (kind == 6) A.setZero();
  return A;
}

}  // namespace

TEST_CASE("smallest eigenvalue agrees with Eigen on 20000 symmetric matrices of every kind") {
  std::mt19937 rng(20261124);
  double worst = 0.0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int k = trial % 5 == 0 ? 6 : 1 + static_cast<int>(rng() % 24);
    const int kind = trial % 7;
    const Eigen::MatrixXd A = randomSymmetric(rng, k, kind);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> oracle(A, Eigen::EigenvaluesOnly);
    const Eigen::VectorXd& ev = oracle.eigenvalues();
    const double norm = std::max(std::abs(ev(0)), std::abs(ev(k - 1)));
    Eigen::MatrixXd W = A, work(k, 4);
    const double ours = vereshchagin::detail::smallestEigenvalue(W, work);
    // Both are backward stable: they agree to a few eps of the largest eigenvalue's magnitude.
    const double err = norm > 0.0 ? std::abs(ours - ev(0)) / norm : std::abs(ours);
    worst = std::max(worst, err);
    CHECK_MESSAGE(err <= 1e-13, "k " << std::to_string(k) << ", kind " << std::to_string(kind)
                                     << ": smallest eigenvalue " << std::to_string(ours) << " vs Eigen "
                                     << std::to_string(ev(0)));
  }
  char summary[96];
  std::snprintf(summary, sizeof summary, "worst |ours - Eigen| / max |lambda| = %.2e", worst);
  MESSAGE(summary);
}

TEST_CASE("eigen-decomposition agrees with Eigen on 20000 symmetric matrices of every kind") {
  std::mt19937 rng(20261128);
  double worst_value = 0.0, worst_residual = 0.0, worst_orthogonality = 0.0;
  int fallbacks = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int k = trial % 5 == 0 ? 7 : 1 + static_cast<int>(rng() % 24);
    const int kind = trial % 7;
    const Eigen::MatrixXd A = randomSymmetric(rng, k, kind);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> oracle(A, Eigen::EigenvaluesOnly);
    const Eigen::VectorXd& ev = oracle.eigenvalues();  // ascending
    const double norm = std::max(std::abs(ev(0)), std::abs(ev(k - 1)));
    // Storage with room around the blocks, as the solver's workspace has.
    Eigen::MatrixXd Wbig = Eigen::MatrixXd::Constant(k + 3, k + 3, 7.0), Vbig(k + 2, k + 2), work(k + 1, 4);
    auto W = Wbig.topLeftCorner(k, k);
    auto V = Vbig.topLeftCorner(k, k);
    auto scratch = work.topLeftCorner(k, 4);
    W = A;
    if (!vereshchagin::detail::symmetricEigen(W, V, scratch)) {
      ++fallbacks;
      continue;
    }
    Eigen::VectorXd lam = W.diagonal();
    const Eigen::MatrixXd off = W - Eigen::MatrixXd(lam.asDiagonal());
    CHECK(off.cwiseAbs().maxCoeff() == 0.0);
    const double s = norm > 0.0 ? norm : 1.0;
    // A V = V diag(lambda) and V^T V = I, to a few eps (both backward stable).
    const double residual = (A * V - V * lam.asDiagonal()).cwiseAbs().maxCoeff() / s;
    const double orthogonality = (V.transpose() * V - Eigen::MatrixXd::Identity(k, k)).cwiseAbs().maxCoeff();
    std::sort(lam.data(), lam.data() + k);
    const double value = (lam - ev).cwiseAbs().maxCoeff() / s;
    worst_value = std::max(worst_value, value);
    worst_residual = std::max(worst_residual, residual);
    worst_orthogonality = std::max(worst_orthogonality, orthogonality);
    CHECK_MESSAGE(value <= 1e-13, "k " << k << ", kind " << kind << ": eigenvalues off by " << value);
    CHECK_MESSAGE(residual <= 1e-13, "k " << k << ", kind " << kind << ": |A V - V diag| / |A| = " << residual);
    CHECK_MESSAGE(orthogonality <= 1e-13, "k " << k << ", kind " << kind << ": |V^T V - I| = " << orthogonality);
  }
  CHECK(fallbacks == 0);
  char summary[160];
  std::snprintf(summary, sizeof summary, "worst eigenvalue %.2e, residual %.2e, orthogonality %.2e (relative)",
                worst_value, worst_residual, worst_orthogonality);
  MESSAGE(summary);
}

TEST_CASE("eigen-decomposition of tiny matrices and of a block-diagonal coupling") {
  Eigen::MatrixXd work(4, 4), V(4, 4);
  Eigen::MatrixXd A1(1, 1);
  A1 << -3.5;
  Eigen::MatrixXd W1 = A1;
  auto V1 = V.topLeftCorner(1, 1);
  auto s1 = work.topLeftCorner(1, 4);
  REQUIRE(vereshchagin::detail::symmetricEigen(W1, V1, s1));
  CHECK(W1(0, 0) == -3.5);
  CHECK(V1(0, 0) == 1.0);
  // Two uncoupled blocks (as K of constraints on separate branches): the eigenvectors stay within them.
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(4, 4);
  B.topLeftCorner(2, 2) << 2.0, 1.0, 1.0, 2.0;
  B.bottomRightCorner(2, 2) << 5.0, 0.0, 0.0, 0.0;
  Eigen::MatrixXd W = B;
  REQUIRE(vereshchagin::detail::symmetricEigen(W, V, work));
  Eigen::VectorXd lam = W.diagonal();
  std::sort(lam.data(), lam.data() + 4);
  CHECK((lam - Eigen::Vector4d(0.0, 1.0, 3.0, 5.0)).cwiseAbs().maxCoeff() <= 1e-15);
  CHECK((B * V - V * W.diagonal().asDiagonal()).cwiseAbs().maxCoeff() <= 1e-15);
}
