// LexicographicQp's first try (lemke.hpp): the two programmes by the dual active-set method
// (dual_qp.hpp) instead of Lemke's pivoting on the doubled primal, with a certificate; when any
// part does not hold, solve() goes on with the pivoting, which does not depend on this.
//   1. The active rows W of the strictly convex programme min 1/2 ||t + C x||^2 + eps (1/2 x^T P x
//      + p^T x) (eps = 1e-7 of the two Hessians' scale ratio): for small eps its minimiser is near
//      the lexicographic one and its active rows are the lexicographic answer's. With the equality
//      E x = 0 (R's first eq rows, written there as pairs within a round-off slack; here one
//      equality row each, the pairs' second halves left out) E^T E is added at the first Hessian's
//      scale, zero on the feasible set.
//   2. The first programme on W's rows held as equalities, exactly: x1 = y + P_W v with y on the
//      rows (R_W y = r_W, the least change of step 1's x) and P_W = I - R_W^T (R_W R_W^T)^-1 R_W
//      the projector onto their null space, v from P_W Q P_W v = -P_W (c + Q y) (Q = C^T C,
//      c = C^T t; a consistent positive semi-definite system, a pivoted Cholesky factor's
//      particular solution).
//   3. The second programme on C's null space (with E: on [C; E]'s) from x1 (x = x1 + Z w), by the
//      dual active-set method: it needs no feasible start, so x1 need not meet the other rows.
//   4. The certificate: every row met to round-off (1e-9 of its terms; E x = 0 too), and x optimal for the first
//      programme: its gradient C^T (t + C x) = R_W^T l with l >= 0 on the inequalities, every row
//      with l > 0 active at x. Then x is the lexicographic answer (the second programme's optimum
//      over the first's optimal set {R x >= r, C x = C x1}).
#include <algorithm>
#include <cmath>

#include "dense_small.hpp"
#include "lemke.hpp"

namespace vereshchagin {
namespace detail {

void LexicographicQp::reserveActiveSet(int p, int k) {
  if (as_h_.rows() < p) {
    as_h_.resize(p, p), as_pw_.resize(p, p), as_s_.resize(p, p), as_v_.resize(p, p), as_rw_.resize(p, p);
    as_gw_.resize(p, p), as_lw_.resize(p, p);
    as_g_.resize(p), as_x_.resize(p), as_y_.resize(p), as_t_.resize(p), as_diag_.resize(p), as_l_.resize(p);
    as_idx_.resize(p), as_piv_.resize(p);
  }
  if (as_a_.rows() < k || as_a_.cols() < as_h_.cols()) {
    as_a_.resize(std::max<Eigen::Index>(k, as_a_.rows()), as_h_.cols());
    as_b_.resize(as_a_.rows());
  }
  gi_.reserve(static_cast<int>(as_h_.cols()), static_cast<int>(as_a_.rows()));
  gi2_.reserve(static_cast<int>(as_h_.cols()), static_cast<int>(as_a_.rows()));
}

// Step 2: the first programme's minimiser on W's rows (gi_'s active rows of as_a_, as_b_) into
// as_y_, from step 1's x (as_x_). False when W's rows are not safely independent.
bool LexicographicQp::firstOnActive(int p) {
  const int a = gi_.activeCount();
  auto RW = as_rw_.topLeftCorner(a, p);
  for (int j = 0; j < a; ++j) RW.row(j) = as_a_.row(gi_.active(j)).head(p);
  auto y = as_y_.head(p);
  y = as_x_.head(p);
  auto Pw = as_pw_.topLeftCorner(p, p);
  Pw.setIdentity();
  if (a > 0) {
    auto G = as_gw_.topLeftCorner(a, a);
    G.noalias() = RW.lazyProduct(RW.transpose());
    auto LG = as_lw_.topLeftCorner(a, a);
    if (!choleskyCertified(G, LG, 1e-12 * std::max(1e-300, G.diagonal().maxCoeff()))) return false;
    auto e = as_l_.head(a);  // the rows' misses at x, then the least change meeting them
    for (int j = 0; j < a; ++j) e(j) = as_b_(gi_.active(j)) - RW.row(j).dot(y);
    choleskySolve(LG, e);
    y.noalias() += RW.transpose() * e;
    if (a >= p) return true;             // W's rows fix the point: y is the minimiser
    auto X = as_v_.topLeftCorner(a, p);  // (R_W R_W^T)^-1 R_W
    X = RW;
    choleskySolveColumns(LG, X);
    Pw.noalias() -= RW.transpose().lazyProduct(X);
  }
  // P_W Q P_W v = -P_W (c + Q y).
  const auto Q = q_.topLeftCorner(p, p);
  auto S = as_s_.topLeftCorner(p, p);
  auto QP = as_h_.topLeftCorner(p, p);  // (step 1's Hessian is no longer needed)
  QP.noalias() = Q.lazyProduct(Pw);
  S.noalias() = Pw.lazyProduct(QP);
  auto rhs = as_t_.head(p);
  auto grad = as_g_.head(p);
  grad = c_.head(p);
  grad.noalias() += Q * y;
  rhs.noalias() = -Pw * grad;
  for (int i = 0; i < p; ++i) as_idx_(i) = i;
  auto V = as_v_.topLeftCorner(p, p);
  // (pivots relative to Q's scale: S may be round-off where W's rows span nearly everything)
  const double top = std::max(1e-300, Q.diagonal().maxCoeff());
  const int r = pivotedCholeskyLeft(S, as_idx_, p, V, as_diag_, as_piv_, 1e-12 * top);
  auto w = as_l_.head(std::max(r, 1));
  for (int i = 0; i < r; ++i) w(i) = rhs(as_piv_(i));
  pivotedForward(V, as_piv_, r, w);  // L1 L1^T w = rhs(piv)
  pivotedBackward(V, as_piv_, r, w);
  auto v = as_x_.head(p);  // (step 1's x is no longer needed)
  v.setZero();
  for (int i = 0; i < r; ++i) v(as_piv_(i)) = w(i);
  y.noalias() += Pw * v;
  return true;
}

// Step 4 at x: every row met, the first programme's multipliers on W.
bool LexicographicQp::certified(const Eigen::Ref<const Eigen::VectorXd>& x, int eq, int rows) {
  const int p = static_cast<int>(x.size()), a = gi_.activeCount();
  const double xs = std::max(1.0, x.cwiseAbs().maxCoeff());
  const auto row_tol = [&](int i) {
    return 1e-9 * std::max({1.0, std::abs(as_b_(i)), as_a_.row(i).head(p).cwiseAbs().maxCoeff() * xs});
  };
  for (int i = 0; i < rows; ++i) {
    const double s = as_a_.row(i).head(p).dot(x) - as_b_(i);
    if (i < eq ? std::abs(s) > row_tol(i) : s < -row_tol(i)) return false;
  }
  const auto Q = q_.topLeftCorner(p, p);
  auto grad = as_g_.head(p);
  grad = c_.head(p);
  grad.noalias() += Q * x;
  const double gs = std::max(1e-300, c_.head(p).cwiseAbs().maxCoeff() + Q.cwiseAbs().maxCoeff() * xs);
  if (a == 0) return grad.cwiseAbs().maxCoeff() <= 1e-9 * gs;
  const auto RW = as_rw_.topLeftCorner(a, p);
  auto l = as_l_.head(a);
  l.noalias() = RW * grad;
  choleskySolve(as_lw_.topLeftCorner(a, a), l);  // (R_W R_W^T)^-1 R_W grad
  auto res = as_t_.head(p);
  res = grad;
  res.noalias() -= RW.transpose() * l;
  if (res.cwiseAbs().maxCoeff() > 1e-9 * gs) return false;
  for (int j = 0; j < a; ++j) {
    const int i = gi_.active(j);
    if (i < eq) continue;  // an equality's multiplier has no sign
    // A multiplier's scale: the gradient's over the row's length.
    const double ls = 1e-9 * gs / std::max(1e-300, as_a_.row(i).head(p).norm());
    if (l(j) < -ls) return false;
    if (l(j) > ls && std::abs(as_a_.row(i).head(p).dot(x) - as_b_(i)) > row_tol(i)) return false;
  }
  return true;
}

LexicographicQp::ActiveSet LexicographicQp::activeSetSolve(const Eigen::Ref<const Eigen::MatrixXd>& P,
                                                           const Eigen::Ref<const Eigen::VectorXd>& pv,
                                                           const Eigen::Ref<const Eigen::MatrixXd>& R,
                                                           const Eigen::Ref<const Eigen::VectorXd>& r,
                                                           Eigen::Ref<Eigen::VectorXd> x, int eq) {
  const int p = static_cast<int>(x.size()), k = static_cast<int>(r.size()) - 2 * eq, rows = eq + k;
  const auto Q = q_.topLeftCorner(p, p);
  const double sq = Q.diagonal().maxCoeff(), sp = P.diagonal().maxCoeff();
  if (!(sq > 0.0) || !(sp > 0.0)) return ActiveSet::kUnknown;
  // The rows: E x = 0 (R's first eq rows; the pairs' second halves left out), then the others.
  auto A = as_a_.topLeftCorner(rows, p);
  auto b = as_b_.head(rows);
  A.topRows(eq) = R.topRows(eq);
  b.head(eq).setZero();
  A.bottomRows(k) = R.bottomRows(k);
  b.tail(k) = r.tail(k);
  // Step 1 (with E: E^T E at the first Hessian's scale added, zero on the feasible set).
  const double eps = 1e-7 * sq / sp;
  auto H = as_h_.topLeftCorner(p, p);
  H = Q + eps * P;
  if (eq > 0) {
    const double se = std::max(1e-300, A.topRows(eq).cwiseAbs2().rowwise().sum().maxCoeff());
    H.noalias() += (sq / se) * A.topRows(eq).transpose().lazyProduct(A.topRows(eq));
  }
  auto g = as_g_.head(p);
  g = c_.head(p) + eps * pv;
  switch (gi_.solve(H, g, A, b, eq, as_x_.head(p), 5 * (p + rows) + 20)) {
    case DualActiveSetQp::kSolved:
      break;
    case DualActiveSetQp::kInfeasible:  // a violated row that active ones imply, beyond round-off
      return ActiveSet::kInfeasible;
    default:
      return ActiveSet::kUnknown;
  }
  // Step 2.
  if (!firstOnActive(p)) return ActiveSet::kUnknown;
  const auto x1 = as_y_.head(p);
  // Step 3: the second programme on the null space of C (with E: of [C; E]).
  const int d = eq == 0 ? nullBasis(Q) : nullBasisWithEqualities(A.topRows(eq));
  x = x1;
  if (d > 0) {
    // secondData's programme, its products coefficient by coefficient (this path's sizes are a
    // few dozen at most; Eigen's blocked product dominated them), into the same members.
    const auto Z = z_.topLeftCorner(p, d);
    auto PZ = v_.topLeftCorner(p, d);
    PZ.noalias() = P.lazyProduct(Z);
    q2_.topLeftCorner(d, d).noalias() = Z.transpose().lazyProduct(PZ);
    auto grad = w_.head(p);
    grad.noalias() = P * x1;
    grad += pv;
    c2_.head(d).noalias() = Z.transpose() * grad;
    rz_.topLeftCorner(k, d).noalias() = A.bottomRows(k).lazyProduct(Z);
    r2_.head(k) = b.tail(k);
    r2_.head(k).noalias() -= A.bottomRows(k) * x1;
    auto w = as_t_.head(d);
    // (a second solver: the certificate reads step 1's active rows from gi_)
    if (gi2_.solve(q2_.topLeftCorner(d, d), c2_.head(d), rz_.topLeftCorner(k, d), r2_.head(k), 0, w,
                   5 * (d + k) + 20) == DualActiveSetQp::kSolved) {
      x.noalias() += Z * w;
    } else {
      // A degenerate vertex (more rows active than null directions, their multipliers huge) can
      // stall the method on round-off: the second programme by the pivoting of its dual, from x1
      // when x1 meets every row.
      if (r2_.head(k).maxCoeff() > 1e-9 * std::max(1.0, b.tail(k).cwiseAbs().maxCoeff())) return ActiveSet::kUnknown;
      if (!secondPivoting(d, k)) return ActiveSet::kUnknown;
      x.noalias() += Z * w_.head(d);
    }
  }
  return certified(x, eq, rows) ? ActiveSet::kAnswered : ActiveSet::kUnknown;
}

}  // namespace detail
}  // namespace vereshchagin
