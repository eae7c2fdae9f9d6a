/// @file
/// Point contacts of a solve (SolveInput::contacts): a point on a segment touching a surface, with
/// Coulomb friction in a polygonal cone, either as a unilateral support or with a normal-force
/// set-point. The environment supplies the contact forces, the motors only the task's constraint
/// forces (and a set-point's normal reaction): Gauss's principle with unilateral constraints.
/// Results: Data::contactForces(), contactStatus(), contactOutcome(). The math, signs and the
/// polygon's orientation are in the docs' "Contacts" page.
///
/// With joint friction (SolveInput::friction), joint friction, joint limits and the contacts are one
/// complementarity problem (each resting joint with friction or on a limit one more bounded unknown
/// torque); the last sweep runs the friction stage with the contact forces as wrenches, so
/// Data::frictionTorques(), limitTorques() and jointStatus() are the friction stage's (its max-min
/// reproduces the contact problem's qdd, which the solve checks: Error::NoContactSolution if not).
///
/// Frames, signs, units: the point in the segment's tip frame (m); the normal in base axes, unit,
/// pointing from the surface into the robot (the direction the surface pushes); forces in base
/// axes (N), ON the robot BY the surface, applied at the point. A point is at rest along the
/// normal (touching) when its normal velocity is at most SolveInput::contact_velocity_tolerance,
/// separating above it; a support approaching the surface faster than that is refused (it needs
/// an impulse, not a force). Tangentially it slides when its tangential speed exceeds the same
/// tolerance.
///
/// The friction polygon of a contact with k facets has its k vertices at mu f_n d_j,
/// d_j = cos(2 pi j / k) t1 + sin(2 pi j / k) t2 (j = 0 .. k-1): inscribed in the circular cone.
/// t1 = unit(e x n) for the base axis e least aligned with n (the first on ties), t2 = n x t1.
#pragma once

#include <limits>

#include "vereshchagin/spatial.hpp"

namespace vereshchagin {

using Matrix3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;  ///< 3 x k: one 3-vector per column

/// One point contact (see the top of this file).
struct PointContact {
  int segment = -1;                   ///< the segment the point moves with (segment order)
  Vector3 point = Vector3::Zero();    ///< the point in the segment's tip frame, m
  Vector3 normal = Vector3::UnitZ();  ///< unit, base axes, along which the surface pushes the robot
  double mu = 0.0;                    ///< Coulomb coefficient, >= 0 (0: frictionless)
  int facets = 4;                     ///< vertices of the friction polygon, 3 .. 64
  /// Normal-force set-point, N, >= 0: the point stays in contact (zero normal acceleration, held by
  /// the motors) and the surface pushes with exactly this force. NaN (default): a support, whose
  /// normal force the solve finds (>= 0, zero when the point lifts off).
  double force = std::numeric_limits<double>::quiet_NaN();
  bool isSupport() const { return force != force; }  ///< no normal-force set-point
};

/// What a contact does in the solved motion.
enum class ContactStatus : signed char {
  Separating = 0,  ///< no force: the point leaves the surface (or already moves away from it)
  Sticking = 1,    ///< at rest tangentially, the force inside the friction polygon
  Sliding = 2,     ///< sliding or starting to slide, the force on the polygon's boundary
};

/// How the contact forces of a solve were determined.
enum class ContactOutcome : signed char {
  None = 0,        ///< no contacts in the last solve
  Unique = 1,      ///< the accelerations are unique (no touching support has friction: a convex problem)
  Consistent = 2,  ///< one consistent answer (supports with friction: others may exist, Painleve)
};

}  // namespace vereshchagin
