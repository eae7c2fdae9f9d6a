// HdCore: the shared sweeps (poses, velocities, bias forces outward) and the fast path of the
// Popov-Vereshchagin recursion (m <= 6 columns on the last segment of a chain, fixed-size
// blocks). Math and conventions in hd_solver.hpp, notation in hd_core.hpp.
#include <cmath>

#include "articulated_step.hpp"
#include "dense_small.hpp"
#include "hd_core.hpp"
#include "model_validation.hpp"

#if defined(__GNUC__) && !defined(__clang__)
// GCC 12 reports a false -Warray-bounds on Eigen's SSE loads of 1x1 fixed-size products.
#pragma GCC diagnostic ignored "-Warray-bounds"
#endif

namespace vereshchagin {
namespace detail {

// Pose of the tip frame at joint position q: the tip moves by the screw motion exp(q S) of its
// own joint axis (constant in the tip frame), so X(q) = X(0) * exp(q [S]) with, for S = [v; w]
// and theta = |w| q, unit axis k = w / |w|, K = [k]x:  E.R = I + sin(theta) K + (1 - cos(theta)) K K
// (Rodrigues), E.p = (I - E.R) (k x v) / |w| + k (k . v) q;  for |w| = 0 (prismatic) E = (I, v q).
// X0 is folded into the constant factors at model build (SegmentModel::RK, ...), so a pose costs
// one sincos and 27 multiply-adds.
void HdCore::screwPose(const SegmentModel& sm, SegmentState& s, double q) const {
  if (sm.w_norm == 0.0) {
    s.X.R = sm.X0.R;
    s.X.p.noalias() = sm.X0.p + sm.pq * q;
    return;
  }
  const double theta = sm.w_norm * q;
  const double sn = std::sin(theta), c1 = 1.0 - std::cos(theta);
  s.X.R = sm.X0.R + sn * sm.RK + c1 * sm.RKK;
  s.X.p = sm.X0.p - sn * sm.pK - c1 * sm.pKK + q * sm.pq;
}

// Outward sweep: poses, velocities, velocity-product accelerations, rigid bias forces.
void HdCore::outwardSweep(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const Matrix6X>& f_ext) {
  const bool has_fext = f_ext.cols() != 0;
  for (unsigned int i = 0; i < model.ns; ++i) {
    const SegmentModel& sm = model.seg[i];
    SegmentState& s = ws.seg[i];
    const int p = model.parent(i);
    if (sm.joint >= 0) {
      screwPose(sm, s, q(sm.joint));
    } else {
      s.X = sm.X0;
    }
    if (p >= 0) {
      s.R_base.noalias() = ws.seg[p].R_base * s.X.R;
      s.v = motionToChild(s.X, ws.seg[p].v);
    } else if (model.floating) {  // R_base: world axes; the base's velocity (floating_base.cpp)
      s.R_base.noalias() = ws.base.X.R * s.X.R;
      s.v = motionToChild(s.X, ws.base.v);
    } else {
      s.R_base = s.X.R;
      s.v = motionToChild(s.X, Vector6::Zero());
    }
    if (sm.joint >= 0) {
      const Vector6 vj = sm.S * q_dot(sm.joint);
      s.v += vj;
      s.c = crossMotion(s.v, vj);
    } else {
      s.c.setZero();
    }
    s.pA = crossForce(s.v, sm.I * s.v);
    if (has_fext) {
      // f_ext: base axes, moment about this tip's origin -> tip axes.
      s.pA.head<3>().noalias() -= s.R_base.transpose() * f_ext.col(i).head<3>();
      s.pA.tail<3>().noalias() -= s.R_base.transpose() * f_ext.col(i).tail<3>();
    }
    s.IA = sm.I;
  }
}

// Inward sweep of the fast path: articulated inertias and bias forces, constraint wrenches felt
// by each segment, acceleration-energy contributions U and L = -K. Templated on the constraint
// count so that the per-segment constraint algebra runs on fixed-size blocks.
int HdCore::inwardSweep(const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  switch (alfa.cols()) {
    case 0:
      return inwardSweepT<0>(alfa, ff_torques);
    case 1:
      return inwardSweepT<1>(alfa, ff_torques);
    case 2:
      return inwardSweepT<2>(alfa, ff_torques);
    case 3:
      return inwardSweepT<3>(alfa, ff_torques);
    case 4:
      return inwardSweepT<4>(alfa, ff_torques);
    case 5:
      return inwardSweepT<5>(alfa, ff_torques);
    default:
      return inwardSweepT<6>(alfa, ff_torques);
  }
}

template <int M>
int HdCore::inwardSweepT(const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  using VecM = Eigen::Matrix<double, M, 1>;
  using MatM = Eigen::Matrix<double, M, M>;
  using Mat6M = Eigen::Matrix<double, 6, M>;
  const int ns = static_cast<int>(model.ns);
  res.m = M;
  VecM U = VecM::Zero();
  MatM L = MatM::Zero();
  double kappa = 0.0;
  if (ns > 0 && M > 0) {
    // alfa: base axes -> last tip axes (moment reference point is already the tip origin).
    SegmentState& last = ws.seg[ns - 1];
    last.A.template topLeftCorner<3, M>().noalias() = last.R_base.transpose() * alfa.template topLeftCorner<3, M>();
    last.A.template bottomLeftCorner<3, M>().noalias() =
        last.R_base.transpose() * alfa.template bottomLeftCorner<3, M>();
  }
  const bool has_tau = ff_torques.size() != 0;
  for (int i = ns - 1; i >= 0; --i) {
    const SegmentModel& sm = model.seg[i];
    SegmentState& s = ws.seg[i];
    Vector6 pa;
    Mat6M Aproj;  // constraint wrenches passed to the parent
    const auto A = s.A.template leftCols<M>();
    if (sm.joint >= 0) {
      double free = 0.0;
      if (!articulate(i, has_tau ? ff_torques(sm.joint) : 0.0, pa, free)) return degenerate(i);
      if (M > 0) {
        auto e = s.e.template leftCols<M>();  // S^T A, kept for the final sweep
        e.noalias() = sm.S.transpose() * A;
        U.noalias() += A.transpose() * (s.c + sm.S * free);
        L.noalias() -= s.Dinv * e.transpose() * e;
        // |e_c| = |v.f_c + w.n_c| <= |v||f_c| + |w||n_c|, so sum_c e_c^2 <= 2 (|v|^2 |F|^2 +
        // |w|^2 |N|^2): a bound in consistent units (|S|^2 |A|^2 would mix N with N m and
        // inflate at small lengths), without square roots in the sweep.
        kappa += 2.0 * s.Dinv *
                 (sm.v2 * A.template topRows<3>().squaredNorm() + sm.w2 * A.template bottomRows<3>().squaredNorm());
        Aproj = A;
        Aproj.noalias() -= s.Dinv * s.u * e;
      }
    } else {
      pa = s.pA;  // rigid attachment: no joint freedom, no velocity product
      if (M > 0) Aproj = A;
    }
    if (i > 0) {
      passToParent(i, pa);
      SegmentState& p = ws.seg[i - 1];
      if (M > 0) {
        // Constraint wrenches to the parent frame, all columns at once: f = R f', n = R n' + p x f.
        auto top = p.A.template topLeftCorner<3, M>();
        auto bottom = p.A.template bottomLeftCorner<3, M>();
        top.noalias() = s.X.R * Aproj.template topRows<3>();
        bottom.noalias() = s.X.R * Aproj.template bottomRows<3>();
        bottom.noalias() += skew(s.X.p) * top;
      }
    } else if (M > 0) {
      // Constraint wrenches at the base frame: the balance uses A_0^T Xdd_0.
      Mat6M A0;
      A0.template topRows<3>().noalias() = s.X.R * Aproj.template topRows<3>();
      A0.template bottomRows<3>().noalias() = s.X.R * Aproj.template bottomRows<3>();
      A0.template bottomRows<3>().noalias() += skew(s.X.p) * A0.template topRows<3>();
      U.noalias() += A0.transpose() * root_acc;
    }
  }
  ws.fast.U0 = U;
  ws.fast.L0 = L;
  ws.kappa = kappa;
  return 0;
}

// Final outward sweep of the fast path: the constraint forces through S^T A_i = e_i.
template <int M>
void HdCore::finalSweepT(const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  Eigen::Matrix<double, M, 1> nu;
  if (M > 0) nu = res.nu;
  finalSweep(ff_torques,
             [&nu, this](int i) { return M > 0 ? ws.seg[i].e.template leftCols<M>().dot(nu.transpose()) : 0.0; });
}

void HdCore::finalSweepFast(const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  switch (res.m) {
    case 0:
      return finalSweepT<0>(ff_torques);
    case 1:
      return finalSweepT<1>(ff_torques);
    case 2:
      return finalSweepT<2>(ff_torques);
    case 3:
      return finalSweepT<3>(ff_torques);
    case 4:
      return finalSweepT<4>(ff_torques);
    case 5:
      return finalSweepT<5>(ff_torques);
    default:
      return finalSweepT<6>(ff_torques);
  }
}

void HdCore::factorizeCoupling() {
  const int m = res.m;
  CouplingFast& f = ws.fast;
  res.rank = 0;
  res.sigma_known = false;
  ws.use_cholesky = false;
  if (m == 0) return;
  f.K = -f.L0;  // symmetric positive semi-definite
  if (options.policy == SingularityPolicy::TruncatedPseudoInverse && choleskyFullRank()) {
    ws.use_cholesky = true;
    res.rank = m;
    return;
  }
  f.eig.compute(f.K);
  f.inv_eigen.setZero(m);
  const auto& lam = f.eig.eigenvalues();  // ascending
  const double cut = options.rcond * std::max(std::max(lam(m - 1), 0.0), ws.kappa);
  res.sigma_min = std::max(lam(0), 0.0);
  res.sigma_known = true;
  res.rank = detail::policyMultipliers(lam, f.inv_eigen, cut,
                                       options.policy == SingularityPolicy::TruncatedPseudoInverse, options.damping);
}

// Cholesky factor K = L L^T (into chol), and a proof that every eigenvalue of K is above the
// truncation threshold rcond * max(lambda_max, kappa) = rcond * kappa: lambda_min(K) =
// 1 / ||L^-1||_2^2, bounded below first by the k^2 bound of inverseNormBound(), then (when that
// is not enough) by 1 / ||L^-1||_F^2; lambda_max(K) <= trace(K) <= kappa. False if the
// factorisation breaks down or both proofs fail.
bool HdCore::choleskyFullRank() {
  const int m = res.m;
  CouplingFast& f = ws.fast;
  f.chol.setZero(m, m);
  if (!detail::choleskyCertified(f.K, f.chol, 0.0)) return false;
  const double threshold = options.rcond * ws.kappa;
  VectorC x(m);
  if (1.0 / detail::inverseNormBound(f.chol, x) > threshold) return true;
  const double lower = 1.0 / detail::inverseFrobeniusSquared(f.chol, x);
  return std::isfinite(lower) && lower > threshold;
}

double HdCore::smallestSingularValue() const {
  if (!res.sigma_known) {
    const int m = res.m;
    if (m == 0) {
      res.sigma_min = 0.0;
    } else if (res.general) {
      res.sigma_min = smallestEigenvalueGeneral();
    } else {
      // The general path's routine (Householder tridiagonalisation, shifted QR on the diagonals):
      // the same accuracy as Eigen's eigenvalues-only solver at two thirds of its time.
      auto W = ws.general.work_g.topLeftCorner(m, m);
      auto scratch = ws.general.work_v.topRows(m);
      W = ws.fast.K;
      res.sigma_min = std::max(detail::smallestEigenvalue(W, scratch), 0.0);
    }
    res.sigma_known = true;
  }
  return res.sigma_min;
}

void HdCore::applyCouplingInverse(const VectorC& rhs, VectorC& out) const {
  const int m = res.m;
  if (m == 0) {
    out.resize(0);
    return;
  }
  if (ws.use_cholesky) {
    out = rhs;  // K out = rhs with K = L L^T
    detail::choleskySolve(ws.fast.chol, out);
    return;
  }
  VectorC t;
  t.noalias() = ws.fast.eig.eigenvectors().transpose() * rhs;
  t.array() *= ws.fast.inv_eigen.array();
  out.noalias() = ws.fast.eig.eigenvectors() * t;
}

// tau_cmd = -J^T alfa nu: the wrench -A_N nu on the last segment carried rigidly to each joint.
void HdCore::commandFromNu(const VectorC& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) const {
  tau_cmd.setZero();
  const int ns = static_cast<int>(model.ns);
  if (res.m == 0 || ns == 0) return;
  Vector6 f;
  f.noalias() = -(ws.seg[ns - 1].A.leftCols(res.m) * nu);
  // The last segment's A was overwritten by nothing: it is alfa in tip axes.
  for (int i = ns - 1; i >= 0; --i) {
    const SegmentState& s = ws.seg[i];
    if (model.seg[i].joint >= 0) tau_cmd(model.seg[i].joint) = model.seg[i].S.dot(f);
    if (i > 0) forceToParentInPlace(s.X, f);
  }
}

int HdCore::commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) {
  if (!res.solved) return fail(HdSolver::E_NO_SOLUTION, "commandTorquesOf() needs a successful solve() first");
  if (nu.size() != res.m || tau_cmd.size() != model.nj)
    return fail(KDL::SolverI::E_SIZE_MISMATCH, "nu has %ld entries and tau_cmd %ld, expected %d and %u",
                (long)nu.size(), (long)tau_cmd.size(), res.m, model.nj);
  if (res.general) {
    CouplingGeneral& g = ws.general;
    for (int c = 0; c < res.m; ++c) g.tmp(c) = nu(g.order(c));  // sorted order
    commandFromNuGeneral(g.tmp.head(res.m), tau_cmd);
  } else {
    const VectorC v = nu;
    commandFromNu(v, tau_cmd);
  }
  return 0;
}

// Constraints on the last segment: the fast path on a chain, the several-segment path on a tree.
int HdCore::solveLast(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                      const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                      const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  res.solved = false;
  res.general = false;
  state_q = &q;
  state_q_dot = &q_dot;
  if (!model.is_chain) {
    if (alfa.cols() > kMaxConstraints)
      return fail(HdSolver::E_TOO_MANY_CONSTRAINTS, "alfa has %ld columns, at most %d constraints are supported",
                  (long)alfa.cols(), kMaxConstraints);
    Eigen::Matrix<int, Eigen::Dynamic, 1, 0, kMaxConstraints, 1> last(alfa.cols());
    last.setConstant(static_cast<int>(model.ns) - 1);
    return solveGeneral(q, q_dot, alfa, beta, last, f_ext, ff_torques);
  }
  int rc = checkInputs(q, q_dot, alfa, beta, f_ext, ff_torques, kMaxConstraints);
  if (rc != 0) return rc;
  outwardSweep(q, q_dot, f_ext);
  if (loads != nullptr) applyFrameLoads();
  rc = inwardSweep(alfa, ff_torques);
  if (rc != 0) return rc;
  rc = passThroughEnergy(f_ext, ff_torques);
  if (rc != 0) return rc;

  // Balance of acceleration energy at the base: A_0^T Xdd_0 + U_0 + L_0 nu = beta.
  factorizeCoupling();
  const int m = res.m;
  VectorC rhs = ws.fast.U0 - beta;              // nu = L0^-1 (beta - U0) = K^+ (U0 - beta), K = -L0
  if (ws.pt.used) rhs -= ws.pt.energy.head(m);  // the drivers' parts that pass through
  applyCouplingInverse(rhs, res.nu);
  finalSweepFast(ff_torques);
  commandFromNu(res.nu, res.tau_cmd);
  rc = checkBounded(res.nu, q_dot, beta, f_ext, ff_torques);
  if (rc != 0) return rc;
  res.solved = true;
  return 0;
}

void HdCore::accelerationsOf(const Eigen::Ref<const Eigen::VectorXd>& qdd) {
  for (unsigned int i = 0; i < model.ns; ++i) {
    const SegmentModel& sm = model.seg[i];
    Vector6 a = incomingAcceleration(i);
    if (sm.joint >= 0) a += sm.S * qdd(sm.joint);
    ws.seg[i].xdd = a;
  }
  res.link_acc_known = false;
}

// Link accelerations in base axes, computed from the tip-frame ones on first request.
const Matrix6X& HdCore::linkAccelerations() const {
  if (!res.link_acc_known) {
    if (model.floating) {  // the base body's, world axes
      res.link_acc.col(0).head<3>().noalias() = ws.base.X.R * ws.base.xdd.head<3>();
      res.link_acc.col(0).tail<3>().noalias() = ws.base.X.R * ws.base.xdd.tail<3>();
    } else {
      res.link_acc.col(0) = root_acc;
    }
    for (unsigned int i = 0; i < model.ns; ++i) {
      const SegmentState& s = ws.seg[i];
      res.link_acc.col(i + 1).head<3>().noalias() = s.R_base * s.xdd.head<3>();
      res.link_acc.col(i + 1).tail<3>().noalias() = s.R_base * s.xdd.tail<3>();
    }
    res.link_acc_known = true;
  }
  return res.link_acc;
}

}  // namespace detail
}  // namespace vereshchagin
