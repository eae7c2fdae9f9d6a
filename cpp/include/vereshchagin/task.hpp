/// @file
/// Task-space helpers for stating constraints in the solver's terms: the solver constrains
/// alfa^T Xdd = beta with Xdd a frame's SPATIAL acceleration (base axes, about the frame's origin,
/// root acceleration -gravity included: hd_solver.hpp, input.hpp's ConstraintBlock), while
/// controllers think in the CLASSICAL acceleration of the frame's origin and in pose errors.
///
/// Units and frames of every argument: base-frame axes; [linear; angular] 6-vectors; a twist is
/// [velocity of the frame's origin (m/s); angular velocity (rad/s)]; a classical acceleration is
/// [second time derivative of the origin's position (m/s^2); angular acceleration (rad/s^2)];
/// gravity is PHYSICAL gravity (m/s^2, Earth with z up: (0, 0, -9.81)), as SolveInput::gravity,
/// with a fixed base (SolveInput::base_acceleration zero).
#pragma once

#include <Eigen/Core>
#include <kdl/frames.hpp>

#include "vereshchagin/array_arg.hpp"
#include "vereshchagin/kinematics.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/spatial.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// The spatial acceleration the solver sees for a desired classical one:
///     [a_lin - omega x v - gravity; a_ang].
/// (The linear part of a spatial acceleration is that of the body point passing through the
/// origin at this instant, a_classical - omega x v; the solver's base accelerates by -gravity.)
Vector6 spatialFromClassical(const Vector6& classical, const Vector6& twist, const KDL::Vector& gravity);

/// beta (m) = alfa^T spatialFromClassical(classical, twist, gravity) for alfa 6 x m (unit wrenches
/// [force; moment about the frame's origin], base axes). Holding a frame still needs
/// beta = alfa^T [-omega x v - gravity; 0], not zero.
void betaFromClassical(const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Vector6& classical, const Vector6& twist,
                       const KDL::Vector& gravity, Eigen::Ref<Eigen::VectorXd> beta);

/// The shape of beta for the arrays of the Python face's task.beta_for (array_arg.hpp): alfa (6,)
/// or (6, m) row-major, twist (6,) or (N, 6) one state per row, classical (6,) for every state or
/// (N, 6) one per twist row, gravity (3,), all finite. Returns false for anything else (the caller
/// then says what is wrong); else beta's shape, (m,) or (N, m), in ndim and shape.
bool betaShape(const ArrayArg& alfa, const ArrayArg& classical, const ArrayArg& twist, const ArrayArg& gravity,
               int& ndim, long shape[2]);

/// betaFromClassical for arrays that passed betaShape: row r of beta (betaShape's shape, row-major)
/// from twist row r and classical row r (or its only row). Returns false when a beta is not finite
/// (finite inputs too large; beta then holds it), else true.
bool betaFromArrays(const ArrayArg& alfa, const ArrayArg& classical, const ArrayArg& twist, const ArrayArg& gravity,
                    double* beta);

/// The same with the frame's twist from kdata (forwardKinematics with q_dot first). Errors: those
/// of frameTwist (kinematics.hpp), SizeMismatch for alfa not 6 x m or beta not m long.
Status betaForFrame(const Model& model, KinematicsData& kdata, const FrameRef& frame,
                    const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Vector6& classical, const KDL::Vector& gravity,
                    Eigen::Ref<Eigen::VectorXd> beta);

/// Pose error [p_d - p_c (m); axis * angle of R_d R_c^T (rad, angle in [0, pi])], base axes: the
/// rotation that turns the current orientation into the desired one (KDL's diff(current, desired)),
/// via a unit quaternion, accurate near 0 and pi.
Vector6 poseError(const KDL::Frame& current, const KDL::Frame& desired);

/// Twist error desired - current (both [v; omega], base axes).
inline Vector6 twistError(const Vector6& current, const Vector6& desired) {
  return desired - current;
}

}  // namespace vereshchagin
