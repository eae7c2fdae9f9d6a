/// @file
/// Everything one solve reads (solve() in data.hpp), as one plain value: the joint state, the
/// constraints, the wrenches, the feed-forward torques, friction and gravity. Frames, signs and
/// units are those of hd_solver.hpp unless stated here.
///
/// A SolveInput is sized for its model once (construction allocates; reserve() more constraint
/// blocks or link wrenches up front); filling it afterwards allocates nothing, so a control loop
/// keeps one and rewrites it. clear() resets everything but the state and gravity. Nothing in it
/// is kept by the solve: the next solve reads only the input it is given.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <kdl/frames.hpp>

#include "vereshchagin/contact.hpp"
#include "vereshchagin/friction_model.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/spatial.hpp"

namespace vereshchagin {

/// Typed joint vectors: a function that takes (JointPositions, JointVelocities) does not compile
/// with the two swapped. Each wraps a reference to the caller's vector (no copy).
template <typename Tag>
class JointVector {
 public:
  /// Wraps a reference to v (which must outlive this object).
  explicit JointVector(const Eigen::Ref<const Eigen::VectorXd>& v) : v_(v) {}
  const Eigen::Ref<const Eigen::VectorXd>& operator*() const { return v_; }  ///< the wrapped vector
  const Eigen::Ref<const Eigen::VectorXd>& value() const { return v_; }      ///< the wrapped vector

 private:
  Eigen::Ref<const Eigen::VectorXd> v_;
};
using JointPositions = JointVector<struct JointPositionsTag>;    ///< q: rad or m, n_joints
using JointVelocities = JointVector<struct JointVelocitiesTag>;  ///< q_dot: rad/s or m/s, n_joints
using JointTorques = JointVector<struct JointTorquesTag>;        ///< N m or N, n_joints

/// Up to 6 constraint columns on one frame moving with a segment.
struct ConstraintBlock {
  int segment = -1;  ///< the segment the columns act on (segment order)
  int columns = 0;   ///< 0..6: how many of the columns below are used
  /// Column c < columns: a unit constraint wrench [force; moment], base axes, the moment about
  /// `point`; beta(c) = alfa.col(c)^T Xdd_point (Xdd: the frame's spatial acceleration in base
  /// axes about `point`, root acceleration -gravity included, as hd_solver.hpp).
  Eigen::Matrix<double, 6, 6> alfa = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> beta = Eigen::Matrix<double, 6, 1>::Zero();  ///< beta(c) of column c (see alfa)
  /// The frame's origin in the segment's tip frame (a merged link or a tool frame; zero: the tip).
  Vector3 point = Vector3::Zero();
  /// Driver pass-through per column (hd_solver.hpp, "Driver pass-through"), each in [0, 1].
  Eigen::Matrix<double, 6, 1> f_ext_pass_through = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> ff_pass_through = Eigen::Matrix<double, 6, 1>::Zero();  ///< see f_ext_pass_through
  /// When true, `beta` is not read: the set-point is the CLASSICAL acceleration
  /// `classical_acceleration` of the frame's origin ([m/s^2; rad/s^2], base axes, task.hpp), and
  /// solve() sets beta = alfa^T spatialFromClassical(classical_acceleration, twist, gravity) with
  /// the frame's twist from its own outward sweep at the input's state (no kinematics of its own).
  /// Needs a base at rest (SolveInput::base_acceleration zero).
  bool classical = false;
  Vector6 classical_acceleration = Vector6::Zero();  ///< see classical
};

/// A wrench on a frame moving with a segment, added to f_ext.
struct FrameWrench {
  int segment = -1;  ///< the segment the frame moves with (segment order)
  Vector6 wrench =
      Vector6::Zero();              ///< [force; moment] ON the body BY the environment, base axes, moment about `point`
  Vector3 point = Vector3::Zero();  ///< the frame's origin in the segment's tip frame
};

/// Everything one solve reads (see the top of this file).
struct SolveInput {
  /// Sized for `model`: q, q_dot, ff_torques zero (n_joints), f_ext zero (6 x n_segments), room
  /// for `blocks` constraint blocks and `wrenches` frame wrenches without allocating.
  explicit SolveInput(const Model& model, int blocks = 8, int wrenches = 8);

  /// Joint positions q (rad or m), model.nq() entries (n_joints on a fixed base; a floating
  /// base's entries first, in the layout of base_kind.hpp: position and unit quaternion).
  Eigen::VectorXd q;
  /// Joint velocities q_dot (rad/s or m/s), model.nv() entries (n_joints on a fixed base; a
  /// floating base's first, in the layout of base_kind.hpp: velocities in base axes).
  Eigen::VectorXd q_dot;
  /// Wrench on each segment BY the environment (6 x n_segments): base axes, moment about the
  /// segment's tip origin. Gravity does not go here.
  Matrix6X f_ext;
  std::vector<FrameWrench> wrenches;         ///< more wrenches, on any frame (added to f_ext)
  Eigen::VectorXd ff_torques;                ///< model.nv(), added as-is (a floating base's rows: a wrench on it)
  std::vector<ConstraintBlock> constraints;  ///< the columns of nu, in this order
  /// Static friction, kinetic friction and joint limits (friction_solver.hpp); nullptr: none.
  /// Not owned: it must outlive the solve.
  const FrictionModel* friction = nullptr;
  /// Point contacts (contact.hpp): supports and normal-force set-points on any segments. The
  /// constraint columns of nu stay those of `constraints`; a set-point's normal reaction is part of
  /// the command torques. With `friction`, joint friction, joint limits and the contacts are solved
  /// together (contact.hpp).
  std::vector<PointContact> contacts;
  /// Below this speed (m/s) a contact point is at rest along the normal, resp. not sliding.
  double contact_velocity_tolerance = 1e-6;
  /// Real-time bound of the contacts' complementarity problem: Lemke pivots per run, -1 (default)
  /// 50 + 20 n_z for its n_z unknowns, n > 0: n. When the general problem reaches it, the solve
  /// returns Error::Degraded with a safe fallback (touching supports held along their normals,
  /// without friction at the contacts and resting joints: docs/friction.md, "Real-time bound").
  int contact_max_pivots = -1;
  /// Time step dt (s) of a velocity-level solve; 0 (default): the instant. With dt > 0 the
  /// conditions of joint friction, joint limits and contacts hold at the end of the step, for the
  /// velocities qd+ = q_dot + dt qdd (the result's qdd is the step's mean acceleration): a joint or
  /// contact point whose holding force stays within friction ends the step at zero velocity, a
  /// sliding one gets the full friction against its end velocity (it cannot be reversed by it), a
  /// support ends the step not approaching its surface (an impact is an impulse). A contact
  /// point's end velocity is taken to first order, v + dt a (its velocity and acceleration at q);
  /// step() in data.hpp integrates (semi-implicit Euler).
  double time_step = 0.0;
  /// Physical gravity, base axes, m/s^2 (Earth with z up: (0, 0, -9.81)), and the base's own
  /// commanded spatial acceleration [linear; angular] (base axes, base origin; zero: a fixed
  /// base). The solver's root acceleration is base_acceleration - [gravity; 0].
  KDL::Vector gravity = KDL::Vector(0.0, 0.0, -9.81);
  KDL::Twist base_acceleration = KDL::Twist::Zero();  ///< see gravity

  /// q = q_in, q_dot = q_dot_in.
  void setState(const JointPositions& q_in, const JointVelocities& q_dot_in);
  /// Appends a block (no allocation within reserve()); Error::SizeMismatch for more than 6 columns
  /// or a beta of another length, Error::OutOfRange for a segment outside the model.
  Status addConstraint(int segment, const Eigen::Ref<const Eigen::MatrixXd>& alfa,
                       const Eigen::Ref<const Eigen::VectorXd>& beta, const Vector3& point = Vector3::Zero());
  /// The same on a frame resolved by Model::findFrame (its offset gives `point`; its orientation
  /// does not matter: alfa is in base axes).
  Status addConstraint(const FrameRef& frame, const Eigen::Ref<const Eigen::MatrixXd>& alfa,
                       const Eigen::Ref<const Eigen::VectorXd>& beta);
  /// Adds a wrench on a frame (its offset gives `point`); Error::OutOfRange for the base
  /// (segment -1: nothing moves it) or a segment outside the model.
  Status addWrench(const FrameRef& frame, const Vector6& wrench);
  /// Constraint columns in all (the size of nu).
  int columns() const;
  /// Zero f_ext and ff_torques, no constraints, frame wrenches, contacts or friction; keeps q,
  /// q_dot, gravity, base_acceleration, the contact velocity tolerance and all capacity.
  void clear();
  /// Room for `blocks` constraint blocks, `wrenches` frame wrenches and as many contacts
  /// (allocates now, not later).
  void reserve(int blocks, int wrenches);

 private:
  int segments_ = 0;  // the model's segment count (addConstraint's and addWrench's range check)
};

}  // namespace vereshchagin
