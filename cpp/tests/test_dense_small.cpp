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
