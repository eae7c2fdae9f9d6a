// The dual active-set method (cpp/src/dual_qp.hpp) and LexicographicQp's first try built on it
// (cpp/src/lexicographic_active.cpp). Oracles written here: the optimality conditions checked
// directly (feasibility, stationarity, multiplier signs, complementarity), a Farkas certificate
// for infeasible rows, and for the two programmes in turn an enumeration of the rows held as
// equalities (each subset's KKT system solved by a complete orthogonal decomposition; the convex
// programme's optimum is any subset's KKT point that meets every row with non-negative multipliers).
#include <cmath>
#include <random>
#include <vector>

#include <doctest/doctest.h>
#include <Eigen/Dense>

#include "../src/dual_qp.hpp"
#include "../src/lemke.hpp"

using vereshchagin::detail::DualActiveSetQp;
using vereshchagin::detail::Lemke;
using vereshchagin::detail::LexicographicQp;

namespace {

struct Rng {
  std::mt19937 gen;
  std::normal_distribution<double> normal{0.0, 1.0};
  explicit Rng(unsigned seed) : gen(seed) {}
  double operator()() { return normal(gen); }
  Eigen::MatrixXd matrix(int r, int c) {
    Eigen::MatrixXd m(r, c);
    for (int j = 0; j < c; ++j)
      for (int i = 0; i < r; ++i) m(i, j) = (*this)();
    return m;
  }
};

// The KKT point of min 1/2 x^T H x + g^T x subject to E x = e (H positive semi-definite): x and
// the multipliers l (E^T l = H x + g), or false when the system has no solution.
bool equalityKkt(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const Eigen::MatrixXd& E, const Eigen::VectorXd& e,
                 Eigen::VectorXd& x, Eigen::VectorXd& l) {
  const int p = static_cast<int>(g.size()), m = static_cast<int>(e.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(p + m, p + m);
  K.topLeftCorner(p, p) = H;
  K.topRightCorner(p, m) = -E.transpose();
  K.bottomLeftCorner(m, p) = E;
  Eigen::VectorXd rhs(p + m);
  rhs << -g, e;
  const Eigen::VectorXd sol = K.completeOrthogonalDecomposition().solve(rhs);
  if ((K * sol - rhs).cwiseAbs().maxCoeff() > 1e-9 * std::max(1.0, rhs.cwiseAbs().maxCoeff())) return false;
  x = sol.head(p);
  l = sol.tail(m);
  return true;
}

// The optimum of min 1/2 x^T H x + g^T x subject to F x = f and R x >= r by enumerating the rows
// of R held as equalities; false when no subset gives one.
bool enumerate(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const Eigen::MatrixXd& F, const Eigen::VectorXd& f,
               const Eigen::MatrixXd& R, const Eigen::VectorXd& r, Eigen::VectorXd& best) {
  const int k = static_cast<int>(r.size()), p = static_cast<int>(g.size()), nf = static_cast<int>(f.size());
  for (int mask = 0; mask < (1 << k); ++mask) {
    std::vector<int> rows;
    for (int i = 0; i < k; ++i)
      if (mask >> i & 1) rows.push_back(i);
    const int m = nf + static_cast<int>(rows.size());
    Eigen::MatrixXd E(m, p);
    Eigen::VectorXd e(m);
    E.topRows(nf) = F;
    e.head(nf) = f;
    for (std::size_t j = 0; j < rows.size(); ++j) E.row(nf + j) = R.row(rows[j]), e(nf + j) = r(rows[j]);
    Eigen::VectorXd x, l;
    if (!equalityKkt(H, g, E, e, x, l)) continue;
    const double xs = std::max(1.0, x.cwiseAbs().maxCoeff());
    if ((R * x - r).minCoeff() < -1e-9 * xs) continue;
    if (l.size() > nf && l.tail(m - nf).minCoeff() < -1e-9 * std::max(1.0, l.cwiseAbs().maxCoeff())) continue;
    best = x;
    return true;
  }
  return false;
}

}  // namespace

TEST_CASE("DualActiveSetQp: random programmes meet their optimality conditions") {
  Rng rng(11);
  int solved = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int p = 2 + trial % 9, k = 1 + trial % 17, eq = trial % 4 == 0 ? std::min(2, p - 1) : 0;
    const Eigen::MatrixXd F = rng.matrix(p, p);
    const Eigen::MatrixXd H = F * F.transpose() + 0.1 * Eigen::MatrixXd::Identity(p, p);
    const Eigen::VectorXd g = rng.matrix(p, 1);
    const Eigen::MatrixXd A = rng.matrix(eq + k, p);
    const Eigen::VectorXd x0 = rng.matrix(p, 1);
    Eigen::VectorXd b = A * x0;  // x0 meets every row; a third of the trials at a degenerate vertex
    if (trial % 3 != 0)
      for (int i = eq; i < eq + k; ++i) b(i) -= std::abs(rng());
    DualActiveSetQp qp;
    qp.reserve(p, eq + k);
    Eigen::VectorXd x(p);
    REQUIRE(qp.solve(H, g, A, b, eq, x, 1000) == DualActiveSetQp::kSolved);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(eq + k);
    for (int j = 0; j < qp.activeCount(); ++j) u(qp.active(j)) = qp.multiplier(j);
    const Eigen::VectorXd s = A * x - b;
    const double scale = std::max({1.0, x.cwiseAbs().maxCoeff(), u.cwiseAbs().maxCoeff()});
    CHECK((H * x + g - A.transpose() * u).cwiseAbs().maxCoeff() <= 1e-8 * scale);
    if (eq > 0) CHECK(s.head(eq).cwiseAbs().maxCoeff() <= 1e-9 * scale);
    CHECK(s.tail(k).minCoeff() >= -1e-9 * scale);
    CHECK(u.tail(k).minCoeff() >= -1e-9 * scale);
    CHECK(u.tail(k).cwiseProduct(s.tail(k)).cwiseAbs().maxCoeff() <= 1e-8 * scale);
    ++solved;
  }
  CHECK(solved == 400);
}

TEST_CASE("DualActiveSetQp: rows that admit no point, and an indefinite Hessian") {
  Rng rng(12);
  for (int trial = 0; trial < 100; ++trial) {
    const int p = 2 + trial % 6, k = 2 + trial % 5;
    const Eigen::MatrixXd F = rng.matrix(p, p);
    const Eigen::MatrixXd H = F * F.transpose() + 0.1 * Eigen::MatrixXd::Identity(p, p);
    const Eigen::VectorXd g = rng.matrix(p, 1);
    // Farkas: rows whose non-negative combination y^T A vanishes while y^T b > 0.
    Eigen::MatrixXd A = rng.matrix(k, p);
    Eigen::VectorXd y(k);
    for (int i = 0; i < k; ++i) y(i) = 0.5 + std::abs(rng());
    A.row(k - 1) = -(y.head(k - 1).transpose() * A.topRows(k - 1)) / y(k - 1);
    Eigen::VectorXd b = rng.matrix(k, 1);
    b(k - 1) += (1.0 - y.dot(b)) / y(k - 1);  // y^T b = 1
    DualActiveSetQp qp;
    qp.reserve(p, k);
    Eigen::VectorXd x(p);
    CHECK(qp.solve(H, g, A, b, 0, x, 1000) == DualActiveSetQp::kInfeasible);
  }
  DualActiveSetQp qp;
  qp.reserve(2, 1);
  Eigen::Vector2d x;
  const Eigen::Matrix2d H = Eigen::Vector2d(1.0, -1.0).asDiagonal();
  CHECK(qp.solve(H, Eigen::Vector2d::Zero(), Eigen::MatrixXd::Ones(1, 2), Eigen::VectorXd::Zero(1), 0, x, 10) ==
        DualActiveSetQp::kNotDefinite);
}

TEST_CASE("LexicographicQp: least first objective, then least second, against an enumeration") {
  Rng rng(13);
  int checked = 0, fast = 0, fast_eq = 0;
  for (int trial = 0; trial < 300; ++trial) {
    // C of rank n < p: the first objective leaves a null space for the second. eq: an equality
    // E x = 0 written as two rows (E, -E) within a round-off slack, as the least-effort stage does.
    const int p = 3 + trial % 3, n = 1 + trial % 2, k = 4 + trial % 4, eq = trial % 5 == 0 ? 1 : 0;
    const Eigen::MatrixXd C = rng.matrix(n, p);
    const Eigen::VectorXd t = rng.matrix(n, 1);
    const Eigen::MatrixXd B = rng.matrix(p, p);
    const Eigen::MatrixXd P = B * B.transpose() + 0.1 * Eigen::MatrixXd::Identity(p, p);
    const Eigen::VectorXd pv = rng.matrix(p, 1);
    const Eigen::MatrixXd E = rng.matrix(eq, p);
    Eigen::VectorXd x0 = rng.matrix(p, 1);
    if (eq > 0) x0 -= E.transpose() * (E * E.transpose()).ldlt().solve(E * x0);  // E x0 = 0
    const Eigen::MatrixXd Rin = rng.matrix(k, p);
    Eigen::VectorXd rin = Rin * x0;
    for (int i = 0; i < k; ++i) rin(i) -= trial % 2 ? std::abs(rng()) : 0.0;  // half of them degenerate at x0
    Eigen::MatrixXd R(2 * eq + k, p);
    Eigen::VectorXd r(2 * eq + k);
    R << E, -E, Rin;
    r << Eigen::VectorXd::Constant(2 * eq, -1e-14), rin;
    LexicographicQp qp;
    qp.reserve(p, 2 * eq + k);
    Eigen::VectorXd x(p);
    REQUIRE(qp.solve(C, t, P, pv, R, r, x, eq) == Lemke::kSolved);
    (eq == 0 ? fast : fast_eq) += qp.byActiveSet() ? 1 : 0;
    // The oracle: the first programme's optimum (its C x is unique), then the second's over
    // {C x = C x1} (unique: P is positive definite).
    Eigen::VectorXd x1, x2;
    const Eigen::VectorXd ze = Eigen::VectorXd::Zero(eq);
    REQUIRE(enumerate(C.transpose() * C, C.transpose() * t, E, ze, Rin, rin, x1));
    Eigen::MatrixXd F(eq + n, p);
    F << E, C;
    Eigen::VectorXd f(eq + n);
    f << ze, C * x1;
    REQUIRE(enumerate(P, pv, F, f, Rin, rin, x2));
    const double scale = std::max(1.0, x2.cwiseAbs().maxCoeff());
    CHECK((x - x2).cwiseAbs().maxCoeff() <= 1e-8 * scale);
    CHECK((Rin * x - rin).minCoeff() >= -1e-9 * scale);
    ++checked;
  }
  CHECK(checked == 300);
  MESSAGE("answered by the active-set method: ", fast, " of the 240 without the equality pair, ", fast_eq,
          " of the 60 with it");
  CHECK(fast >= 192);    // the pivoting only where the method stalls (degenerate vertices)
  CHECK(fast_eq >= 48);  // with the pair as well (E x = 0 held as an equality)
}
