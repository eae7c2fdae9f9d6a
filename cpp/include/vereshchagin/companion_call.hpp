/// @file
/// The kinematics and dynamics companions (kinematics.hpp, dynamics.hpp) as the Python face calls
/// them (Chain.fk, Tree.inverse_dynamics, ...): arguments are row-major arrays with their shapes
/// (array_arg.hpp), checked one at a time with messages that name them as Python does; then one
/// call writes the result into a buffer of the shape companionShape() reports.
///
///     CompanionCall call{Companion::MassMatrix};
///     call.args[0] = q;                                    // (n_joints,)
///     checkCompanionArg(dd.kinematics(), call, CompanionArg::Q);
///     companionShape(dd.kinematics(), call, ndim, shape);  // (n_joints, n_joints)
///     callCompanion(model, dd, call, out);                 // out: shape[0] * shape[1] doubles
///
/// The dynamics and momentum companions take a floating base's whole state (q: nq, qd and qdd: nv
/// entries), the kinematics companions the joints' (base_kind.hpp).
/// Units, frames and signs: those of kinematics.hpp, dynamics.hpp and momentum.hpp (base axes, physical gravity,
/// f_ext ON each segment BY the environment about its tip origin). Every failure is a Status whose
/// message lives in the KinematicsData (dd.kinematics()); no allocation on success.
#pragma once

#include <utility>
#include <vector>

#include "vereshchagin/array_arg.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/kinematics.hpp"

namespace vereshchagin {

/// The companions, named in messages by their Python names ("inverse_dynamics", ...).
enum class Companion {
  InverseDynamics,       ///< tau (n,) from q, qd, qdd, f_ext, gravity
  MassMatrix,            ///< H (n, n) from q
  GravityTorques,        ///< g(q) (n,) from q, gravity
  CoriolisTorques,       ///< C(q, qd) qd (n,) from q, qd
  Fk,                    ///< the frame's pose (4, 4), or (N, 4, 4) for N rows of q
  FkAll,                 ///< every segment's tip pose (n_segments, 4, 4) from q
  Jacobian,              ///< the frame's Jacobian (6, n), written COLUMN-major, from q
  Twist,                 ///< the frame's twist (6,), or (N, 6) for N rows of q and qd
  JacobianDotTimesQd,    ///< the frame's bias acceleration (6,) from q, qd
  CenterOfMass,          ///< the centre of mass (3,) from q (momentum.hpp)
  CenterOfMassJacobian,  ///< its Jacobian (3, nv), written COLUMN-major, from q
  CenterOfMassVelocity,  ///< its velocity (3,) from q, qd
  CentroidalMomentum,    ///< [linear; angular about the centre of mass] (6,) from q, qd
  Integrate,             ///< q (+) qd (nq,): integrateConfiguration of base_kind.hpp with dt = 1
};

/// The arguments, in the order a companion reads and checks them (those it does not take are not
/// read): q, qd, qdd (n,) or, for fk and twist, (N, n) one state per row; gravity (3,) m/s^2;
/// f_ext (n_segments, 6) [force (N); moment (N m) about the tip origin] rows (data nullptr: none).
enum class CompanionArg { Q, Qd, Qdd, Gravity, FExt };

/// One companion call: the companion, its arguments by CompanionArg, and the frame of fk,
/// jacobian, twist and jacobian_dot_times_qd.
struct CompanionCall {
  Companion kind = Companion::MassMatrix;  ///< the companion
  ArrayArg args[5];                        ///< indexed by CompanionArg
  FrameRef frame;                          ///< the frame the frame companions are asked of
  /// inverse_dynamics' f_ext as wrenches on frames instead of rows, when frame_wrenches_given:
  /// [force (N); moment (N m) about the frame's origin] ON the frame's body BY the environment,
  /// base axes, summed onto the tips at q (addFrameWrench, dynamics.hpp).
  std::vector<std::pair<FrameRef, Vector6>> frame_wrenches;
  bool frame_wrenches_given = false;  ///< use frame_wrenches (even none) as f_ext
};

/// The Python name of a companion ("jacobian_dot_times_qd", ...).
const char* companionName(Companion kind) noexcept;

/// The Python name of an argument ("q", "qd", "qdd", "gravity", "f_ext").
inline const char* companionArgName(CompanionArg arg) noexcept {
  constexpr const char* names[5] = {"q", "qd", "qdd", "gravity", "f_ext"};
  const int k = static_cast<int>(arg);
  return k >= 0 && k < 5 ? names[k] : "unknown argument";
}

/// Checks call.args[arg] (names: q, qd, qdd, gravity, f_ext): its shape ("q must have shape (7,),
/// got (6,)", "f_ext must have shape (7, 6) or be a dict {segment: wrench (6,)}, got (7, 3)") as
/// Error::SizeMismatch, then its values ("q contains NaN or Inf (flat index 0)") as
/// Error::NonfiniteInput. The sizes are kdata's model's.
Status checkCompanionArg(KinematicsData& kdata, const CompanionCall& call, CompanionArg arg);

/// After every argument passed checkCompanionArg: the shape of the result (ndim 1 to 3 entries of
/// shape), or SizeMismatch for a twist whose q and qd differ in shape ("q and qd must have the
/// same shape, got 2 and 3 rows").
Status companionShape(KinematicsData& kdata, const CompanionCall& call, int& ndim, long shape[3]);

/// Writes the result of a checked call to `out` (companionShape's shape, row-major; the Jacobian
/// column-major). Errors: those of the kinematics and dynamics functions, NonfiniteResult with
/// the message "<python name>: the result overflows the double range".
Status callCompanion(const Model& model, DynamicsData& ddata, const CompanionCall& call, double* out);

}  // namespace vereshchagin
