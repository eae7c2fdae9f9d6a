/// @file
/// Joint friction and limits of a solve with static friction (friction_solver.hpp has the
/// problem, the method and the outputs; docs/friction.md the math). Units: N m or N, rad or m.
#pragma once

#include <Eigen/Core>

namespace vereshchagin {

/// Friction (and joint limit) parameters of one FrictionSolver::solve() call.
struct FrictionModel {
  Eigen::VectorXd static_friction;   ///< f_j >= 0 per joint (N m or N)
  Eigen::VectorXd kinetic_friction;  ///< 0 <= fk_j <= f_j per joint; empty: equal to static_friction
  double velocity_tolerance = 1e-6;  ///< |qd_j| at or below this: the joint is at rest
  /// Joint position limits (Vukcevic 2018, sec. 5.2: a second dissipative force). A joint at rest
  /// with q_j <= lower_j + limit_tolerance (or >= upper_j - limit_tolerance) gets, in the same
  /// optimisation, a one-sided reaction that stops it from moving further into the limit (no
  /// bound on its size). Empty vectors: no limits; +-infinity entries: no limit on that side.
  Eigen::VectorXd lower, upper;   ///< lower and upper joint position limits (rad or m)
  double limit_tolerance = 1e-9;  ///< distance (rad or m) from a limit at which a joint counts as on it
  /// Real-time bound on the active-set iterations of each optimisation stage of one solve (the box
  /// QP over the k joints with unknown friction, then the least-command tie-break), at the
  /// instant and over a time step (docs/friction.md, "Real-time bound"): -1 (default) for
  /// 6 k + 16, 0 for the exhaustive bound 5 (k + 1) 3^k + 4 (capped at 1e8), n > 0 for n (at most
  /// the exhaustive bound). Hitting it is not a failure: the solve returns Error::Degraded
  /// (FrictionSolver::E_DEGRADED) with its documented fallback: friction torques within their
  /// bounds that do no positive work on the motion in sum. Other values: E_INVALID_FRICTION.
  int max_iterations = -1;

  /// Every vector empty: zero friction and no limits on every joint, as an empty f_ext means no
  /// external wrench (the solve's motion is the frictionless one; the friction outputs are zero).
  bool empty() const noexcept {
    return static_friction.size() == 0 && kinetic_friction.size() == 0 && lower.size() == 0 && upper.size() == 0;
  }
};

class Model;

/// The model's own friction in one call: its joints' static friction (a URDF's `<dynamics
/// friction>`, N m or N) and position limits, kinetic friction equal to static, FrictionModel's
/// default tolerances; empty (no friction) for a model built from KDL objects, which carry none.
FrictionModel modelFriction(const Model& model);

}  // namespace vereshchagin
