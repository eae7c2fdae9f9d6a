// H(q)^-1 tau from the articulated inertias of the last solve (HdCore::inverseInertia).
//
// The inward sweep of a solve leaves, per segment i, its articulated inertia IA_i (children
// included, constraints not), u_i = IA_i S_i and D_i = S_i^T u_i + rotor_i. With no velocity, no
// gravity and no constraint, the articulated-body recursion maps joint torques tau to joint
// accelerations H^-1 tau:
//   inward:  f_i = sum over children c of X_c^T (f_c + u_c z_c),  z_i = (tau_i - S_i^T f_i) / D_i
//            (a fixed joint passes f_i on unchanged);
//   outward: a_i = X_i a_lambda(i) (a = 0 at the base),  qdd_i = z_i - u_i^T a_i / D_i,
//            a_i += S_i qdd_i.
// Two 6-vector transforms per segment, no inertia is moved: a fraction of a solve.
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

void HdCore::inverseInertia(const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> out) {
  Matrix6X& force = ws.inertia_force;  // bias force felt by each segment from its subtree
  Matrix6X& acc = ws.inertia_acc;      // each segment's acceleration
  Eigen::VectorXd& z = ws.inertia_joint;
  force.setZero();
  for (int i = static_cast<int>(model.ns) - 1; i >= 0; --i) {
    const SegmentModel& sm = model.seg[i];
    const SegmentState& s = ws.seg[i];
    Vector6 pa = force.col(i);
    if (sm.joint >= 0) {
      z(sm.joint) = s.Dinv * (tau(sm.joint) - sm.S.dot(pa));
      pa += s.u * z(sm.joint);
    }
    const int p = model.parent(i);
    if (p >= 0) {
      auto fp = force.col(p);
      addForceToParent(s.X, pa, fp);
    }
  }
  for (unsigned int i = 0; i < model.ns; ++i) {
    const SegmentModel& sm = model.seg[i];
    const SegmentState& s = ws.seg[i];
    const int p = model.parent(i);
    Vector6 a = p >= 0 ? motionToChild(s.X, acc.col(p)) : Vector6::Zero();
    if (sm.joint >= 0) {
      const double qdd = z(sm.joint) - s.Dinv * s.u.dot(a);
      out(sm.joint) = qdd;
      a += sm.S * qdd;
    }
    acc.col(i) = a;
  }
}

}  // namespace detail
}  // namespace vereshchagin
