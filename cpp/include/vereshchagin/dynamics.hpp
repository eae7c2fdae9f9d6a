/// @file
/// Rigid-body dynamics companions of the hybrid solver on a Model (model.hpp), for chains and trees
/// alike: inverse dynamics (recursive Newton-Euler), the joint-space mass matrix (composite rigid
/// bodies), gravity torques and Coriolis/centrifugal torques.
///
///     Model model(chain);
///     DynamicsData dd(model);                       // once: allocates everything
///     Eigen::VectorXd tau(model.nrOfJoints());
///     gravityTorques(model, dd, JointPositions(q), KDL::Vector(0, 0, -9.81), tau);  // no allocation
///
/// The equation of motion these functions split up is
///     H(q) q_ddot + C(q, q_dot) q_dot + g(q) = tau + sum_i J_i(q)^T f_ext_i,
/// with, for every argument and result:
///  * q, q_dot, q_ddot, tau: n_joints entries in the model's joint order (rad, rad/s, rad/s^2, N m;
///    m, m/s, m/s^2, N for prismatic joints); tau is what the joint motors apply;
///  * H (n_joints x n_joints, kg m^2 or kg): symmetric, rotor inertias KDL::Joint::getInertia() on
///    the diagonal; entries of two joints on different branches (neither on the other's path to
///    the base) are zero;
///  * gravity: PHYSICAL gravity in base-frame axes, m/s^2 (Earth with z up: (0, 0, -9.81)),
///    the convention of SolveInput::gravity; g(q) is the torque that holds the robot still
///    against it (the base is treated as accelerating by -gravity);
///  * f_ext: 6 x n_segments (or 6 x 0 for none), column i the wrench [force (N); moment (N m)] ON
///    segment i BY the environment, base-frame axes, the moment about segment i's TIP ORIGIN (as
///    SolveInput::f_ext); J_i is the Jacobian of segment i's tip origin (kinematics.hpp).
///
/// On a floating base (Model::baseKind() FreeFlyer or Planar, base_kind.hpp) the same functions
/// take and give the whole state: q has nq entries, q_dot, q_ddot and tau nv (H is nv x nv), the
/// base's first in Pinocchio's layout: the base's velocity and acceleration in BASE axes (LOCAL),
/// and on tau's base rows the wrench on the base body [force (N); moment about the base origin
/// (N m)] in base axes (planar: f_x, f_y, n_z), as pin.rnea / pin.crba with a JointModelFreeFlyer
/// or JointModelPlanar. There gravity and f_ext are in WORLD axes (as SolveInput's on a floating
/// base; f_ext's moments still about each tip origin); the base body's inertia is
/// ModelOptions::base_inertia (with a URDF's root link). The base's unit quaternion (or
/// (cos, sin) pair) is checked as the solver checks it (NonfiniteInput beyond 1e-6 off unit).
///
/// After a call, dd.kinematics() holds the forward kinematics at q (and at q_dot for
/// inverseDynamics and coriolisTorques): framePose() etc. of kinematics.hpp can be asked of it.
/// Errors: NotUpToDate (dd built for another model), SizeMismatch (a vector, f_ext or the output
/// of the wrong size), NonfiniteInput (NaN or Inf in an input), NonfiniteResult (finite inputs whose
/// result overflows, |q_dot| ~ 1e160: message "the result overflows the double range", the output
/// then holds the overflowing values); the message lives in dd. Any Model
/// works, also one whose status() reports an inertia problem (the numbers are used as given).
#pragma once

#include <memory>

#include <Eigen/Core>
#include <kdl/frames.hpp>

#include "vereshchagin/input.hpp"
#include "vereshchagin/kinematics.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/spatial.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// q_ddot: rad/s^2 or m/s^2, n_joints (input.hpp's typed joint vectors).
using JointAccelerations = JointVector<struct JointAccelerationsTag>;

namespace detail {
struct DynamicsImpl;
}  // namespace detail

/// Workspace of the dynamics functions below on one Model, one per thread.
class DynamicsData {
 public:
  /// Sized for `model` (allocates); every call below is allocation-free.
  explicit DynamicsData(const Model& model);
  ~DynamicsData();
  DynamicsData(DynamicsData&&) noexcept;             ///< moves the workspace
  DynamicsData& operator=(DynamicsData&&) noexcept;  ///< moves the workspace
  DynamicsData(const DynamicsData&) = delete;
  DynamicsData& operator=(const DynamicsData&) = delete;

  const Model& model() const noexcept;  ///< the model it was built for
  /// The kinematics of the last call's state (kinematics.hpp).
  KinematicsData& kinematics() noexcept;
  const KinematicsData& kinematics() const noexcept;  ///< see kinematics()

  detail::DynamicsImpl& impl() noexcept { return *impl_; }  ///< the implementation (internal)

 private:
  std::unique_ptr<detail::DynamicsImpl> impl_;
};

/// tau = H q_ddot + C q_dot + g - sum_i J_i^T f_ext_i (recursive Newton-Euler). f_ext: 6 x n_segments
/// or 6 x 0; tau: n_joints, nv on a floating base (written).
Status inverseDynamics(const Model& model, DynamicsData& ddata, const JointPositions& q, const JointVelocities& q_dot,
                       const JointAccelerations& q_ddot, const Eigen::Ref<const Matrix6X>& f_ext,
                       const KDL::Vector& gravity, Eigen::Ref<Eigen::VectorXd> tau);

/// H(q), n_joints x n_joints, nv x nv on a floating base (written in full, both triangles).
Status massMatrix(const Model& model, DynamicsData& ddata, const JointPositions& q, Eigen::Ref<Eigen::MatrixXd> H);

/// g(q) for physical gravity `gravity` (base axes, m/s^2; world axes on a floating base): tau = g(q)
/// holds the robot still (on a floating base with the base rows: the wrench that holds its weight).
Status gravityTorques(const Model& model, DynamicsData& ddata, const JointPositions& q, const KDL::Vector& gravity,
                      Eigen::Ref<Eigen::VectorXd> tau);

/// C(q, q_dot) q_dot: the Coriolis and centrifugal torques (no gravity, q_ddot = 0).
Status coriolisTorques(const Model& model, DynamicsData& ddata, const JointPositions& q, const JointVelocities& q_dot,
                       Eigen::Ref<Eigen::VectorXd> tau);

/// Adds a wrench on a frame moving with a segment (a FrameRef of Model::findFrame: a segment's
/// tip or a merged link) to f_ext in the layout of the functions above: `wrench` = [force f (N);
/// moment n (N m) about the frame's origin], ON the body BY the environment, base axes. Column
/// frame.segment of f_ext (6 x n_segments) gains [f; n + (R_tip p) x f], the moment moved to the
/// tip origin, with p = frame.in_tip.p (m, tip axes; its orientation does not matter) and R_tip the
/// tip's orientation in the base at the last forwardKinematics' q of kdata (e.g. dd.kinematics()
/// after any call above at the same q). No allocation; f_ext is unchanged on failure. Errors:
/// NotUpToDate, NoSolution (no forwardKinematics yet), OutOfRange (frame.segment not in
/// [0, n_segments): the base takes no wrench), SizeMismatch (f_ext not 6 x n_segments),
/// NonfiniteInput (NaN or Inf in wrench or p).
Status addFrameWrench(const Model& model, KinematicsData& kdata, const FrameRef& frame, const Vector6& wrench,
                      Eigen::Ref<Matrix6X> f_ext);

}  // namespace vereshchagin
