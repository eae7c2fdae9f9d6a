// The per-segment articulated-body step of HdCore's inward sweeps and its final outward sweep,
// shared by the fast path (hd_core.cpp) and the several-segment path (segment_constraints.cpp).
#pragma once

#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

// u = IA S, D = rotor + S^T u; free = (tau - S^T (pA + IA c)) / D is the joint acceleration with
// the parent at rest and no constraint; pa = pA + IA c + u free is the apparent bias force. On a
// coordinate axis u is a column of IA times S's entry (the same values as the product).
inline bool HdCore::articulate(int i, double tau, Vector6& pa, double& free) {
  const SegmentModel& sm = model.seg[i];
  SegmentState& s = ws.seg[i];
  if (sm.axis >= 0) {
    s.u = s.IA.col(sm.axis) * sm.S(sm.axis);
  } else {
    s.u.noalias() = s.IA * sm.S;
  }
  s.D = sm.rotor + sm.dotS(s.u);
  if (!(s.D > sm.d_tolerance)) return false;
  s.Dinv = 1.0 / s.D;
  const Vector6 IAc = s.IA * s.c;
  free = s.Dinv * (tau - sm.dotS(s.pA + IAc));
  pa = s.pA + IAc + s.u * free;
  return true;
}

// Apparent inertia IA - u u^T / D (IA for a fixed joint) and bias force pa moved to the parent.
// IA is downdated in place: nothing reads a segment's articulated inertia after this step (u and
// D keep what the later passes need), and a copy of it cost more than the downdate.
inline void HdCore::passToParent(int i, const Vector6& pa) {
  SegmentState& s = ws.seg[i];
  SegmentState& p = ws.seg[model.parent(i)];
  if (model.seg[i].joint >= 0) s.IA.noalias() -= s.Dinv * s.u * s.u.transpose();
  addInertiaToParent(s.X, s.IA, p.IA);
  addForceToParent(s.X, pa, p.pA);
}

inline void HdCore::passToBase(int i, const Vector6& pa) {
  SegmentState& s = ws.seg[i];
  if (model.seg[i].joint >= 0) s.IA.noalias() -= s.Dinv * s.u * s.u.transpose();
  addInertiaToParent(s.X, s.IA, ws.base.IA);
  addForceToParent(s.X, pa, ws.base.pA);
}

// Segment i's acceleration before its own joint's: the parent's (root_acc at the base) in i's
// tip frame plus the velocity-product term c_i.
inline Vector6 HdCore::incomingAcceleration(int i) const {
  const int p = model.parent(i);
  Vector6 a = motionToChild(ws.seg[i].X, p >= 0 ? ws.seg[p].xdd : model.floating ? ws.base.xdd : root_acc);
  a += ws.seg[i].c;
  return a;
}

// Final outward sweep: joint and link accelerations given the constraint magnitudes.
// constraint_force(i) is segment i's joint-axis share of the constraint forces, S^T A nu (the
// only part in which the two paths differ).
template <typename ConstraintForce>
inline void HdCore::finalSweep(const Eigen::Ref<const Eigen::VectorXd>& ff_torques,
                               const ConstraintForce& constraint_force) {
  const bool has_tau = ff_torques.size() != 0;
  double* const qdd_joints = res.qdd.data() + model.nbv;  // the joints' entries (after a floating base's)
  res.link_acc_known = false;
  for (unsigned int i = 0; i < model.ns; ++i) {
    const SegmentModel& sm = model.seg[i];
    SegmentState& s = ws.seg[i];
    Vector6 a = incomingAcceleration(i);
    if (sm.joint >= 0) {
      const double tau = has_tau ? ff_torques(sm.joint) : 0.0;
      const double f = sm.dotS(s.pA) + s.u.dot(a) + constraint_force(i);  // S^T IA a = u^T a
      const double qdd = s.Dinv * (tau - f);
      qdd_joints[sm.joint] = qdd;
      if (sm.axis >= 0) {
        a(sm.axis) += sm.S(sm.axis) * qdd;
      } else {
        a += sm.S * qdd;
      }
    }
    s.xdd = a;
  }
}

}  // namespace detail
}  // namespace vereshchagin
