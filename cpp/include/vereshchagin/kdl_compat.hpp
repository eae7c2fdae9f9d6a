/// @file
/// Drop-in replacement for Orocos KDL 1.5.1's KDL::ChainHdSolver_Vereshchagin: change
///     `#include <kdl/chainhdsolver_vereshchagin.hpp>`   KDL::ChainHdSolver_Vereshchagin
/// to  `#include <vereshchagin/kdl_compat.hpp>`          vereshchagin::kdl_compat::ChainHdSolver_Vereshchagin
/// and nothing else. Same constructor, CartToJnt and getters, same frames, signs and units (see
/// chain_hd_solver.hpp: alfa columns are unit constraint wrenches in base axes about the last tip's
/// origin, beta = alfa^T Xdd_N including root_acc, root_acc is the base acceleration with gravity
/// as +9.81 up, f_ext[i] in base axes about segment i's tip origin).
///
/// Accepted as in KDL wherever the solve is well defined:
///  * identified robot models: inertias are checked with InertiaCheck::JointSpace (every
///    articulated joint inertia D_j > 0 at each solve, i.e. the joint-space inertia is positive
///    definite there; a clear error naming the joint, never NaN, where KDL returns NaN);
///  * zero columns of alfa disable those constraints (their nu entries are 0), as in KDL;
///  * fixed joints anywhere, and a massless distal body with rotor inertia.
///
/// Outputs: by default every output is KDL 1.5.1's (TorqueConvention::Kdl), so code written for KDL
/// keeps its numbers; the torques that realise the motion are one switch away:
///  * constraint_torques (the output of CartToJnt): KDL's entry j is -Z_j^T E_j nu, the torque that
///    joint j feels from the constraint wrench -alfa nu through the articulated body distal to it
///    (joints beyond j free, Z_j its unit twist, E_j the constraint's unit wrenches there).
///    Added to ff_torques and applied to the arm, these do NOT reproduce q_dotdot (only the last
///    joint's entry is also a command).
///  * getTotalTorque(): KDL's is D_j * q_dotdot_j, the articulated inertia of joint j (rotor
///    included) times its acceleration: the net generalised force of the articulated-body
///    recursion, not a torque any motor applies.
///  * setTorqueConvention(TorqueConvention::Command): constraint_torques become the command torques
///    -J^T alfa nu (J: base-frame Jacobian of the last segment's tip): ff_torques + these, applied
///    to the unconstrained arm (forward dynamics, same f_ext and gravity), reproduce q_dotdot; and
///    getTotalTorque() = ff_torques + constraint_torques, the joint torques the motors apply.
///    getCommandTorques() returns the command torques in either convention. docs/migration.md
///    describes the two steps (swap and compare, then switch).
///
/// Documented differences, only where KDL 1.5.1 is wrong or undefined:
///  * The chain is copied (KDL keeps a reference, which dangles for a temporary chain). Like KDL,
///    CartToJnt returns E_NOT_UP_TO_DATE while the caller's chain (the lvalue given to the
///    constructor) has another number of segments than at construction or at the last
///    updateInternalDataStructures(), which re-reads it. A temporary (rvalue) chain is only copied
///    and never watched. A change that keeps the number of segments is not seen (KDL reads the
///    chain at every call): call updateInternalDataStructures() after any change.
///  * Errors are reported, not asserted or computed as NaN: sizes (E_SIZE_MISMATCH, as KDL), and
///    ChainHdSolver's codes (E_NONFINITE_INPUT, E_INVALID_MODEL, E_DEGENERATE_INERTIA, ...); the
///    message is in errorMessage(). CartToJnt allocates no heap memory (KDL's does, when nc > 0).
///  * A chain with no mass and no rotor inertia at all, driven by no ff_torques and no f_ext (KDL's
///    own test chains): its dynamics leave every acceleration free; KDL returns 0 with NaN outputs.
///    Here CartToJnt returns E_DEGRADED (+1, KDL's "converged but degraded solution") with the
///    smallest q_dotdot that meets the constraints (least squares where they conflict), zero
///    constraint torques, nu and total torque (no torque is needed), and errorMessage() says so.
///    With ff_torques or f_ext on such a chain the acceleration is unbounded: E_DEGENERATE_INERTIA.
///  * A rank-deficient constraint set is pseudo-inverted relative to the coupling matrix's scale
///    (ChainHdSolver's TruncatedPseudoInverse), not with KDL's absolute 1e-14 SVD cut-off.
///
/// Getters of KDL's internal recursion quantities, absent here: getLinkUnitForceAccelerationEnergy,
/// getLinkBiasForceAcceleratoinEnergy, getLinkUnitForceMatrix, getLinkBiasForceMatrix and
/// getJointBiasAcceleration. KDL 1.5.1's header has them only inside a comment (with the six link
/// getters below), so no KDL code calls them. This implementation keeps no per-segment copy of
/// those quantities (its sweeps hold them in fixed-size per-segment blocks in another row order and
/// frame), so there is nothing equivalent to return. The public ChainHdSolver (solver()) gives the
/// useful equivalents: constraintRank(), smallestSingularValue(), responseColumns().
///
/// Beyond KDL (ours, not declared by KDL 1.5.1's header, where they are commented out):
/// getLinkCartesianPose, getLinkCartesianVelocity, getLinkCartesianAcceleration, getLinkPose,
/// getLinkVelocity, getLinkAcceleration. Also ours: setTorqueConvention() and getCommandTorques(),
/// setDriverWeights() (driver pass-through, see below), solver() for the full
/// vereshchagin::ChainHdSolver API, and errorMessage().
///
/// The deprecated name KDL::ChainIdSolver_Vereshchagin (KDL's chainidsolver_vereshchagin.hpp) is
/// vereshchagin::kdl_compat::ChainIdSolver_Vereshchagin below (also reachable through
/// vereshchagin/kdl_compat_idsolver.hpp). Classes of a KDL fork (fixed joints, driver weights,
/// gravity-free beta) are in vereshchagin/kdl_fork_compat.hpp.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/chainidsolver.hpp>  // KDL::Wrenches
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/solveri.hpp>

#include "vereshchagin/chain_hd_solver.hpp"

namespace vereshchagin {
namespace kdl_compat {

/// Which torques constraint_torques and getTotalTorque() return (see the top of this file).
enum class TorqueConvention {
  Kdl,      ///< default: KDL 1.5.1's values (felt torques -Z_j^T E_j nu; total D_j q_dotdot_j)
  Command,  ///< the command torques -J^T alfa nu; total = ff_torques + constraint_torques
};

/// Drop-in for KDL 1.5.1's KDL::ChainHdSolver_Vereshchagin (see the top of this file).
class ChainHdSolver_Vereshchagin : public KDL::SolverI {
  typedef std::vector<KDL::Twist> Twists;
  typedef std::vector<KDL::Frame> Frames;

 public:
  /// chain: copied. An lvalue chain is also watched for a changed number of segments (CartToJnt
  /// then returns E_NOT_UP_TO_DATE until updateInternalDataStructures(), as KDL), so it must
  /// outlive the solver, as in KDL; a temporary chain is only copied. root_acc: the base's
  /// acceleration, base frame (gravity g = (0, 0, -9.81) is root_acc = (0, 0, +9.81, 0, 0, 0)).
  /// nc: the number of alfa columns every CartToJnt call passes (0..6).
  ChainHdSolver_Vereshchagin(const KDL::Chain& chain, const KDL::Twist& root_acc, const unsigned int nc);
  /// The same from a temporary chain: copied, never watched.
  ChainHdSolver_Vereshchagin(KDL::Chain&& chain, const KDL::Twist& root_acc, const unsigned int nc);

  /// q, q_dot (n_joints): joint positions and velocities; q_dotdot (n_joints, output): joint
  /// accelerations. alfa (6 x nc): unit constraint wrenches, rows 0-2 force, 3-5 moment, base axes,
  /// moment about the last segment's tip origin; all-zero columns are disabled constraints. beta
  /// (nc): acceleration energies alfa^T Xdd_N (including root_acc). f_ext (n_segments): wrench on
  /// each segment, base axes, moment about its tip origin. ff_torques (n_joints): joint torques.
  /// constraint_torques (n_joints, output): KDL's felt torques, or the command torques with
  /// TorqueConvention::Command (see above). Returns 0, E_NOT_UP_TO_DATE (the watched chain changed
  /// its number of segments), E_SIZE_MISMATCH, or a ChainHdSolver error code (negative).
  int CartToJnt(const KDL::JntArray& q, const KDL::JntArray& q_dot, KDL::JntArray& q_dotdot, const KDL::Jacobian& alfa,
                const KDL::JntArray& beta, const KDL::Wrenches& f_ext, const KDL::JntArray& ff_torques,
                KDL::JntArray& constraint_torques);

  /// Re-reads the watched chain (after the caller changed it) and rebuilds; for a solver made
  /// from a temporary chain, rebuilds from its own copy. Keeps the torque convention.
  void updateInternalDataStructures() override;

  /// Torque convention of constraint_torques and getTotalTorque() (default TorqueConvention::Kdl);
  /// kept until changed, applies from the next CartToJnt.
  void setTorqueConvention(TorqueConvention convention) { convention_ = convention; }
  TorqueConvention torqueConvention() const { return convention_; }  ///< the current torque convention

  /// After a successful CartToJnt. Frames: "base" = base axes (and base origin for poses); link
  /// quantities refer to each segment's tip frame, moments and velocities about its tip origin.
  /// Outputs are resized as needed (no allocation when already the right size).
  /// x_dotdot (n_segments + 1): [0] = root_acc, [i] = segment i-1's tip acceleration, base axes.
  void getTransformedLinkAcceleration(Twists& x_dotdot);
  /// total_tau (n_joints): D_j q_dotdot_j (Kdl) or ff_torques + constraint_torques (Command).
  void getTotalTorque(KDL::JntArray& total_tau);
  /// tau (n_joints): the command torques -J^T alfa nu, whatever the convention (ours).
  void getCommandTorques(KDL::JntArray& tau);
  /// nu (nc): constraint force magnitudes in alfa's column order (0 for disabled columns); the
  /// wrench on the last segment is -alfa nu. (KDL's spelling.)
  void getContraintForceMagnitude(Eigen::VectorXd& nu_);
  /// Ours (commented out in KDL 1.5.1's header). n_segments entries each: [i] = segment i's tip
  /// frame in the base frame / its velocity and acceleration in base axes.
  void getLinkCartesianPose(Frames& x_base);
  void getLinkCartesianVelocity(Twists& xDot_base);         ///< see getLinkCartesianPose()
  void getLinkCartesianAcceleration(Twists& xDotDot_base);  ///< see getLinkCartesianPose()
  /// Ours (commented out in KDL 1.5.1's header). n_segments entries each: [i] = segment i's tip
  /// frame in its parent's tip frame / its velocity and acceleration in its own tip axes.
  void getLinkPose(Frames& x_local);
  void getLinkVelocity(Twists& xDot_local);         ///< see getLinkPose()
  void getLinkAcceleration(Twists& xDotdot_local);  ///< see getLinkPose()

  /// Driver pass-through (ChainHdSolver::setPassThrough; Shakhimardanov 2015, eq. 3.42), per alfa
  /// column (nc entries each, in [0, 1]): 0 (default) = the constraint compensates that driver
  /// (f_ext or ff_torques) along that column, as KDL; 1 = the driver's own acceleration along that
  /// column passes through (alfa_c^T Xdd_N = beta_c + the driver's share). Kept until changed.
  /// Returns E_SIZE_MISMATCH if a vector does not have nc entries, E_OUT_OF_RANGE for entries
  /// outside [0, 1]. (A KDL fork has a method of this name whose weights meant the opposite in
  /// one of its versions: here a weight is always the share that passes through.)
  int setDriverWeights(const Eigen::VectorXd& w_f_ext, const Eigen::VectorXd& w_ff_torques);

  const char* errorMessage() const;                        ///< detail of the last error
  const char* strError(const int error) const override;    ///< text of an error code
  const ChainHdSolver& solver() const { return solver_; }  ///< the vereshchagin::ChainHdSolver underneath

 protected:
  /// The beta actually solved for: the caller's (KDL), or a derived class's shifted one.
  virtual void effectiveBeta(const KDL::Jacobian& alfa, const KDL::JntArray& beta, Eigen::VectorXd& out) const;
  const KDL::Twist& rootAcceleration() const { return root_acc_; }  ///< root_acc given to the constructor

 private:
  void allocate();
  // Base-frame pose of every segment's tip at the last solve, into poses_ (on request).
  void updateBasePoses();
  // KDL's felt constraint torques and articulated inertias D_j at the last solve (one inward sweep).
  void feltTorques(const KDL::JntArray& q, const Eigen::VectorXd& nu_all, const KDL::Jacobian& alfa);
  // The E_DEGRADED answer of a chain with no mass at all (kdl_compat.cpp); false if it does not apply.
  bool masslessAnswer(const KDL::JntArray& q, const KDL::JntArray& q_dot, const KDL::JntArray& ff_torques,
                      KDL::JntArray& q_dotdot, KDL::JntArray& constraint_torques);
  // setDriverWeights()'s weights of the enabled columns on `solver` (solver_ or unit_).
  void applyDriverWeights(ChainHdSolver& solver);
  // The solver holding the last solve's results.
  const ChainHdSolver& answered() const { return degraded_ ? *unit_ : solver_; }

  const KDL::Chain* source_;  // the caller's chain (lvalue constructor), or nullptr
  KDL::Twist root_acc_;
  unsigned int nc_;
  ChainHdSolver solver_;
  unsigned int nj_ = 0, ns_ = 0;
  TorqueConvention convention_ = TorqueConvention::Kdl;
  int active_ = 0;                           // enabled (non-zero) alfa columns at the last solve
  ChainHdSolver::Matrix6X alfa_on_, f_ext_;  // the enabled columns; f_ext as a 6 x n_segments matrix
  Eigen::VectorXd beta_all_, beta_on_, nu_, total_, felt_, d_;
  Eigen::VectorXi column_;                       // alfa column of each enabled one
  Eigen::VectorXd w_f_, w_t_, w_f_on_, w_t_on_;  // pass-through weights (nc), of the enabled columns
  bool weighted_ = false;
  bool not_up_to_date_ = false;          // the last CartToJnt returned E_NOT_UP_TO_DATE
  bool degraded_ = false;                // the last CartToJnt returned E_DEGRADED (a massless chain)
  std::unique_ptr<ChainHdSolver> unit_;  // massless chains only: the chain with unit rotor inertias
  Frames poses_;
};

/// KDL 1.5.1's deprecated name of the same class (KDL's chainidsolver_vereshchagin.hpp; KDL also
/// prints a notice on construction, this one warns at compile time only).
class [[deprecated("renamed ChainHdSolver_Vereshchagin (as in KDL 1.5)")]] ChainIdSolver_Vereshchagin
    : public ChainHdSolver_Vereshchagin {
 public:
  using ChainHdSolver_Vereshchagin::ChainHdSolver_Vereshchagin;
};

}  // namespace kdl_compat
}  // namespace vereshchagin
