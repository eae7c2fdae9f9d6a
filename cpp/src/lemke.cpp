// Lemke's complementary pivoting (lemke.hpp): the textbook scheme on an explicit tableau. The
// artificial variable z0 enters at the most negative q; afterwards the complement of the variable
// that just left enters, until z0 leaves (a solution) or a column has no positive entry (a ray).
#include "lemke.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dense_small.hpp"

namespace vereshchagin {
namespace detail {

void Lemke::reserve(int n) {
  if (n <= capacity()) return;
  tableau_.resize(n, 2 * n + 2);
  basis_.resize(n);
  factor_.resize(n);
}

// The leaving row for `entering`: the lexicographic minimum of (rhs, B^-1 row) / pivot entry over
// the rows with a positive entry (B^-1 is the tableau's first n columns), which never cycles; the
// artificial variable leaves whenever it ties for the minimum ratio. -1: no positive entry (a ray).
int Lemke::ratioTest(int entering, int n, double tol) const {
  const auto T = tableau_.topLeftCorner(n, 2 * n + 2);
  const double col_max = T.col(entering).cwiseAbs().maxCoeff();
  const double piv_tol = std::max(tol, 1e-11 * col_max);
  int best = -1;
  double rb = 0.0;  // the best row's ratio (the same quotient as recomputing it)
  for (int i = 0; i < n; ++i) {
    const double a = T(i, entering);
    if (a <= piv_tol) continue;
    const double ri = T(i, 2 * n + 1) / a;
    if (best < 0) {
      best = i, rb = ri;
      continue;
    }
    const double b = T(best, entering);
    const double eps = 1e-12 * std::max({1.0, std::abs(ri), std::abs(rb)});
    if (ri < rb - eps) {
      best = i, rb = ri;
      continue;
    }
    if (ri > rb + eps) continue;
    if (basis_(i) == 2 * n) {  // z0 ties: let it leave
      best = i, rb = ri;
      continue;
    }
    if (basis_(best) == 2 * n) continue;
    for (int k = 0; k < n; ++k) {  // lexicographic on B^-1
      const double xi = T(i, k) / a, xb = T(best, k) / b;
      if (xi < xb - 1e-12 * std::max({1.0, std::abs(xi), std::abs(xb)})) {
        best = i, rb = ri;
        break;
      }
      if (xi > xb + 1e-12 * std::max({1.0, std::abs(xi), std::abs(xb)})) break;
    }
  }
  return best;
}

// Row `row` scaled to a unit pivot, then T(i, j) -= T(i, col) T(row, j) for every other row i:
// column by column (the tableau is column-major, so each update is one contiguous axpy), skipping
// the columns whose pivot-row entry is zero (nothing to subtract).
void Lemke::pivot(int row, int col, int n) {
  auto T = tableau_.topLeftCorner(n, 2 * n + 2);
  const double p = T(row, col);
  T.row(row) /= p;
  auto f = factor_.head(n);
  f = T.col(col);
  f(row) = 0.0;  // the pivot row keeps its scaled values
  for (int j = 0; j < 2 * n + 2; ++j) {
    const double r = T(row, j);
    if (r != 0.0) T.col(j) -= f * r;
  }
  basis_(row) = col;
}

Lemke::Result Lemke::solve(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                           Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w, int max_pivots, int& pivots) {
  const int n = static_cast<int>(q.size());
  pivots = 0;
  z.setZero();
  w = q;
  const double scale = std::max({1.0, M.cwiseAbs().maxCoeff(), q.cwiseAbs().maxCoeff()});
  const double tol = 1e-13 * scale;
  if (n == 0 || q.minCoeff() >= -tol) return kSolved;  // z = 0 (w = q, non-negative to round-off)
  auto T = tableau_.topLeftCorner(n, 2 * n + 2);
  T.setZero();
  T.leftCols(n).setIdentity();
  T.middleCols(n, n) = -M;
  T.col(2 * n).setConstant(-1.0);
  T.col(2 * n + 1) = q;
  for (int i = 0; i < n; ++i) basis_(i) = i;
  int row;
  q.minCoeff(&row);
  pivot(row, 2 * n, n);  // z0 enters, the most negative w leaves
  int leaving = row;     // the variable that left is w_row
  for (pivots = 1; pivots <= max_pivots; ++pivots) {
    const int entering = leaving < n ? leaving + n : leaving - n;  // its complement
    const int best = ratioTest(entering, n, tol);
    if (best < 0) return kRay;
    leaving = basis_(best);
    pivot(best, entering, n);
    if (leaving == 2 * n) {  // z0 left: a complementary basis
      w.setZero();
      z.setZero();
      for (int i = 0; i < n; ++i) {
        const int v = basis_(i);
        const double value = std::max(0.0, T(i, 2 * n + 1));
        if (v < n)
          w(v) = value;
        else
          z(v - n) = value;
      }
      w = q;  // recomputed from z (the caller's certificate reads it), without a temporary
      w.noalias() += M * z;
      return kSolved;
    }
  }
  return kPivotLimit;
}

void Lemke::basicSolution(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                          Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w) const {
  const int n = static_cast<int>(q.size());
  const auto Binv = tableau_.topLeftCorner(n, n);  // the first n columns: B^-1
  z.setZero();
  for (int i = 0; i < n; ++i) {
    const int v = basis_(i);
    if (v >= n && v < 2 * n) z(v - n) = std::max(0.0, Binv.row(i).dot(q));
  }
  w = q;
  w.noalias() += M * z;
}

void ConvexQp::reserve(int p, int k) {
  const int n = 2 * p + k;
  if (m_.rows() < n) {
    m_.resize(n, n);
    q_.resize(n), z_.resize(n), w_.resize(n);
  }
  lemke_.reserve(n);
}

Lemke::Result ConvexQp::solve(const Eigen::Ref<const Eigen::MatrixXd>& Q, const Eigen::Ref<const Eigen::VectorXd>& c,
                              const Eigen::Ref<const Eigen::MatrixXd>& R, const Eigen::Ref<const Eigen::VectorXd>& r,
                              Eigen::Ref<Eigen::VectorXd> x, int max_pivots) {
  const int p = static_cast<int>(c.size()), k = static_cast<int>(r.size()), n = 2 * p + k;
  auto M = m_.topLeftCorner(n, n);
  M.setZero();
  M.topLeftCorner(p, p) = Q;
  M.block(0, p, p, p) = -Q;
  M.block(p, 0, p, p) = -Q;
  M.block(p, p, p, p) = Q;
  M.block(0, 2 * p, p, k) = -R.transpose();
  M.block(p, 2 * p, p, k) = R.transpose();
  M.block(2 * p, 0, k, p) = R;
  M.block(2 * p, p, k, p) = -R;
  auto q = q_.head(n);
  q << c, -c, -r;
  int pivots = 0;
  const Lemke::Result result = lemke_.solve(M, q, z_.head(n), w_.head(n), max_pivots, pivots);
  if (result == Lemke::kSolved) x = z_.head(p) - z_.segment(p, p);
  return result;
}

void LexicographicQp::reserve(int p, int k) {
  if (q_.rows() < p) {
    q_.resize(p, p), v_.resize(p, p), z_.resize(p, p), q2_.resize(p, p);
    c_.resize(p), w_.resize(p), c2_.resize(p), diag_.resize(p);
    idx_.resize(p), piv_.resize(p);
  }
  if (rz_.rows() < k || rz_.cols() < q_.cols()) {  // never smaller: callers of several sizes share it
    rz_.resize(std::max<Eigen::Index>(k, rz_.rows()), q_.cols());
    r2_.resize(rz_.rows());
  }
  if (l2_.rows() < p || m2_.rows() < k) {
    const Eigen::Index pp = std::max<Eigen::Index>(p, l2_.rows()), kk = std::max<Eigen::Index>(k, m2_.rows());
    l2_.resize(pp, pp), g2_.resize(pp, kk + 1), m2_.resize(kk, kk);
    q2v_.resize(kk), l_.resize(kk), s_.resize(kk);
    lemke2_.reserve(static_cast<int>(kk));
  }
  qp_.reserve(static_cast<int>(q_.cols()), static_cast<int>(rz_.rows()));
  reserveActiveSet(static_cast<int>(q_.cols()), static_cast<int>(rz_.rows()));
}

Lemke::Result LexicographicQp::solve(const Eigen::Ref<const Eigen::MatrixXd>& C,
                                     const Eigen::Ref<const Eigen::VectorXd>& t,
                                     const Eigen::Ref<const Eigen::MatrixXd>& P,
                                     const Eigen::Ref<const Eigen::VectorXd>& pv,
                                     const Eigen::Ref<const Eigen::MatrixXd>& R,
                                     const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::Ref<Eigen::VectorXd> x,
                                     int eq) {
  const int p = static_cast<int>(C.cols()), k = static_cast<int>(r.size());
  auto Q = q_.topLeftCorner(p, p);
  Q.noalias() = C.transpose().lazyProduct(C);
  auto c = c_.head(p);
  c.noalias() = C.transpose() * t;
  const int limit = 100 + 40 * (2 * p + k);
  by_active_set_ = false;
  if (C.rows() > 0) {
    const ActiveSet as = activeSetSolve(P, pv, R, r, x, eq);
    by_active_set_ = as == ActiveSet::kAnswered;
    if (by_active_set_) return Lemke::kSolved;
    if (as == ActiveSet::kInfeasible && eq == 0) return Lemke::kRay;  // (with E, the pairs' slack may matter)
  }
  if (C.rows() == 0) {  // no first objective: x1 = 0 (the caller's point, feasible), Z spans everything
    x.setZero();
    // With the equality E x = 0 the second programme lives on E's null space: there first, its
    // dual of the other rows (P is positive definite there in the usual case), before the doubled
    // primal over all p coordinates with E as two inequalities, whose answer it equals up to the
    // pairs' round-off slack.
    if (eq > 0 && secondOnEqualities(P, pv, R, r, x, eq)) return Lemke::kSolved;
  } else if (const Lemke::Result res = qp_.solve(Q, c, R, r, x, limit); res != Lemke::kSolved)
    return res;
  const int d = nullBasis(Q);
  if (d == 0) return Lemke::kSolved;
  if (!secondOnNull(P, pv, R, r, x, d)) {
    if (eq > 0) (void)secondOnEqualities(P, pv, R, r, x, eq);  // else keep x1
    return Lemke::kSolved;
  }
  x.noalias() += z_.topLeftCorner(p, d) * w_.head(d);
  return Lemke::kSolved;
}

// The second programme in the coordinates w of x = x1 + Z w (Z: z_'s first d columns, x = x1):
// min 1/2 w^T (Z^T P Z) w + (Z^T (P x1 + pv))^T w subject to (Rs Z) w >= rs - Rs x1, its dual
// first (strictSecond), else the doubled primal. The answer w into w_'s head; false when neither
// finishes.
bool LexicographicQp::secondOnNull(const Eigen::Ref<const Eigen::MatrixXd>& P,
                                   const Eigen::Ref<const Eigen::VectorXd>& pv,
                                   const Eigen::Ref<const Eigen::MatrixXd>& Rs,
                                   const Eigen::Ref<const Eigen::VectorXd>& rs,
                                   const Eigen::Ref<const Eigen::VectorXd>& x, int d) {
  secondData(P, pv, Rs, rs, x, d);
  return secondPivoting(d, static_cast<int>(rs.size()));
}

void LexicographicQp::secondData(const Eigen::Ref<const Eigen::MatrixXd>& P,
                                 const Eigen::Ref<const Eigen::VectorXd>& pv,
                                 const Eigen::Ref<const Eigen::MatrixXd>& Rs,
                                 const Eigen::Ref<const Eigen::VectorXd>& rs,
                                 const Eigen::Ref<const Eigen::VectorXd>& x, int d) {
  const int p = static_cast<int>(x.size()), k = static_cast<int>(rs.size());
  const auto Z = z_.topLeftCorner(p, d);
  auto PZ = v_.topLeftCorner(p, d);  // V is no longer needed
  PZ.noalias() = P * Z;
  auto Q2 = q2_.topLeftCorner(d, d);
  Q2.noalias() = Z.transpose() * PZ;
  auto grad = w_.head(p);  // the second objective's gradient at x1
  grad.noalias() = P * x;
  grad += pv;
  auto c2 = c2_.head(d);
  c2.noalias() = Z.transpose() * grad;
  auto RZ = rz_.topLeftCorner(k, d);
  RZ.noalias() = Rs * Z;
  auto r2 = r2_.head(k);
  r2 = rs;
  r2.noalias() -= Rs * x;
}

bool LexicographicQp::secondPivoting(int d, int k) {
  const auto Q2 = q2_.topLeftCorner(d, d);
  const auto c2 = c2_.head(d);
  const auto RZ = rz_.topLeftCorner(k, d);
  auto r2 = r2_.head(k);
  // x1 meets every row in exact arithmetic (the first programme's answer, or the caller's feasible
  // point); a row it misses by round-off would make w = 0 infeasible and the pivoting end on a
  // ray. Such a row asks only that w not make it worse.
  r2 = r2.cwiseMin(0.0);
  auto w = w_.head(d);
  return strictSecond(Q2, c2, RZ, r2, w) || qp_.solve(Q2, c2, RZ, r2, w, 100 + 40 * (2 * d + k)) == Lemke::kSolved;
}

// The second programme on the null space of [C; E] (E = R's first eq rows): x = x1 + Z w keeps
// C x and E x exactly, so only R's rows after the 2 eq of the pairs remain, and P is positive
// definite there when the free coordinates it does not weigh (a joint's torque) cannot move
// without the motors or qdd. Z from the pivoted Cholesky factor of C^T C / |C^T C| + E^T E / |E^T E|
// (q_ holds C^T C). The answer is checked (every row of R, C's change within round-off): false
// leaves x at x1.
bool LexicographicQp::secondOnEqualities(const Eigen::Ref<const Eigen::MatrixXd>& P,
                                         const Eigen::Ref<const Eigen::VectorXd>& pv,
                                         const Eigen::Ref<const Eigen::MatrixXd>& R,
                                         const Eigen::Ref<const Eigen::VectorXd>& r, Eigen::Ref<Eigen::VectorXd> x,
                                         int eq) {
  const int p = static_cast<int>(x.size()), k = static_cast<int>(r.size()) - 2 * eq;
  const auto Q = q_.topLeftCorner(p, p);
  const double qs = std::max(1e-300, Q.diagonal().maxCoeff());
  const int d = nullBasisWithEqualities(R.topRows(eq));
  if (d == 0) return false;
  if (!secondOnNull(P, pv, R.bottomRows(k), r.tail(k), x, d)) return false;
  auto u = c_.head(p);  // the step Z w, checked before it is taken
  u.noalias() = z_.topLeftCorner(p, d) * w_.head(d);
  auto Qu = diag_.head(p);
  Qu.noalias() = Q * u;
  const double size = std::max(1.0, (x + u).cwiseAbs().maxCoeff());
  if (u.dot(Qu) > 1e-18 * qs * size * size) return false;  // C x changed beyond round-off
  const double row_tol = 1e-9 * std::max(1.0, R.cwiseAbs().maxCoeff()) * size;
  for (int i = 0; i < static_cast<int>(r.size()); ++i)
    if (R.row(i).dot(x) + R.row(i).dot(u) < r(i) - row_tol) return false;
  x += u;
  return true;
}

// A basis of C's null space into z_'s first columns (returns their number) from the pivoted
// Cholesky factor of Q = C^T C (pivots above 1e-12 of its largest diagonal entry): Q(perm, perm) ~
// V V^T with V lower trapezoidal in pivot order (L1 its r x r top); the null direction of each
// position b not pivoted has z(b) = 1 and z(piv) = -L1^-T V(b, :)^T.
int LexicographicQp::nullBasis(const Eigen::Ref<const Eigen::MatrixXd>& Q) {
  const int p = static_cast<int>(Q.rows());
  for (int i = 0; i < p; ++i) idx_(i) = i;
  auto V = v_.topLeftCorner(p, p);
  const double top = std::max(1e-300, Q.diagonal().cwiseAbs().maxCoeff());
  const int r = pivotedCholeskyLeft(Q, idx_, p, V, diag_, piv_, 1e-12 * top);
  constexpr double kDone = -std::numeric_limits<double>::infinity();  // pivotedCholeskyLeft's mark
  int d = 0;
  for (int b = 0; b < p && r < p; ++b) {
    if (diag_(b) == kDone) continue;  // a pivot
    auto z = z_.col(d++).head(p);
    z.setZero();
    z(b) = 1.0;
    auto c = w_.head(std::max(r, 1));  // L1^T c = -V(b, :)^T (w_: free until the second programme)
    for (int i = 0; i < r; ++i) c(i) = -V(b, i);
    pivotedBackward(V, piv_, r, c);
    for (int i = 0; i < r; ++i) z(piv_(i)) = c(i);
  }
  return d;
}

// nullBasis() of C^T C / |C^T C| + E^T E / |E^T E| (q_ holds C^T C; built in q2_): the directions
// that keep both C x and E x.
int LexicographicQp::nullBasisWithEqualities(const Eigen::Ref<const Eigen::MatrixXd>& E) {
  const int p = static_cast<int>(E.cols());
  const auto Q = q_.topLeftCorner(p, p);
  auto Qe = q2_.topLeftCorner(p, p);
  Qe.noalias() = E.transpose().lazyProduct(E);
  const double qs = std::max(1e-300, Q.diagonal().maxCoeff()), es = std::max(1e-300, Qe.diagonal().maxCoeff());
  Qe /= es;
  Qe += Q / qs;
  return nullBasis(Qe);
}

// The second programme has a positive definite Q2 (P is, on Z's span): its dual is an LCP in the
// k multipliers alone, w = Q2^-1 (RZ^T l - c2), s = RZ w - r2 = (RZ Q2^-1 RZ^T) l - RZ Q2^-1 c2 - r2,
// half the size of the doubled primal. False (w unset) when Q2's Cholesky is not certain or the
// pivoting does not finish: the primal form then runs.
bool LexicographicQp::strictSecond(const Eigen::Ref<const Eigen::MatrixXd>& Q2,
                                   const Eigen::Ref<const Eigen::VectorXd>& c2,
                                   const Eigen::Ref<const Eigen::MatrixXd>& RZ,
                                   const Eigen::Ref<const Eigen::VectorXd>& r2, Eigen::Ref<Eigen::VectorXd> w) {
  const int d = static_cast<int>(c2.size()), k = static_cast<int>(r2.size());
  auto L = l2_.topLeftCorner(d, d);
  if (!choleskyCertified(Q2, L, 1e-12 * std::max(1e-300, Q2.diagonal().cwiseAbs().maxCoeff()))) return false;
  auto G = g2_.topLeftCorner(d, k + 1);  // Q2^-1 [RZ^T, c2]
  G.leftCols(k) = RZ.transpose();
  G.col(k) = c2;
  choleskySolveColumns(L, G);
  auto M = m2_.topLeftCorner(k, k);
  M.noalias() = RZ * G.leftCols(k);
  auto q = q2v_.head(k);
  q = -r2;
  q.noalias() -= RZ * G.col(k);
  int pivots = 0;
  if (lemke2_.solve(M, q, l_.head(k), s_.head(k), 100 + 40 * k, pivots) != Lemke::kSolved) return false;
  w.noalias() = G.leftCols(k) * l_.head(k);
  w -= G.col(k);
  return true;
}

}  // namespace detail
}  // namespace vereshchagin
