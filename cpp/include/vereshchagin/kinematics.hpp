/// @file
/// Forward kinematics on a Model (model.hpp): every segment's tip pose in the base frame and its
/// twist, then the pose, twist, Jacobian and bias acceleration (Jdot q_dot) of any frame moving
/// with a segment (a FrameRef of Model::findFrame: a segment's tip, a merged link, the base).
///
///     Model model(chain);
///     KinematicsData kd(model);                    // once: allocates everything
///     forwardKinematics(model, kd, JointPositions(q), JointVelocities(qd));  // no allocation
///     KDL::Frame pose;  Vector6 twist;
///     framePose(model, kd, frame, pose);  frameTwist(model, kd, frame, twist);
///
/// Conventions (as hd_solver.hpp's):
///  * base frame: the frame of the model's base (the chain's root, the tree's root segment);
///    every result below has base-frame axes;
///  * a twist is [linear; angular]: the velocity of the frame's ORIGIN (m/s) and the angular
///    velocity (rad/s); a Jacobian column is the twist per unit joint rate (rad/s or m/s) of that
///    joint, reference point the frame's origin (KDL's ChainJntToJacSolver after changeRefPoint to
///    the frame's origin, Pinocchio's LOCAL_WORLD_ALIGNED);
///  * the bias acceleration is [classical acceleration of the frame's origin (m/s^2, the second
///    time derivative of its position); angular acceleration (rad/s^2)] at q_ddot = 0 without
///    gravity: d/dt(J) q_dot, so that the classical acceleration at q_ddot is J q_ddot + bias;
///  * q, q_dot: n_joints entries in the model's joint order (Model::segmentOfJoint()).
///
/// KDL::Joint scale and offset are honoured as KDL::Segment::pose() does. Any Model works,
/// including one whose status() reports an inertia problem (kinematics reads no inertia); an empty
/// Model has no segments and only the base frame.
///
/// Failure: every call returns a Status (status.hpp) whose message lives in the KinematicsData (valid
/// until its next call); nothing is allocated on success or failure.
#pragma once

#include <array>
#include <memory>
#include <string>

#include <Eigen/Core>
#include <kdl/frames.hpp>

#include "vereshchagin/array_arg.hpp"
#include "vereshchagin/input.hpp"  // JointPositions, JointVelocities
#include "vereshchagin/model.hpp"
#include "vereshchagin/spatial.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

namespace detail {
struct KinematicsImpl;
}  // namespace detail

/// Workspace and results of the kinematics functions below on one Model, one per thread.
class KinematicsData {
 public:
  /// Sized for `model` (allocates); every call below is allocation-free.
  explicit KinematicsData(const Model& model);
  ~KinematicsData();
  KinematicsData(KinematicsData&&) noexcept;             ///< moves the workspace and results
  KinematicsData& operator=(KinematicsData&&) noexcept;  ///< moves the workspace and results
  KinematicsData(const KinematicsData&) = delete;
  KinematicsData& operator=(const KinematicsData&) = delete;

  /// The model it was built for (a call with another model: Error::NotUpToDate).
  const Model& model() const noexcept;
  /// After forwardKinematics: the tip pose of segment i in the base frame (m), 0 <= i < n_segments.
  const Pose& tipPose(int i) const;
  /// After forwardKinematics with q_dot: segment i's spatial velocity, base axes, reference point
  /// the BASE ORIGIN: [velocity of the body point at the base origin; angular velocity].
  const Vector6& spatialVelocity(int i) const;
  /// After forwardKinematics: segment i's joint axis as a unit twist, base axes, reference point
  /// the base origin (zero for a fixed joint); its joint's velocity adds axis * q_dot.
  const Vector6& jointAxis(int i) const;
  /// True once forwardKinematics has run (with q_dot: velocities too).
  bool hasPositions() const noexcept;
  bool hasVelocities() const noexcept;  ///< see hasPositions()

  detail::KinematicsImpl& impl() noexcept { return *impl_; }              ///< the implementation (internal)
  const detail::KinematicsImpl& impl() const noexcept { return *impl_; }  ///< the implementation (internal)

 private:
  std::unique_ptr<detail::KinematicsImpl> impl_;
};

/// Tip poses of every segment at q (and twists with q_dot). Errors: NotUpToDate (kdata built for
/// another model), SizeMismatch (q or q_dot not n_joints long), NonfiniteInput (NaN or Inf in them).
Status forwardKinematics(const Model& model, KinematicsData& kdata, const JointPositions& q);
/// The same with the velocities q_dot: twists too.
Status forwardKinematics(const Model& model, KinematicsData& kdata, const JointPositions& q,
                         const JointVelocities& q_dot);

/// Pose of `frame` in the base frame (identity for the base) at the last forwardKinematics' q.
/// Errors: NotUpToDate, NoSolution (no forwardKinematics yet), OutOfRange (frame.segment not in
/// [-1, n_segments)).
Status framePose(const Model& model, KinematicsData& kdata, const FrameRef& frame, KDL::Frame& pose);

/// Twist [v of the frame's origin (m/s); omega (rad/s)], base axes (zero for the base), at the last
/// forwardKinematics' q and q_dot. Errors as framePose; NoSolution also without q_dot;
/// NonfiniteResult (message "the result overflows the double range") when finite inputs give a
/// twist with Inf or NaN (|q_dot| ~ 1e308).
Status frameTwist(const Model& model, KinematicsData& kdata, const FrameRef& frame, Vector6& twist);

/// Jacobian (6 x n_joints, columns in joint order, rows [linear; angular], base axes, reference
/// point the frame's origin): twist = J q_dot. Columns of joints off the frame's path to the base
/// are zero. Errors as framePose, and SizeMismatch for a jacobian not 6 x n_joints.
Status frameJacobian(const Model& model, KinematicsData& kdata, const FrameRef& frame,
                     Eigen::Ref<Eigen::MatrixXd> jacobian);

/// Bias acceleration d/dt(J) q_dot = [classical acceleration of the frame's origin (m/s^2); angular
/// acceleration (rad/s^2)] at q_ddot = 0, gravity excluded, base axes. Needs q_dot (as frameTwist);
/// NonfiniteResult as frameTwist when the result overflows.
Status frameBiasAcceleration(const Model& model, KinematicsData& kdata, const FrameRef& frame, Vector6& bias);

// ------------------------------------------------------------------------------------------------
// Several states at once, and poses as homogeneous matrices (kinematics_rows.cpp)
// ------------------------------------------------------------------------------------------------

/// q or q_dot of several states, one state per row (rows x n_joints, rad or m, rad/s or m/s).
using JointRows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
/// A pose as the row-major 4x4 homogeneous transform [R p; 0 0 0 1] (R: the frame's axes as
/// columns in base coordinates; p: its origin in the base frame, m).
using Homogeneous = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
/// Poses, one per row: row r holds a Homogeneous in row-major order (rows x 16).
using PoseRows = Eigen::Matrix<double, Eigen::Dynamic, 16, Eigen::RowMajor>;
/// Twists [v of the frame's origin (m/s); omega (rad/s)], base axes, one per row (rows x 6).
using TwistRows = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;

/// `pose` (a frame in the base frame, m) as a homogeneous transform.
Homogeneous homogeneous(const KDL::Frame& pose);

/// The pose of a 4x4 homogeneous transform T (row-major array, m), written to `pose`. Returns "" on
/// success, else the message naming T `name` (`pose` is then unchanged): "<name> must be a 4x4
/// homogeneous transform, got shape <shape>", nonfiniteMessage's (array_arg.hpp), "<name> must
/// have last row [0, 0, 0, 1]" (an entry off by more than 1e-12), or "<name>: the upper-left 3x3
/// block must be a rotation matrix (orthonormal, det +1)" (|R^T R - I| above 1e-9 or det R < 0).
std::string poseFromArray(const ArrayArg& T, const char* name, KDL::Frame& pose);

/// framePose at each state: row r of `poses` (rows x 16) is the pose of `frame` at q.row(r) (q:
/// rows x n_joints). kdata then holds the last row's kinematics. Errors: those of forwardKinematics
/// and framePose, SizeMismatch for poses without q's row count.
Status framePoses(const Model& model, KinematicsData& kdata, const Eigen::Ref<const JointRows>& q,
                  const FrameRef& frame, Eigen::Ref<PoseRows> poses);

/// frameTwist at each state: row r of `twists` (rows x 6) is the twist of `frame` at q.row(r) and
/// q_dot.row(r) (both rows x n_joints). Errors: those of forwardKinematics and frameTwist,
/// SizeMismatch for q_dot or twists without q's row count.
Status frameTwists(const Model& model, KinematicsData& kdata, const Eigen::Ref<const JointRows>& q,
                   const Eigen::Ref<const JointRows>& q_dot, const FrameRef& frame, Eigen::Ref<TwistRows> twists);

/// The tip pose of every segment at q: row i of `poses` (n_segments x 16) is segment i's. Errors:
/// those of forwardKinematics, SizeMismatch for poses not n_segments x 16.
Status segmentPoses(const Model& model, KinematicsData& kdata, const JointPositions& q, Eigen::Ref<PoseRows> poses);

}  // namespace vereshchagin
