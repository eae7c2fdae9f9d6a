/// @file
/// Drop-in classes for code written against the secorolab fork of Orocos KDL (used by Kinova Gen3
/// and mobile-manipulator controllers), which adds to KDL 1.5.1's ChainHdSolver_Vereshchagin:
/// fixed joints, setDriverWeights(), a beta that excludes gravity, and f_ext-priority variants.
/// Change
///     KDL::ChainHdSolver_Vereshchagin_Fixed_Joint      (and the others below)
/// to  vereshchagin::kdl_fork::ChainHdSolver_Vereshchagin_Fixed_Joint
/// and the fork's solver includes to <vereshchagin/kdl_fork_compat.hpp>. Same constructor
/// (chain, root_acc, nc), CartToJnt, getters and setDriverWeights(w_f_ext, w_ff_torques) as
/// vereshchagin::kdl_compat::ChainHdSolver_Vereshchagin (kdl_compat.hpp: frames, signs, units, the
/// torque convention switch, errors), with the fork's semantics where they differ from KDL:
///
///  * beta excludes the root acceleration (the fork's convention for all its classes): the caller's
///    beta_c is the acceleration energy alfa_c^T (Xdd_N - root_acc) and the solver adds
///    alfa_c^T root_acc (alfa column c: rows 0-2 force with root_acc's linear part, rows 3-5
///    moment with its angular part, base axes). So beta = 0 holds the tip still along the
///    constrained directions against gravity (KDL 1.5.1 needs beta = alfa^T root_acc for that).
///    The fork adds this term inside its constraint balance; here it is added to beta before the
///    solve: the same equations. getTransformedLinkAcceleration() still returns accelerations
///    including root_acc, as the fork's does.
///  * Fixed joints anywhere in the chain (as the fork's *_Fixed_Joint / *_FixedJoint classes):
///    joint arrays have one entry per moving joint, f_ext one per segment.
///  * setDriverWeights: the fork's meaning (its ChainHdSolver_Vereshchagin documents it): per alfa
///    column, 0 = the constraint compensates that driver (default), 1 = the driver passes through
///    (alfa_c^T Xdd_N = beta_c + what the driver alone would add), in between linear
///    (Shakhimardanov 2015, eq. 3.42). Here on every class of this header.
///  * Truncation of a rank-deficient coupling matrix: relative to its scale (ChainHdSolver's
///    TruncatedPseudoInverse), not the fork's absolute 1e-8 singular-value cut-off; for well-posed
///    tasks the results are the same.
///
/// Classes (fork name -> semantics here):
///  * ChainHdSolver_Vereshchagin: the fork's main class: KDL's algorithm with the fork's beta and
///    driver weights (defaults 0).
///  * ChainHdSolver_Vereshchagin_Fixed_Joint: the same class (the fork's fixed-joint variant of
///    KDL's algorithm; fixed joints are supported by every class here).
///  * ChainHdSolver_Vereshchagin_Fext_FixedJoint, ChainHdSolver_Vereshchagin_Fext: the fork's
///    variants in which the external wrenches f_ext have priority over the acceleration
///    constraints (a commanded press on the environment is not cancelled by the task): the f_ext
///    driver weights start at 1 in every column (ff_torques weights 0), and are restored after
///    updateInternalDataStructures(); setDriverWeights() changes them as on the others. The fork's
///    own implementation of these two classes changed between its versions (one dropped the
///    constraint term from q_dotdot, velocity-product wrenches and ff_torques; a later one returns
///    J^T f_ext as constraint_torques): what is kept here is the documented intent (f_ext passes
///    through the constraints), with the same torque outputs as the other classes
///    (TorqueConvention, getCommandTorques()).
#pragma once

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>

#include "vereshchagin/kdl_compat.hpp"

namespace vereshchagin {
namespace kdl_fork {

using kdl_compat::TorqueConvention;

/// The fork's main class: kdl_compat's class with the fork's gravity-free beta (see the top of this file).
class ChainHdSolver_Vereshchagin : public kdl_compat::ChainHdSolver_Vereshchagin {
 public:
  /// chain (copied; an lvalue chain is watched as in kdl_compat), root_acc (base acceleration,
  /// gravity as +9.81 up, as KDL), nc (alfa columns per call, 0..6).
  using kdl_compat::ChainHdSolver_Vereshchagin::ChainHdSolver_Vereshchagin;

 protected:
  /// beta + alfa^T root_acc (the fork's gravity-free beta).
  void effectiveBeta(const KDL::Jacobian& alfa, const KDL::JntArray& beta, Eigen::VectorXd& out) const override;
};

/// The fork's fixed-joint variant: the same semantics (fixed joints are supported by all classes).
using ChainHdSolver_Vereshchagin_Fixed_Joint = ChainHdSolver_Vereshchagin;

/// The fork's f_ext-priority variant: f_ext driver weights 1 in every column by default.
class ChainHdSolver_Vereshchagin_Fext_FixedJoint : public ChainHdSolver_Vereshchagin {
 public:
  /// chain, root_acc, nc: as ChainHdSolver_Vereshchagin.
  ChainHdSolver_Vereshchagin_Fext_FixedJoint(const KDL::Chain& chain, const KDL::Twist& root_acc,
                                             const unsigned int nc);
  /// The same from a temporary chain.
  ChainHdSolver_Vereshchagin_Fext_FixedJoint(KDL::Chain&& chain, const KDL::Twist& root_acc, const unsigned int nc);
  /// Rebuilds (see kdl_compat) and restores the f_ext-priority weights (f_ext 1, ff_torques 0).
  void updateInternalDataStructures() override;

 private:
  void prioritizeExternalWrenches();
  unsigned int nc_;
};

/// The fork's earlier f_ext-priority variant (before fixed joints): the same class here.
using ChainHdSolver_Vereshchagin_Fext = ChainHdSolver_Vereshchagin_Fext_FixedJoint;

}  // namespace kdl_fork
}  // namespace vereshchagin
