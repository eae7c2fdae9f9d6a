// Constraints on any segments (Shakhimardanov's extension of the Popov-Vereshchagin recursion):
// the general path of ChainHdSolver::solve(). Conventions in chain_hd_solver.hpp.
//
// Columns are sorted by segment, most distal first, so that the columns felt by segment i are a
// prefix [0, active_[i]) of the sorted order: a constraint on segment k acts on segments <= k
// only. In the inward sweep segment i's own columns (alfa in its tip axes) join the wrenches
// passed from its child; each column then goes through the same projection A <- A - u e / D as on
// the end-segment path, and K = sum_i D_i^-1 e_i e_i^T with e_i = A_i^T S_i couples every pair.
#include <algorithm>
#include <cmath>

#include "articulated_step.hpp"
#include "dense_small.hpp"
#include "model_validation.hpp"

namespace vereshchagin {

int ChainHdSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                         const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                         const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
                         const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  solved_ = false;
  general_ = false;
  if (segments.size() != alfa.cols())
    return fail(E_SIZE_MISMATCH, "segments has %ld entries, expected %ld (one per alfa column)", (long)segments.size(),
                (long)alfa.cols());
  bool last_only = alfa.cols() <= kMaxConstraints && ns_ > 0;
  for (Eigen::Index c = 0; c < segments.size() && last_only; ++c) last_only = segments(c) == static_cast<int>(ns_) - 1;
  if (last_only) return solve(q, q_dot, alfa, beta, f_ext, ff_torques);  // the end-segment path

  int rc = checkInputs(q, q_dot, alfa, beta, f_ext, ff_torques, mcap_);
  if (rc != E_NOERROR) return rc;
  rc = sortColumns(segments);
  if (rc != E_NOERROR) return rc;
  general_ = true;
  outwardSweep(q, q_dot, f_ext);
  rc = inwardSweepGeneral(alfa, ff_torques);
  if (rc != E_NOERROR) {
    general_ = false;
    return rc;
  }
  rc = passThroughEnergy(f_ext, ff_torques);
  if (rc != E_NOERROR) {
    general_ = false;
    return rc;
  }
  factorizeCouplingGeneral();
  const int m = m_;
  for (int k = 0; k < m; ++k) rhs_g_(k) = ug_(k) - beta(order_(k));  // nu = K^+ (U - beta)
  if (pt_used_) rhs_g_.head(m) -= pt_energy_.head(m);                // the drivers' parts that pass through
  couplingSolve(rhs_g_.head(m), nug_.head(m));
  finalSweepGeneral(ff_torques);
  for (int k = 0; k < m; ++k) nu_user_(order_(k)) = nug_(k);
  commandFromNuGeneral(nug_.head(m), tau_cmd_);
  rc = checkBounded(nu_user_.head(m), q_dot, beta, f_ext, ff_torques);
  if (rc != E_NOERROR) return rc;
  solved_ = true;
  error = E_NOERROR;
  return E_NOERROR;
}

// Counting sort of the columns by segment, distal first (stable within a segment).
int ChainHdSolver::sortColumns(const Eigen::Ref<const Eigen::VectorXi>& segments) {
  const int m = static_cast<int>(segments.size());
  seg_count_.setZero();
  for (int c = 0; c < m; ++c) {
    const int s = segments(c);
    if (s < 0 || s >= static_cast<int>(ns_))
      return fail(E_OUT_OF_RANGE, "segments(%d) = %d is out of range [0, %u)", c, s, ns_);
    if (++seg_count_(s) > kMaxConstraints)
      return fail(E_TOO_MANY_CONSTRAINTS, "segment %d ('%s') has more than %d constraint columns", s,
                  chain_.getSegment(s).getName().c_str(), kMaxConstraints);
  }
  active_[ns_] = 0;
  for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) active_[i] = active_[i + 1] + seg_count_(i);
  for (unsigned int i = 0; i < ns_; ++i) seg_count_(i) = active_[i + 1];  // next free position
  for (int c = 0; c < m; ++c) order_(seg_count_(segments(c))++) = c;
  m_ = m;
  return E_NOERROR;
}

int ChainHdSolver::inwardSweepGeneral(const Eigen::Ref<const Matrix6X>& alfa,
                                      const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  const int M = m_;
  ug_.head(M).setZero();
  kg_.topLeftCorner(M, M).setZero();
  double kappa = 0.0;
  const bool has_tau = ff_torques.size() != 0;
  for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) {
    Segment& s = segs_[i];
    const int c0 = active_[i + 1], c = active_[i];
    // This segment's own columns: alfa in its tip axes (the moment is already about its origin).
    for (int k = c0; k < c; ++k) {
      const auto a = alfa.col(order_(k));
      anew_.col(k).head<3>().noalias() = s.R_base.transpose() * a.head<3>();
      anew_.col(k).tail<3>().noalias() = s.R_base.transpose() * a.tail<3>();
      acur_.col(k) = anew_.col(k);
    }
    auto A = acur_.leftCols(c);
    auto Ap = aproj_.leftCols(c);
    Vector6 pa;
    eg_.col(i).head(M).setZero();
    if (s.joint >= 0) {
      double free = 0.0;
      if (!articulate(s, has_tau ? ff_torques(s.joint) : 0.0, pa, free)) return degenerate(i);
      if (c > 0) {
        auto e = eg_.col(i).head(c);  // A^T S
        e.noalias() = A.transpose().lazyProduct(s.S);
        const Vector6 bias = s.c + s.S * free;
        ug_.head(c).noalias() += A.transpose().lazyProduct(bias);
        kg_.topLeftCorner(c, c).noalias() += s.Dinv * e.lazyProduct(e.transpose());
        // The end-segment path's unit-consistent bound of |e_c|: |v||f_c| + |w||n_c|.
        kappa += 2.0 * s.Dinv * (s.v2 * A.topRows<3>().squaredNorm() + s.w2 * A.bottomRows<3>().squaredNorm());
        Ap = A;
        Ap.noalias() -= (s.Dinv * s.u).lazyProduct(e.transpose());
      }
    } else {
      pa = s.pA;
      if (c > 0) Ap = A;
    }
    if (c > 0) {  // to the parent's frame (the base frame for i = 0): f = R f', n = R n' + p x f
      A.topRows<3>().noalias() = s.X.R.lazyProduct(Ap.topRows<3>());
      A.bottomRows<3>().noalias() = s.X.R.lazyProduct(Ap.bottomRows<3>());
      A.bottomRows<3>().noalias() += skew(s.X.p).lazyProduct(A.topRows<3>());
    }
    if (i > 0) {
      passToParent(i, pa);
    } else if (c > 0) {
      ug_.head(c).noalias() += A.transpose().lazyProduct(root_acc_);
    }
  }
  kappa_ = kappa;
  return E_NOERROR;
}

// K = kg_ (M x M): certified Cholesky (truncation policy, every eigenvalue provably above the
// threshold) else a Jacobi eigen-decomposition with the policy's multipliers.
void ChainHdSolver::factorizeCouplingGeneral() {
  const int m = m_;
  rank_ = 0;
  sigma_known_ = false;
  use_cholesky_ = false;
  if (m == 0) return;
  const auto K = kg_.topLeftCorner(m, m);
  if (options_.policy == SingularityPolicy::TruncatedPseudoInverse) {
    auto L = cholg_.topLeftCorner(m, m);
    L.setZero();
    if (detail::choleskyCertified(K, L, 0.0)) {
      auto x = tmp_g_.head(m);
      const double lower = 1.0 / detail::inverseFrobeniusSquared(L, x);  // <= lambda_min(K)
      if (std::isfinite(lower) && lower > options_.rcond * kappa_) {
        use_cholesky_ = true;
        rank_ = m;
        return;
      }
    }
  }
  auto W = work_g_.topLeftCorner(m, m);
  auto V = vg_.topLeftCorner(m, m);
  W = K;
  detail::jacobiEigen(W, V);
  const auto lam = W.diagonal();
  const double cut = options_.rcond * std::max(std::max(lam.maxCoeff(), 0.0), kappa_);
  sigma_min_ = std::max(lam.minCoeff(), 0.0);
  sigma_known_ = true;
  auto inv = invg_.head(m);
  rank_ = detail::policyMultipliers(lam, inv, cut, options_.policy == SingularityPolicy::TruncatedPseudoInverse,
                                    options_.damping);
}

void ChainHdSolver::couplingSolve(const Eigen::Ref<const Eigen::VectorXd>& rhs, Eigen::Ref<Eigen::VectorXd> out) const {
  const int m = m_;
  if (!general_) {
    VectorC r = rhs.head(m), o;
    applyCouplingInverse(r, o);
    out.head(m) = o;
    return;
  }
  if (m == 0) return;
  if (use_cholesky_) {
    out.head(m) = rhs.head(m);
    auto x = out.head(m);
    detail::choleskySolve(cholg_.topLeftCorner(m, m), x);
    return;
  }
  const auto V = vg_.topLeftCorner(m, m);
  tmp_g_.head(m).noalias() = V.transpose().lazyProduct(rhs.head(m));
  tmp_g_.head(m).array() *= invg_.head(m).array();
  out.head(m).noalias() = V.lazyProduct(tmp_g_.head(m));
}

// Final outward sweep of the several-segment path: the active columns felt by segment i.
void ChainHdSolver::finalSweepGeneral(const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  finalSweep(ff_torques, [this](int i, const Segment&) {
    const int c = active_[i];
    return c > 0 ? eg_.col(i).head(c).dot(nug_.head(c)) : 0.0;
  });
}

// tau_cmd = -sum_c J_c^T alfa_c nu_c: each segment adds the wrenches -alfa nu of its own columns
// (tip axes, tip origin) to what its descendants pass, carried rigidly to the base.
void ChainHdSolver::commandFromNuGeneral(const Eigen::Ref<const Eigen::VectorXd>& nu_sorted,
                                         Eigen::Ref<Eigen::VectorXd> tau_cmd) const {
  tau_cmd.setZero();
  Vector6 f = Vector6::Zero();
  for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) {
    const Segment& s = segs_[i];
    const int c0 = active_[i + 1], c = active_[i];
    if (c > c0) f.noalias() -= anew_.middleCols(c0, c - c0).lazyProduct(nu_sorted.segment(c0, c - c0));
    if (s.joint >= 0) tau_cmd(s.joint) = s.S.dot(f);
    if (i > 0) f = forceToParent(s.X, f);
  }
}

}  // namespace vereshchagin
