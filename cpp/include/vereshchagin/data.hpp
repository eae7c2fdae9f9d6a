/// @file
/// The per-thread side of a solve: Data holds the workspace and the results, sized once for a
/// Model; solve(model, data, input) runs the Popov-Vereshchagin sweeps (with static friction when
/// the input has it) on them. Math, frames, signs and units: hd_solver.hpp; friction:
/// friction_solver.hpp.
///
///     Model model(chain);                       // once; shared by threads
///     Data data(model);                         // once per thread
///     SolveInput in(model);                     // once; rewritten every cycle
///     in.setState(JointPositions(q), JointVelocities(qd));
///     in.addConstraint(model.segmentOfJoint().back(), alfa, beta);
///     if (const Status s = solve(model, data, in); !s) handle(s.message());
///     use(data.qdd(), data.commandTorques());
///
/// Real-time use: constructing a Data allocates everything; solve() and every accessor below
/// allocate nothing. One Data per thread: a call entering a Data while another thread is inside
/// one returns Error::ConcurrentCall and leaves it untouched.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <kdl/frames.hpp>

#include "vereshchagin/hd_solver.hpp"  // SolverOptions
#include "vereshchagin/input.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

namespace detail {
struct DataImpl;
}  // namespace detail

/// Per joint after a solve with friction (friction_solver.hpp).
enum class JointStatus : signed char { Moving = 0, Stick = 1, SlipPositive = 2, SlipNegative = 3 };

/// Workspace and results of solves on one Model, one per thread (see the top of this file).
class Data {
 public:
  /// Workspace for `model` with `options` (policy, rcond, damping, max_constraints; its
  /// inertia_check is the model's and is ignored here). status() reports invalid options or an
  /// invalid model.
  explicit Data(const Model& model, const SolverOptions& options = SolverOptions());
  ~Data();
  Data(Data&&) noexcept;             ///< moves the workspace and results
  Data& operator=(Data&&) noexcept;  ///< moves the workspace and results
  Data(const Data&) = delete;
  Data& operator=(const Data&) = delete;

  Status status() const noexcept;                 ///< invalid options or model, else Error::None
  const SolverOptions& options() const noexcept;  ///< the options given to the constructor
  /// Constraint columns one solve may have in all: 6 per segment (at least 6), capped by
  /// options().max_constraints (0: SolverOptions::kDefaultConstraintCapacity).
  int maxConstraints() const noexcept;
  /// The workspace of the friction stage (n_joints^2 doubles, a few times over) is allocated at
  /// the first solve with input.friction set, so a frictionless Data stays O(n + m^2); call this
  /// once beforehand to keep that first friction solve allocation-free too.
  void reserveFriction();
  /// The model this Data was built for (solve() with another one: Error::NotUpToDate).
  const Model& model() const noexcept;

  /// Results of the last successful solve (unspecified before one). qdd: model.nv() entries (rad/s^2,
  /// m/s^2); on a floating base its first entries are the base's acceleration in base axes
  /// (base_kind.hpp), then the joints'.
  const Eigen::VectorXd& qdd() const noexcept;
  /// tau_cmd (model.nv(); hd_solver.hpp). On a floating base: the generalized force of the
  /// constraint forces, its base rows a wrench on the base (base axes) that no motor produces
  /// (docs/floating-base.md).
  const Eigen::VectorXd& commandTorques() const noexcept;
  Eigen::Map<const Eigen::VectorXd> nu() const noexcept;  ///< input.columns(), the input's column order
  int constraintRank() const noexcept;                    ///< rank of the coupling matrix K, hd_solver.hpp
  double smallestSingularValue() const;                   ///< computed on first request
  /// 6 x (n_segments + 1): column 0 the root acceleration, column i + 1 segment i's tip (base axes,
  /// tip origin, root acceleration included). Computed on first request. On a floating base:
  /// world axes, column 0 the base body's acceleration at its origin.
  const Matrix6X& linkAccelerations() const;
  /// With friction (zero / Moving without): friction and limit torques, joint status, Gauss value.
  /// Over a time step (SolveInput::time_step) they are the step's: the torques of the impulses
  /// over dt, Stick for a joint that ends the step at rest, and Z0(qdd) + sum_j f_j |qd+_j| / dt.
  const Eigen::VectorXd& frictionTorques() const noexcept;
  const Eigen::VectorXd& limitTorques() const noexcept;          ///< joint limit reactions (n_joints)
  const std::vector<JointStatus>& jointStatus() const noexcept;  ///< JointStatus of each joint
  double gaussValue() const;                                     ///< NaN without a friction solve
  int iterations() const noexcept;                               ///< active-set iterations of the friction solve
  /// With contacts (contact.hpp): the force each surface applies to the robot at its point (3 x k,
  /// base axes, N; a set-point's normal force included), each contact's status, and how the
  /// forces were determined. Without contacts: 3 x 0, empty, ContactOutcome::None.
  Eigen::Map<const Matrix3X> contactForces() const noexcept;
  const std::vector<ContactStatus>& contactStatus() const noexcept;  ///< ContactStatus of each contact
  ContactOutcome contactOutcome() const noexcept;                    ///< see contactForces()

  /// Kinematics at the last solve's state, base axes (allocation-free, O(depth) per call):
  /// the pose of a frame in the base frame, its twist [linear velocity of its origin; angular],
  /// and its Jacobian (6 x n_joints, columns in joint order; twist = J q_dot). On a floating base
  /// the pose and twist are in the world frame (the base's motion included) and the Jacobian is
  /// 6 x nv, world axes, the base's columns first (for its LOCAL velocity: twist = J q_dot, as
  /// Pinocchio's getFrameJacobian in LOCAL_WORLD_ALIGNED).
  KDL::Frame framePose(const FrameRef& frame) const;
  KDL::Twist frameTwist(const FrameRef& frame) const;                                       ///< see framePose()
  Status frameJacobian(const FrameRef& frame, Eigen::Ref<Eigen::MatrixXd> jacobian) const;  ///< see framePose()

  /// Affine response to unit joint torques (hd_solver.hpp, "Affine structure"), after a solve.
  /// dqdd, dtau_cmd: model.nv() x joints.size() (joints: joint indices; on a floating base the
  /// base's rows first, base axes, as qdd).
  Status responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                         Eigen::Ref<Eigen::MatrixXd> dtau_cmd);
  /// The same around a friction solve's sticking state: the joints that stuck in the last solve
  /// (jointStatus() Stick) are held, their static friction (or limit reaction) absorbing a small
  /// change of torque, so their qdd stays 0 and the others respond as in the robot with those
  /// joints locked: the columns of G - G[:, S] G[S, S]^+ G[S, :] (S the sticking joints,
  /// pseudo-inverse by complete orthogonal decomposition with threshold 1e-12). After a solve
  /// without friction, or with no joint sticking, it equals responseColumns(). Valid while the
  /// friction torques stay inside their bounds. Allocates its |S|-sized workspace (not for a
  /// real-time loop). dqdd, dtau_cmd: n_joints x joints.size().
  Status responseColumnsHoldingSticking(const Eigen::Ref<const Eigen::VectorXi>& joints,
                                        Eigen::Ref<Eigen::MatrixXd> dqdd, Eigen::Ref<Eigen::MatrixXd> dtau_cmd);
  /// Affine response to wrenches, after a solve: column c of dqdd (model.nv() x k) is the change of
  /// qdd per the wrench wrenches.col(c) added to f_ext ([force; moment] ON segment segments(c) BY
  /// the environment, base axes, moment about that segment's tip origin), the constraints held
  /// (their magnitudes change with it). O(n) per column, allocation-free; the results of the solve
  /// stay as they are. Error::NoSolution before a successful solve; SizeMismatch, OutOfRange.
  Status wrenchResponseColumns(const Eigen::Ref<const Eigen::VectorXi>& segments,
                               const Eigen::Ref<const Matrix6X>& wrenches, Eigen::Ref<Eigen::MatrixXd> dqdd);
  /// tau_cmd of given constraint magnitudes at the last solve's state.
  Status commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd);
  /// out = H(q)^-1 tau at the last solve's q.
  Status inverseInertiaTimes(const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> out);

  detail::DataImpl& impl() noexcept { return *impl_; }              ///< the implementation (internal)
  const detail::DataImpl& impl() const noexcept { return *impl_; }  ///< the implementation (internal)

 private:
  std::unique_ptr<detail::DataImpl> impl_;
};

/// One solve: validates the input against the model (sizes, finite values, constraint and
/// friction ranges, with the messages of HdSolver and FrictionSolver), then runs the sweeps.
/// Results in data. Nothing of the input outlives the call.
Status solve(const Model& model, Data& data, const SolveInput& input);

/// One step of semi-implicit Euler over input.time_step = dt > 0 (s): solve() over the time step
/// (the conditions of friction, limits and contacts on the end velocities, see
/// SolveInput::time_step), then qd_next = q_dot + dt qdd, exactly 0 for a joint friction holds
/// (JointStatus::Stick), and q_next = q + dt qd_next (n_joints each; they may alias input.q and
/// input.q_dot). On a floating base (base_kind.hpp) q_next has nq entries and qd_next nv, and
/// q_next = q (+) dt qd_next: the base moves on SE(3) (SE(2) for a planar base) by the exponential
/// of its LOCAL twist, as Pinocchio's integrate (integrateConfiguration()); free motion and segment
/// constraints there (friction and contacts are refused by solve()). Error::OutOfRange for
/// dt <= 0, SizeMismatch for wrong sizes, else solve()'s status. The results of the solve stay in data.
Status step(const Model& model, Data& data, const SolveInput& input, Eigen::Ref<Eigen::VectorXd> q_next,
            Eigen::Ref<Eigen::VectorXd> qd_next);

/// One step of symplectic Euler in momentum form over input.time_step = dt > 0 (s), from the state
/// (q, u) = (input.q, input.q_dot) and the momentum p = `momentum` (n_joints; N m s or N s): the
/// momentum the previous step left, H(q_prev) u, or H(q) u at the start). It finds u+ with
///     H(q) u+ = p + dt (tau - g(q) + dT/dq(q, u+)) + the impulses of friction, limits, contacts
/// (tau the input's torques and wrenches; dT/dq of energy.hpp), the impulses' conditions those of
/// solve() over the time step at the start velocity u, by fixed-point iteration on dT/dq(q, u+)
/// (each iteration one solve(); a few per step, one for a robot at rest); then q_next = q + dt u+,
/// qd_next = u+ (exactly 0 for a joint friction holds) and momentum_next = H(q) u+. Its energy
/// error stays bounded where step()'s grows (docs "Friction in discrete time", "Passive energy").
/// The results in data are those of the last iteration's solve (commandTorques() the motors' part,
/// the feed-forward torques not included, as always). After 100 iterations without convergence
/// (max |change of u+| <= 1e-12 max(1, |u+|)) the last iterate is taken: Error::Degraded. The
/// first call on a Data allocates its workspace (O(n)); later ones allocate nothing. Outputs
/// must not alias the inputs. On a floating base (as step()) momentum, qd_next and momentum_next
/// have nv entries, the base's rows the momentum in base axes (LOCAL), dT/dq's base rows those of
/// energy.hpp, and q_next = q (+) dt u+ (nq). Errors: those of step(), SizeMismatch for a momentum of
/// the wrong size, NonfiniteInput for one that is not finite.
Status stepSymplectic(const Model& model, Data& data, const SolveInput& input,
                      const Eigen::Ref<const Eigen::VectorXd>& momentum, Eigen::Ref<Eigen::VectorXd> q_next,
                      Eigen::Ref<Eigen::VectorXd> qd_next, Eigen::Ref<Eigen::VectorXd> momentum_next);

}  // namespace vereshchagin
