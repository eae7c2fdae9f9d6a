/// @file
/// Base kinds of a model (model.hpp, ModelOptions::base): a fixed base welded to the world, a
/// free-flyer (6 unactuated DOF) or a planar base (x, y, yaw in the world's x-y plane), and the
/// state layout each gives. The layout is Pinocchio's (JointModelFreeFlyer, JointModelPlanar):
///
///  * Fixed: q = (joints), q_dot = (joints): nq = nv = n (n: the moving joints).
///  * FreeFlyer: q = (x, y, z, qx, qy, qz, qw, joints): the base frame's origin in world
///    coordinates (m) and its orientation as a unit quaternion (x, y, z, w order; the rotation
///    from base axes to world axes); nq = n + 7. q_dot = (v, omega, joints): the base origin's
///    linear velocity (m/s) and the base's angular velocity (rad/s), both in BASE axes (Pinocchio's
///    LOCAL); nv = n + 6. qdd's base rows are the time derivatives of those six numbers, i.e. the
///    base's spatial acceleration in base axes.
///  * Planar: q = (x, y, cos yaw, sin yaw, joints): the base origin in the world's x-y plane (m)
///    and the yaw about the world z axis; nq = n + 4. q_dot = (v_x, v_y, omega_z, joints) with the
///    linear velocity in BASE axes; nv = n + 3.
///
/// Generalized forces (ff_torques, tau_command) have nv entries in q_dot's order: on the base
/// rows a wrench on the base body in base axes, [force (N); moment about the base origin (N m)]
/// (the planar base: f_x, f_y, n_z), which no motor produces (the base is unactuated).
#pragma once

#include <string>

#include <Eigen/Core>

namespace vereshchagin {

/// How the model's base (its root frame) moves: see the top of this file.
enum class BaseKind {
  Fixed,      ///< welded to the world (nq = nv = n)
  FreeFlyer,  ///< 6 unactuated DOF, unit quaternion (nq = n + 7, nv = n + 6)
  Planar,     ///< x, y, yaw in the world's x-y plane (nq = n + 4, nv = n + 3)
};

/// Entries of q the base takes: 0, 7 or 4.
constexpr int baseConfigurationSize(BaseKind kind) noexcept {
  return kind == BaseKind::FreeFlyer ? 7 : kind == BaseKind::Planar ? 4 : 0;
}

/// Entries of q_dot (and of qdd, ff_torques, tau_command) the base takes: 0, 6 or 3.
constexpr int baseVelocitySize(BaseKind kind) noexcept {
  return kind == BaseKind::FreeFlyer ? 6 : kind == BaseKind::Planar ? 3 : 0;
}

/// "fixed", "free" or "planar" (the names of Tree.from_urdf's base= in Python).
const char* baseKindName(BaseKind kind) noexcept;

/// The kind named "fixed", "free" (or "free_flyer") or "planar"; false for any other name.
bool baseKindFromName(const std::string& name, BaseKind& out) noexcept;

/// q_next = q (+) dt v, the configuration reached from q (nq entries, this layout) by moving with
/// the constant velocity v (nv entries; rad/s, m/s, the base's LOCAL twist) for dt (s), as
/// Pinocchio's integrate(model, q, dt v) with the same root joint: the joints q_j + dt v_j; a
/// free-flyer's base M_next = M exp(dt v_b), the SE(3) exponential of its twist (so the base
/// moves along a screw: the translation in base axes, turned as the base turns), its quaternion
/// times that of exp(dt omega) on the right, normalized; a planar base likewise with the SE(2)
/// exponential of dt (v_x, v_y, omega_z), (cos, sin) normalized. q_next may alias q, not v. No
/// allocation, no checks (sizes, finiteness and the unit norm are the caller's).
void integrateConfiguration(BaseKind kind, const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& v, double dt, Eigen::Ref<Eigen::VectorXd> q_next);

/// Sets q's base part (nq entries) to the base at the world origin, unrotated: (0, 0, 0, 0, 0, 0,
/// 1) for a free-flyer, (0, 0, 1, 0) for a planar base; the joints' entries are left as they are.
void setNeutralBase(BaseKind kind, Eigen::Ref<Eigen::VectorXd> q);

}  // namespace vereshchagin
