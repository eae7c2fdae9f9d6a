// The dual active-set method (dual_qp.hpp). With L L^T = H and B = L^-1 N (N: the active rows'
// normals as columns), the step for a new row n is
//     d = L^-1 n,   r = (B^T B)^-1 B^T d,   z = L^-T (d - B r),   z^T n = ||d - B r||^2:
// moving x by t z changes the new row by t z^T n and keeps the active rows, while the active
// multipliers change by -t r and the new one by +t (the optimality conditions H x + g = N u stay
// true along the step). The step length is the smaller of the full step (the new row met) and the
// partial one (an inequality's multiplier reaching zero: that row leaves).
#include "dual_qp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dense_small.hpp"

namespace vereshchagin {
namespace detail {

void DualActiveSetQp::reserve(int p, int k) {
  if (l_.rows() < p) {
    l_.resize(p, p), b_.resize(p, p), j_.resize(p, p), t_.resize(p, p);
    d_.resize(p), z_.resize(p), r_.resize(p), u_.resize(p), w_.resize(p);
    act_.resize(p);
  }
  if (norm_.size() < k) norm_.resize(k), s_.resize(k), is_active_.resize(k);
}

void DualActiveSetQp::direction(const Eigen::Ref<const Eigen::MatrixXd>& A, int row, double& zn) {
  const int p = p_, a = na_;
  const double* Lp = l_.data();
  const Eigen::Index ls = l_.outerStride();
  double* d = d_.data();
  for (int i = 0; i < p; ++i) {  // d = L^-1 n
    double v = A(row, i);
    for (int c = 0; c < i; ++c) v -= Lp[i + c * ls] * d[c];
    d[i] = v / Lp[i + i * ls];
  }
  // w = d - J h, h = J^T d (twice: the second pass removes what round-off left in J's span).
  double* w = w_.data();
  double* h = r_.data();
  for (int i = 0; i < p; ++i) w[i] = d[i];
  for (int j = 0; j < a; ++j) h[j] = 0.0;
  for (int pass = 0; pass < 2; ++pass)
    for (int j = 0; j < a; ++j) {
      const double* q = &j_(0, j);
      double v = 0.0;
      for (int i = 0; i < p; ++i) v += q[i] * w[i];
      h[j] += v;
      for (int i = 0; i < p; ++i) w[i] -= v * q[i];
    }
  double dd = 0.0, ww = 0.0;
  for (int i = 0; i < p; ++i) dd += d[i] * d[i], ww += w[i] * w[i];
  zn = a >= p || ww <= 1e-20 * dd ? 0.0 : ww;  // 0: n depends on the active normals
  for (int j = a - 1; j >= 0; --j) {           // r = T^-1 h (B = J T, T upper triangular)
    double v = h[j];
    for (int c = j + 1; c < a; ++c) v -= t_(j, c) * h[c];
    h[j] = v / t_(j, j);
  }
  double* z = z_.data();
  for (int i = p - 1; i >= 0; --i) {  // z = L^-T w
    double v = w[i];
    for (int c = i + 1; c < p; ++c) v -= Lp[c + i * ls] * z[c];
    z[i] = v / Lp[i + i * ls];
  }
}

// Column j of J and T from B's column j and J's first j columns (modified Gram-Schmidt, twice).
void DualActiveSetQp::orthogonalize(int j) {
  const int p = p_;
  double* q = &j_(0, j);
  const double* b = &b_(0, j);
  for (int i = 0; i < p; ++i) q[i] = b[i];
  for (int c = 0; c <= j; ++c) t_(c, j) = 0.0;
  for (int pass = 0; pass < 2; ++pass)
    for (int c = 0; c < j; ++c) {
      const double* qc = &j_(0, c);
      double v = 0.0;
      for (int i = 0; i < p; ++i) v += qc[i] * q[i];
      t_(c, j) += v;
      for (int i = 0; i < p; ++i) q[i] -= v * qc[i];
    }
  double nn = 0.0;
  for (int i = 0; i < p; ++i) nn += q[i] * q[i];
  const double norm = std::sqrt(nn);
  t_(j, j) = norm;
  for (int i = 0; i < p; ++i) q[i] /= norm;
}

void DualActiveSetQp::addActive(int row, double u) {
  act_(na_) = row;
  u_(na_) = u;
  b_.col(na_).head(p_) = d_.head(p_);
  is_active_(row) = true;
  orthogonalize(na_);
  ++na_;
}

void DualActiveSetQp::dropActive(int j) {
  is_active_(act_(j)) = false;
  for (int i = j; i + 1 < na_; ++i) {
    act_(i) = act_(i + 1);
    u_(i) = u_(i + 1);
    b_.col(i).head(p_) = b_.col(i + 1).head(p_);
  }
  --na_;
  for (int i = j; i < na_; ++i) orthogonalize(i);
}

DualActiveSetQp::Result DualActiveSetQp::solve(const Eigen::Ref<const Eigen::MatrixXd>& H,
                                               const Eigen::Ref<const Eigen::VectorXd>& g,
                                               const Eigen::Ref<const Eigen::MatrixXd>& A,
                                               const Eigen::Ref<const Eigen::VectorXd>& b, int eq,
                                               Eigen::Ref<Eigen::VectorXd> x, int max_steps) {
  const int p = static_cast<int>(g.size()), k = static_cast<int>(b.size());
  p_ = p;
  na_ = 0;
  auto L = l_.topLeftCorner(p, p);
  if (!choleskyCertified(H, L, 1e-14 * std::max(1e-300, H.diagonal().cwiseAbs().maxCoeff()))) return kNotDefinite;
  x = -g;
  choleskySolve(L, x);
  double xs = std::max(1.0, x.cwiseAbs().maxCoeff());
  for (int i = 0; i < k; ++i) norm_(i) = A.row(i).norm(), is_active_(i) = false;
  // A row counts as met within round-off of its terms.
  const auto slack = [&](int i) { return A.row(i).dot(x) - b(i); };
  const auto tol = [&](int i) { return 1e-13 * std::max({1.0, std::abs(b(i)), norm_(i) * xs}); };
  // A row missed by more than round-off of a degenerate vertex's steps.
  const auto met = [&](int i) { return 1e-9 * std::max({1.0, std::abs(b(i)), norm_(i) * xs}); };
  int steps = 0;
  bool skipped = false;
  // The equalities first, each with a full step (their multipliers have no sign).
  for (int i = 0; i < eq; ++i) {
    if (norm_(i) == 0.0) {
      if (std::abs(b(i)) > tol(i)) return kInfeasible;
      continue;
    }
    double zn = 0.0;
    direction(A, i, zn);
    if (zn == 0.0) {  // implied by the earlier equalities: consistent, or no point at all
      if (std::abs(slack(i)) > met(i)) return kInfeasible;
      continue;
    }
    const double t = -slack(i) / zn;
    x.noalias() += t * z_.head(p);
    u_.head(na_).noalias() -= t * r_.head(na_);
    addActive(i, t);
    xs = std::max(1.0, x.cwiseAbs().maxCoeff());
  }
  while (true) {
    // The most violated inequality, relative to its normal's length.
    int add = -1;
    double worst = 0.0;
    double* s = s_.data();  // every row's slack A x - b, column by column
    for (int i = 0; i < k; ++i) s[i] = -b(i);
    for (int j = 0; j < p; ++j) {
      const double xj = x(j);
      const double* col = A.data() + j * A.outerStride();
      for (int i = 0; i < k; ++i) s[i] += col[i] * xj;
    }
    for (int i = eq; i < k; ++i) {
      if (is_active_(i) || norm_(i) == 0.0) continue;
      if (s[i] < -tol(i) && s[i] / norm_(i) < worst) worst = s[i] / norm_(i), add = i;
    }
    if (add < 0) {
      for (int i = eq; i < k && skipped; ++i)  // the rows left out are still met
        if (is_active_(i) && slack(i) < -met(i)) return kInfeasible;
      return kSolved;
    }
    double u_new = 0.0;
    while (true) {  // steps for the row `add` until it is met
      if (++steps > max_steps) return kStepLimit;
      double zn = 0.0;
      direction(A, add, zn);
      // The partial step: the first inequality multiplier to reach zero.
      int drop = -1;
      double t1 = std::numeric_limits<double>::infinity();
      for (int j = 0; j < na_; ++j)
        if (act_(j) >= eq && r_(j) > 0.0 && u_(j) / r_(j) < t1) t1 = u_(j) / r_(j), drop = j;
      if (zn == 0.0) {   // only the dual step
        if (drop < 0) {  // the active rows imply the row's normal with no multiplier to release
          if (slack(add) < -met(add)) return kInfeasible;
          is_active_(add) = true;  // missed by round-off only (a degenerate vertex): left out
          skipped = true;
          break;
        }
        u_.head(na_).noalias() -= t1 * r_.head(na_);
        u_new += t1;
        dropActive(drop);
        continue;
      }
      const double t2 = -slack(add) / zn;
      const double t = std::min(t1, t2);
      x.noalias() += t * z_.head(p);
      u_.head(na_).noalias() -= t * r_.head(na_);
      u_new += t;
      xs = std::max(1.0, x.cwiseAbs().maxCoeff());
      if (t2 <= t1) {
        addActive(add, u_new);
        break;
      }
      dropActive(drop);
    }
  }
}

}  // namespace detail
}  // namespace vereshchagin
