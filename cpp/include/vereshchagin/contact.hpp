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
/// torque, maximum dissipation); where the torques are not unique, the sticking joints' torques
/// join the least-effort programme (the friction solver's least-command rule). Data's joint outputs
/// (frictionTorques(), limitTorques(), jointStatus(), gaussValue()) come from the same answer.
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
