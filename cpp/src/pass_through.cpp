// Driver pass-through of HdCore (Shakhimardanov, KU Leuven 2015, sec. 3.5.3, eq. 3.42): the
// acceleration energy along the constraint columns that f_ext alone and ff_torques alone give the
// unconstrained robot, weighted per column. Math and conventions in hd_solver.hpp.
//
// Everything in the recursion is linear in the drivers once the articulated inertias are known:
// a driver's own articulated bias force p (-f_ext in tip axes, plus what the children pass) and
// its torque give free_j = (tau_j - S_j^T p_j) / D_j with the parent at rest, the child passes
// p + u free to its parent, and the energy along the columns is sum_j e_j^T free_j (e_j = S_j^T
// A_j, the columns felt by joint j). Velocity products and root_acc belong to nature only.
#include <cmath>

#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

int HdCore::setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                           const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through, PassThroughWeights& pt) {
  const long nf = f_ext_pass_through.size(), nt = ff_pass_through.size();
  if (nf != 0 && nt != 0 && nf != nt)
    return fail(KDL::SolverI::E_SIZE_MISMATCH,
                "f_ext_pass_through has %ld entries and ff_pass_through %ld: expected the same "
                "number (one per constraint column) or an empty one",
                nf, nt);
  const long m = std::max(nf, nt);
  if (m > mcap)
    return fail(KDL::SolverI::E_SIZE_MISMATCH, "pass-through weights have %ld entries, at most %d constraint columns",
                m, mcap);
  for (long c = 0; c < nf; ++c)
    if (!(f_ext_pass_through(c) >= 0.0 && f_ext_pass_through(c) <= 1.0))
      return fail(KDL::SolverI::E_OUT_OF_RANGE, "f_ext_pass_through(%ld) = %g is not in [0, 1]", c,
                  f_ext_pass_through(c));
  for (long c = 0; c < nt; ++c)
    if (!(ff_pass_through(c) >= 0.0 && ff_pass_through(c) <= 1.0))
      return fail(KDL::SolverI::E_OUT_OF_RANGE, "ff_pass_through(%ld) = %g is not in [0, 1]", c, ff_pass_through(c));
  res.solved = false;
  if (m == 0) {
    pt.m = -1;
    pt.f_any = pt.t_any = false;
    return 0;
  }
  pt.f.head(m).setZero();
  pt.t.head(m).setZero();
  if (nf) pt.f.head(m) = f_ext_pass_through;
  if (nt) pt.t.head(m) = ff_pass_through;
  pt.f_any = nf != 0 && (f_ext_pass_through.array() != 0.0).any();
  pt.t_any = nt != 0 && (ff_pass_through.array() != 0.0).any();
  pt.m = static_cast<int>(m);
  return 0;
}

// After an inward sweep of either path: E_SIZE_MISMATCH if weights are set for another column
// count; else, when a weight is non-zero, writes p_f .* a_fext + p_t .* a_ff (m, the path's
// column order) into pt.energy and sets pt.used.
int HdCore::passThroughEnergy(const Eigen::Ref<const Matrix6X>& f_ext,
                              const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  PassThroughState& pt = ws.pt;
  pt.used = false;
  if (pt.weights == nullptr || pt.weights->m < 0) return 0;
  const PassThroughWeights& w = *pt.weights;
  const int m = res.m;
  if (w.m != m)
    return fail(KDL::SolverI::E_SIZE_MISMATCH, "the pass-through weights are for %d constraint columns, alfa has %d",
                w.m, m);
  const Eigen::Ref<const Eigen::VectorXd> tau = pt.driver ? Eigen::Ref<const Eigen::VectorXd>(*pt.driver) : ff_torques;
  const bool use_f = w.f_any && f_ext.cols() != 0, use_t = w.t_any && tau.size() != 0;
  if (!use_f && !use_t) return 0;
  auto energy = pt.energy.head(m);
  energy.setZero();
  // Weight of column k of the path's order: the caller's column order(k) on the general path.
  const auto weight = [this](const Eigen::VectorXd& p, int k) { return p(res.general ? ws.general.order(k) : k); };
  if (use_f) {
    driverFree(f_ext, ws.zero_joints.head(0));
    driverEnergy(pt.tmp.head(m));
    for (int k = 0; k < m; ++k) energy(k) += weight(w.f, k) * pt.tmp(k);
  }
  if (use_t) {
    driverFree(ws.zero_f_ext.leftCols(0), tau);
    driverEnergy(pt.tmp.head(m));
    for (int k = 0; k < m; ++k) energy(k) += weight(w.t, k) * pt.tmp(k);
  }
  pt.used = true;
  return 0;
}

// Joint accelerations one driver alone gives (f_ext or joint torques tau, either may be empty),
// each joint with its parent at rest and no constraint, through the last sweep's articulated
// inertias: free_j = (tau_j - S_j^T p_j) / D_j, p the driver's articulated bias force.
void HdCore::driverFree(const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& tau) {
  const bool has_f = f_ext.cols() != 0, has_tau = tau.size() != 0;
  Matrix6X& p_all = ws.general.seg_force;  // each segment's apparent driver force, its tip frame
  p_all.setZero();
  for (int i = static_cast<int>(model.ns) - 1; i >= 0; --i) {
    const SegmentModel& sm = model.seg[i];
    const SegmentState& s = ws.seg[i];
    auto p = p_all.col(i);  // holds what the children passed
    if (has_f) {            // f_ext: base axes, moment about this tip's origin -> tip axes
      p.head<3>().noalias() -= s.R_base.transpose() * f_ext.col(i).head<3>();
      p.tail<3>().noalias() -= s.R_base.transpose() * f_ext.col(i).tail<3>();
    }
    if (sm.joint >= 0) {
      const double free = s.Dinv * ((has_tau ? tau(sm.joint) : 0.0) - sm.S.dot(p));
      ws.pt.free(sm.joint) = free;
      p += s.u * free;
    }
    if (model.parent(i) >= 0) {
      auto fp = p_all.col(model.parent(i));
      addForceToParent(s.X, p, fp);
    }
  }
}

// Acceleration energy along the constraint columns (m, the path's order) of driverFree()'s
// accelerations: sum_j e_j^T free_j, into out.
void HdCore::driverEnergy(Eigen::Ref<Eigen::VectorXd> out) const {
  const int m = res.m;
  out.setZero();
  for (unsigned int i = 0; i < model.ns; ++i) {
    const int joint = model.seg[i].joint;
    if (joint < 0) continue;
    if (res.general) {
      const auto [lo, hi] = feltColumns(static_cast<int>(i));
      out.segment(lo, hi - lo).noalias() += ws.general.eg.col(i).segment(lo, hi - lo) * ws.pt.free(joint);
    } else {
      out.noalias() += ws.seg[i].e.leftCols(m).transpose() * ws.pt.free(joint);
    }
  }
}

}  // namespace detail
}  // namespace vereshchagin
