// The contact stage's pivoting (cpp/src/lemke.hpp): Lemke::basicSolution (the basis a solve ended
// on, evaluated at another q: the tie-breaking retry of the contact stage), and LexicographicQp
// without a first objective (no motor columns) and with an equality written as two inequalities
// while the second objective does not weigh every coordinate (a joint's torque).
#include <cmath>
#include <random>

#include <doctest/doctest.h>
#include <Eigen/Dense>

#include "../src/lemke.hpp"

using vereshchagin::detail::Lemke;
using vereshchagin::detail::LexicographicQp;

TEST_CASE("Lemke: the basis found, evaluated at the problem's q, is its solution") {
  std::mt19937 rng(7);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 3 + trial % 6;
    Eigen::MatrixXd B(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) B(i, j) = N(rng);
    const Eigen::MatrixXd M = B * B.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);  // positive definite
    Eigen::VectorXd q(n), qp(n), z(n), w(n), z2(n), w2(n);
    for (int i = 0; i < n; ++i) q(i) = N(rng);
    for (int i = 0; i < n; ++i) qp(i) = q(i) + 1e-10 * (i + 1) / n;  // the contact stage's perturbation
    Lemke lemke;
    lemke.reserve(n);
    int pivots = 0;
    REQUIRE(lemke.solve(M, qp, z, w, 50 + 20 * n, pivots) == Lemke::kSolved);
    lemke.basicSolution(M, q, z2, w2);
    CHECK((w2 - (M * z2 + q)).cwiseAbs().maxCoeff() <= 1e-12);
    CHECK(z2.minCoeff() >= 0.0);
    CHECK(w2.minCoeff() >= -1e-12);
    CHECK(std::abs(z2.dot(w2)) <= 1e-12);
    CHECK((z2 - z).cwiseAbs().maxCoeff() <= 1e-8);  // the perturbation leaves no trace beyond its size
  }
}

TEST_CASE("LexicographicQp: no first objective, an equality pair, an unweighted coordinate") {
  // x = (a, b, t): min 1/2 (a^2 + b^2) - 2 a - 2 b subject to a + b + t = 0 (rows 0, 1 within a
  // slack of 1e-14) and -1 <= t <= 1 (rows 2, 3); t is not weighed (P singular). Optimum: a = b =
  // 1/2, t = -1.
  const Eigen::MatrixXd C(0, 3);
  const Eigen::VectorXd t0(0);
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(3, 3);
  P(0, 0) = P(1, 1) = 1.0;
  const Eigen::Vector3d pv(-2.0, -2.0, 0.0);
  Eigen::MatrixXd R(4, 3);
  R << 1, 1, 1, -1, -1, -1, 0, 0, 1, 0, 0, -1;
  const Eigen::Vector4d r(-1e-14, -1e-14, -1.0, -1.0);
  LexicographicQp qp;
  qp.reserve(3, 4);
  Eigen::VectorXd x(3);
  REQUIRE(qp.solve(C, t0, P, pv, R, r, x, 1) == Lemke::kSolved);
  CHECK(x(0) == doctest::Approx(0.5).epsilon(1e-9));
  CHECK(x(1) == doctest::Approx(0.5).epsilon(1e-9));
  CHECK(x(2) == doctest::Approx(-1.0).epsilon(1e-9));
}
