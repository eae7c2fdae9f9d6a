// Driver pass-through of ChainHdSolver (Shakhimardanov, KU Leuven 2015, sec. 3.5.3, eq. 3.42):
// the acceleration energy along the constraint columns that f_ext alone and ff_torques alone
// give the unconstrained arm, weighted per column. Math and conventions in chain_hd_solver.hpp.
//
// Everything in the recursion is linear in the drivers once the articulated inertias are known:
// a driver's own articulated bias force p (-f_ext in tip axes, plus what the children pass) and
// its torque give free_j = (tau_j - S_j^T p_j) / D_j with the parent at rest, the child passes
// p + u free to its parent, and the energy along the columns is sum_j e_j^T free_j (e_j = S_j^T
// A_j, the columns felt by joint j). Velocity products and root_acc belong to nature only.
#include <cmath>

#include "vereshchagin/chain_hd_solver.hpp"

namespace vereshchagin {

int ChainHdSolver::setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                                  const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through) {
  const long nf = f_ext_pass_through.size(), nt = ff_pass_through.size();
  if (nf != 0 && nt != 0 && nf != nt)
    return fail(E_SIZE_MISMATCH,
                "f_ext_pass_through has %ld entries and ff_pass_through %ld: expected the same "
                "number (one per constraint column) or an empty one",
                nf, nt);
  const long m = std::max(nf, nt);
  if (m > mcap_)
    return fail(E_SIZE_MISMATCH, "pass-through weights have %ld entries, at most %d constraint columns", m, mcap_);
  for (long c = 0; c < nf; ++c)
    if (!(f_ext_pass_through(c) >= 0.0 && f_ext_pass_through(c) <= 1.0))
      return fail(E_OUT_OF_RANGE, "f_ext_pass_through(%ld) = %g is not in [0, 1]", c, f_ext_pass_through(c));
  for (long c = 0; c < nt; ++c)
    if (!(ff_pass_through(c) >= 0.0 && ff_pass_through(c) <= 1.0))
      return fail(E_OUT_OF_RANGE, "ff_pass_through(%ld) = %g is not in [0, 1]", c, ff_pass_through(c));
  if (m == 0) {
    clearPassThrough();
    return E_NOERROR;
  }
  pt_f_.head(m).setZero();
  pt_t_.head(m).setZero();
  if (nf) pt_f_.head(m) = f_ext_pass_through;
  if (nt) pt_t_.head(m) = ff_pass_through;
  pt_f_any_ = nf != 0 && (f_ext_pass_through.array() != 0.0).any();
  pt_t_any_ = nt != 0 && (ff_pass_through.array() != 0.0).any();
  pt_m_ = static_cast<int>(m);
  solved_ = false;
  return E_NOERROR;
}

void ChainHdSolver::clearPassThrough() {
  pt_m_ = -1;
  pt_f_any_ = pt_t_any_ = false;
  solved_ = false;
}

int ChainHdSolver::passThroughEnergy(const Eigen::Ref<const Matrix6X>& f_ext,
                                     const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  pt_used_ = false;
  if (pt_m_ < 0) return E_NOERROR;
  const int m = m_;
  if (pt_m_ != m)
    return fail(E_SIZE_MISMATCH, "the pass-through weights are for %d constraint columns, alfa has %d", pt_m_, m);
  const Eigen::Ref<const Eigen::VectorXd> tau =
      pt_driver_ ? Eigen::Ref<const Eigen::VectorXd>(*pt_driver_) : ff_torques;
  const bool use_f = pt_f_any_ && f_ext.cols() != 0, use_t = pt_t_any_ && tau.size() != 0;
  if (!use_f && !use_t) return E_NOERROR;
  auto energy = pt_energy_.head(m);
  energy.setZero();
  // Weight of column k of the path's order: the caller's column order_(k) on the general path.
  const auto weight = [this](const Eigen::VectorXd& w, int k) { return w(general_ ? order_(k) : k); };
  if (use_f) {
    driverFree(f_ext, zero_joints_.head(0));
    driverEnergy(pt_tmp_.head(m));
    for (int k = 0; k < m; ++k) energy(k) += weight(pt_f_, k) * pt_tmp_(k);
  }
  if (use_t) {
    driverFree(zero_f_ext_.leftCols(0), tau);
    driverEnergy(pt_tmp_.head(m));
    for (int k = 0; k < m; ++k) energy(k) += weight(pt_t_, k) * pt_tmp_(k);
  }
  pt_used_ = true;
  return E_NOERROR;
}

void ChainHdSolver::driverFree(const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& tau) {
  const bool has_f = f_ext.cols() != 0, has_tau = tau.size() != 0;
  Vector6 p_child = Vector6::Zero();  // the child's apparent driver force, in the child's tip frame
  for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) {
    const Segment& s = segs_[i];
    Vector6 p = Vector6::Zero();
    if (i + 1 < static_cast<int>(ns_)) p = forceToParent(segs_[i + 1].X, p_child);
    if (has_f) {  // f_ext: base axes, moment about this tip's origin -> tip axes
      p.head<3>().noalias() -= s.R_base.transpose() * f_ext.col(i).head<3>();
      p.tail<3>().noalias() -= s.R_base.transpose() * f_ext.col(i).tail<3>();
    }
    if (s.joint >= 0) {
      const double free = s.Dinv * ((has_tau ? tau(s.joint) : 0.0) - s.S.dot(p));
      pt_free_(s.joint) = free;
      p += s.u * free;
    }
    p_child = p;
  }
}

void ChainHdSolver::driverEnergy(Eigen::Ref<Eigen::VectorXd> out) const {
  const int m = m_;
  out.setZero();
  for (unsigned int i = 0; i < ns_; ++i) {
    const Segment& s = segs_[i];
    if (s.joint < 0) continue;
    if (general_) {
      out.noalias() += eg_.col(i).head(m) * pt_free_(s.joint);  // zero past the columns i feels
    } else {
      out.noalias() += s.e.leftCols(m).transpose() * pt_free_(s.joint);
    }
  }
}

}  // namespace vereshchagin
