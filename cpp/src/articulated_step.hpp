// The per-segment articulated-body step of ChainHdSolver's inward sweep and its final outward
// sweep, shared by the end-segment path (chain_hd_solver.cpp) and the several-segment path
// (segment_constraints.cpp).
#pragma once

#include "vereshchagin/chain_hd_solver.hpp"

namespace vereshchagin {

// u = IA S, D = rotor + S^T u; free = (tau - S^T (pA + IA c)) / D is the joint acceleration with
// the parent at rest and no constraint; pa = pA + IA c + u free is the apparent bias force.
inline bool ChainHdSolver::articulate(Segment& s, double tau, Vector6& pa, double& free) const {
  s.u.noalias() = s.IA * s.S;
  s.D = s.rotor + s.S.dot(s.u);
  if (!(s.D > d_tolerance_)) return false;
  s.Dinv = 1.0 / s.D;
  const Vector6 IAc = s.IA * s.c;
  free = s.Dinv * (tau - s.S.dot(s.pA + IAc));
  pa = s.pA + IAc + s.u * free;
  return true;
}

// Apparent inertia IA - u u^T / D (IA for a fixed joint) and bias force pa moved to the parent.
inline void ChainHdSolver::passToParent(int i, const Vector6& pa) {
  Segment& s = segs_[i];
  Segment& p = segs_[i - 1];
  if (s.joint >= 0) {
    Matrix6 Ia = s.IA;
    Ia.noalias() -= s.Dinv * s.u * s.u.transpose();
    addInertiaToParent(s.X, Ia, p.IA);
  } else {
    addInertiaToParent(s.X, s.IA, p.IA);
  }
  p.pA += forceToParent(s.X, pa);
}

// Final outward sweep: joint and link accelerations given the constraint magnitudes.
// constraint_force(i, s) is segment i's joint-axis share of the constraint forces, S^T A nu (the
// only part in which the two paths differ).
template <typename ConstraintForce>
inline void ChainHdSolver::finalSweep(const Eigen::Ref<const Eigen::VectorXd>& ff_torques,
                                      const ConstraintForce& constraint_force) {
  const bool has_tau = ff_torques.size() != 0;
  Vector6 xdd_parent = root_acc_;
  link_acc_known_ = false;
  for (unsigned int i = 0; i < ns_; ++i) {
    Segment& s = segs_[i];
    Vector6 a = motionToChild(s.X, xdd_parent);
    a += s.c;
    if (s.joint >= 0) {
      const double tau = has_tau ? ff_torques(s.joint) : 0.0;
      const double f = s.S.dot(s.pA) + s.u.dot(a) + constraint_force(i, s);  // S^T IA a = u^T a
      const double qdd = s.Dinv * (tau - f);
      qdd_(s.joint) = qdd;
      a += s.S * qdd;
    }
    s.xdd = a;
    xdd_parent = a;
  }
}

}  // namespace vereshchagin
