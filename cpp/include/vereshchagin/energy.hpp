/// @file
/// Energy companions on a Model (model.hpp): the kinetic and potential energy of the robot and the
/// gradient of the kinetic energy in the joint positions, the piece of the equation of motion
/// that the symplectic step (simulator.hpp) treats implicitly. Conventions, errors and the
/// workspace are those of dynamics.hpp:
///  * q, q_dot: n_joints entries in the model's joint order (rad, rad/s; m, m/s for prismatic);
///  * T(q, q_dot) = 1/2 q_dot^T H(q) q_dot (J), rotor inertias included;
///  * V(q) = - sum_i m_i gravity . c_i(q) (J): gravity PHYSICAL, base axes, m/s^2; c_i body i's
///    centre of mass in the base frame (m), so V = 0 for every mass at the height of the base
///    origin;
///  * dT/dq (n_joints; N m or N): the partial derivative of T at fixed q_dot. With the Lagrangian
///    L = T - V the equation of motion reads d/dt (H q_dot) = dT/dq - dV/dq + tau (+ J^T f_ext),
///    and dT/dq = C(q, q_dot)^T q_dot for the Coriolis matrix C whose H_dot - 2 C is skew.
///
/// On a floating base (base_kind.hpp; dynamics.hpp for q of nq and q_dot of nv entries, gravity in
/// world axes): T includes the base body's and is 1/2 q_dot^T H q_dot still; V sums every mass's
/// height in the WORLD frame (the base body's too: Pinocchio's computePotentialEnergy); dT/dq's
/// base rows are -S_b^T (V_b x* h): V_b the base's spatial velocity and h the whole robot's
/// momentum, both in base axes about the base origin, S_b the base's axes (identity, or the
/// x, y, yaw columns of a planar base). With the base's LOCAL velocity these rows are not a
/// partial derivative (T does not depend on the base's pose) but the body-frame term of
/// d/dt (H q_dot) = C^T q_dot + tau - g, so that dT/dq = C(q, q_dot)^T q_dot holds on every row
/// (Pinocchio's computeCoriolisMatrix).
///
/// Each call is O(n): one sweep out (poses, velocities, body momenta about the base origin) and,
/// for the gradient, one sweep in (subtree momenta h_sub): dT/dq_j = (V_j x S_j) . h_sub(j), with
/// V_j the spatial velocity of joint j's segment and S_j its axis (derivation: docs/time-step.md).
/// No allocation.
#pragma once
#include <Eigen/Core>
#include <kdl/frames.hpp>
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/status.hpp"
namespace vereshchagin {

/// T(q, q_dot) (J) into `energy`.
Status kineticEnergy(const Model& model, DynamicsData& ddata, const JointPositions& q, const JointVelocities& q_dot,
                     double& energy);

/// V(q) (J) for physical gravity `gravity` (base axes, m/s^2) into `energy`.
Status potentialEnergy(const Model& model, DynamicsData& ddata, const JointPositions& q, const KDL::Vector& gravity,
                       double& energy);

/// dT/dq at (q, q_dot) into `gradient` (n_joints, written).
Status kineticEnergyGradient(const Model& model, DynamicsData& ddata, const JointPositions& q,
                             const JointVelocities& q_dot, Eigen::Ref<Eigen::VectorXd> gradient);

}  // namespace vereshchagin
