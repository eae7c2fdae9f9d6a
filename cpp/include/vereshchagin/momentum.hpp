/// @file
/// Centre-of-mass and momentum companions on a Model (model.hpp): the robot's centre of mass, its
/// Jacobian and velocity, and the centroidal momentum, for every base kind (base_kind.hpp).
/// Conventions, errors and the workspace are those of dynamics.hpp:
///  * q (nq entries), q_dot (nv): the model's state; on a fixed base the joints' only;
///  * "the frame" of the results: the WORLD frame on a floating base (the base's pose from q), the
///    base frame on a fixed base; every mass counts, the floating base body's included
///    (ModelOptions::base_inertia with a URDF's root link); rotor inertias do not (they are not
///    bodies);
///  * Pinocchio: centerOfMass, jacobianCenterOfMass and computeCentroidalMomentum (data.hg) with
///    the same root joint (JointModelFreeFlyer, JointModelPlanar or none).
/// No allocation. Errors: NotUpToDate, SizeMismatch, NonfiniteInput (also a base quaternion or
/// (cos, sin) more than 1e-6 off unit norm), NonfiniteResult; InvalidModel for a robot of zero
/// total mass (no centre of mass).
#pragma once

#include <Eigen/Core>

#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/spatial.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// The centre of mass c(q) (m, 3 entries) in the frame (see the top of this file).
Status centerOfMass(const Model& model, DynamicsData& ddata, const JointPositions& q, Eigen::Ref<Eigen::Vector3d> com);

/// The centre of mass's Jacobian J_c (3 x nv, written): dc/dt = J_c q_dot, m per rad (or per m),
/// the frame's axes; on a floating base its first columns take the base's LOCAL velocity.
Status centerOfMassJacobian(const Model& model, DynamicsData& ddata, const JointPositions& q,
                            Eigen::Ref<Eigen::MatrixXd> jacobian);

/// The centre of mass's velocity dc/dt = J_c q_dot (m/s, 3 entries), the frame's axes.
Status centerOfMassVelocity(const Model& model, DynamicsData& ddata, const JointPositions& q,
                            const JointVelocities& q_dot, Eigen::Ref<Eigen::Vector3d> velocity);

/// The centroidal momentum h_G = [p; L_G] (6 entries): the linear momentum p = M dc/dt (kg m/s)
/// and the angular momentum L_G (kg m^2/s) about the centre of mass, in the frame's axes.
Status centroidalMomentum(const Model& model, DynamicsData& ddata, const JointPositions& q,
                          const JointVelocities& q_dot, Eigen::Ref<Vector6> momentum);

}  // namespace vereshchagin
