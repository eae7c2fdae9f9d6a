/// @file
/// Whole-body least effort for underactuated robots (issue 28): at a state (q, qd), the actuated
/// joints' torques tau_a and the supports' contact forces lambda that realize a task with the
/// least motor effort. The base of a floating tree has no motor; on any tree a mask says which
/// joints have one. The math is in the docs' "Floating and mobile bases" page, section
/// "Underactuation and whole-body least effort".
///
/// Unknowns x = (tau_a, lambda): the torques of the actuated joints (N m or N, joint order) and
/// three force components per support (N, base axes: world axes on a floating base; ON the robot
/// BY the surface). The forward dynamics are affine in them:
///     qdd = qdd0 + R_tau tau_a + R_lambda lambda,
/// qdd0 the forward dynamics of the input alone (f_ext, wrenches, ff_torques, gravity), the
/// columns of R from the O(n) response sweeps (Data::responseColumns, wrenchResponseColumns), never
/// a dense mass-matrix inverse. Conditions:
///   - every support sticks: its point's classical acceleration is zero (normal and tangential);
///   - every task row holds: alfa^T Xdd = beta for each column of each SolveInput::constraints block
///     (the same meaning as in solve(), hd_solver.hpp; `classical` blocks too), and a block on
///     segment -1 constrains the base body itself (a floating base's frame, `point` in base axes):
///     "base still" is alfa = I (6 x 6) on segment -1 with beta = [-gravity; 0] at rest; a block on
///     segment kCenterOfMass (free-flyer only) constrains the centre of mass: alfa's force rows
///     (its moment rows must be zero) against [c_ddot - gravity; 0] (world axes, `point` unused;
///     `classical`: classical_acceleration's first 3 entries are c_ddot). On a free-flyer
///     M c_ddot = M gravity + the external forces (f_ext, wrenches, the base rows of ff_torques,
///     the supports): the joints' torques do not move it;
///   - each force lies in its contact's friction cone: n.f >= 0 and the polygon of `facets`
///     vertices of docs/contacts.md, written as its facets: mu cos(pi/k) n.f - m_j.f >= 0, m_j the
///     unit outward normal of facet j (at angle (2 j + 1) pi / k from t1).
/// Objective: the least motor effort sum(tau_a^2); where the forces are still not unique, the
/// least sum(|f_c|^2) among those (docs/contacts.md's rule). The equalities are eliminated exactly
/// (a column-pivoted QR of their matrix), the rest is a small convex programme solved by Lemke's
/// complementary pivoting (finite, lexicographic) and checked: residuals of the equalities and the
/// cone rows at round-off (the KKT certificate of the pivoting's complementary basis).
///
/// Not realizable: Error::NoSolution with a message naming what fails: the task rows and the
/// sticking supports contradict each other (no torques and forces at all meet them), or they can
/// be met but not with forces in the cones (the cones are too narrow, or a support would pull).
/// Nothing of a call is kept for the next one; workspace is sized at construction, and a call
/// allocates nothing once one of the same size has run.
#pragma once

#include <memory>

#include <Eigen/Core>

#include "vereshchagin/contact.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// ConstraintBlock::segment of a centre-of-mass task row block (see the top of this file).
constexpr int kCenterOfMass = -2;

/// Capacities and tolerance of a WholeBodySolver.
struct WholeBodyOptions {
  int max_contacts = 16;    ///< supports one solve may have (SolveInput::contacts)
  int max_task_rows = 36;   ///< task rows (constraint columns) one solve may have
  double tolerance = 1e-9;  ///< relative residual above which a condition counts as violated
};

/// What WholeBodySolver::solve() returns (sized by it).
struct WholeBodyResult {
  Eigen::VectorXd tau;    ///< model.nv(): motor torques (N m, N), zero on unactuated joints and base rows
  Matrix3X forces;        ///< 3 x k: each support's force ON the robot, base axes (world on a floating base), N
  Eigen::VectorXd qdd;    ///< model.nv(): the accelerations (a floating base's first, base axes, as Data::qdd())
  double effort = 0.0;    ///< sum of tau^2 (N^2 m^2)
  double residual = 0.0;  ///< largest violation of the task rows, supports and cones (their units), at round-off
};

/// Whole-body least effort on one Model (see the top of this file). One per thread.
class WholeBodySolver {
 public:
  /// Workspace for `model` (allocates); status() reports an invalid model or options.
  explicit WholeBodySolver(const Model& model, const WholeBodyOptions& options = WholeBodyOptions());
  ~WholeBodySolver();
  WholeBodySolver(WholeBodySolver&&) noexcept;             ///< moves the workspace
  WholeBodySolver& operator=(WholeBodySolver&&) noexcept;  ///< moves the workspace
  WholeBodySolver(const WholeBodySolver&) = delete;
  WholeBodySolver& operator=(const WholeBodySolver&) = delete;

  Status status() const noexcept;  ///< Error::InvalidModel or InvalidOptions, else Error::None

  /// Solves at input.q, input.q_dot (nq, nv entries) with input.f_ext, wrenches, ff_torques
  /// (nv: a floating base's rows are a wrench on the base, not a motor) and gravity; the task is
  /// input.constraints (segment -1: the base body), the supports input.contacts (support contacts
  /// only, segments >= 0, resting: their velocity is not checked). actuated: n_joints entries,
  /// non-zero for a joint with a motor; empty: every joint (a floating base's rows never are).
  /// Refused with a message: friction, a force set-point, time_step or base_acceleration non-zero,
  /// more contacts or task rows than the options' capacities (Error::OutOfRange,
  /// InvalidContact, TooManyConstraints, SizeMismatch). Not realizable: Error::NoSolution.
  Status solve(const SolveInput& input, const Eigen::Ref<const Eigen::VectorXi>& actuated, WholeBodyResult& result);

  struct Impl;  ///< the workspace (internal: cpp/src/whole_body_impl.hpp)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace vereshchagin
