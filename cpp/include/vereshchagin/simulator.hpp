/// @file
/// A simulator on the exact velocity-level step (step() in data.hpp, docs "Friction in discrete
/// time"): it owns a Model (a shared copy), a Data, the time step dt and the state (q, q_dot, t),
/// and advances the state one step per call with the torques, task, wrenches, friction and
/// contacts of a SolveInput. rollout() runs n steps with a controller callback and records the
/// states (and optionally the step outputs) into buffers the caller sized beforehand.
///
///     Simulator sim(model, 1e-3);               // once: allocates the workspace
///     sim.setState(JointPositions(q0), JointVelocities(qd0));
///     SolveInput in(model);                     // torques, friction, contacts: the caller's
///     in.friction = &friction;
///     for (int k = 0; k < 1000; ++k)
///       if (const Status s = sim.step(in); !s) handle(s.message());
///     use(sim.q(), sim.qDot(), sim.time(), sim.data().frictionTorques());
///
/// Real-time use: the constructor, setState() and reserveFriction() may allocate; step() and
/// rollout() allocate nothing once the input's sizes are those of the previous step (the first
/// step with friction or contacts sizes their workspace, as solve() does). The simulator keeps no
/// state from one step to the next besides (q, q_dot, t): each step is solve() of its own input.
#pragma once

#include <functional>

#include <Eigen/Core>

#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/hd_solver.hpp"  // SolverOptions
#include "vereshchagin/input.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// How a step turns the solve over the step into the next state.
enum class Integrator : signed char {
  /// step() of data.hpp: qd+ = q_dot + dt qdd (exactly 0 for a joint friction holds), then
  /// q+ = q + dt qd+, with every condition of friction, limits and contacts on qd+. The velocity
  /// terms (Coriolis, centrifugal, gravity's dependence on q) are taken at the start of the step.
  SemiImplicitEuler = 0,
  /// stepSymplectic() of data.hpp: symplectic Euler in momentum form, the velocity terms through
  /// dT/dq at the END velocity (a few solves per step, one at rest). The simulator carries the
  /// momentum p = H(q_prev) u (momentum()); q_dot is the step's velocity u (exactly 0 for a joint
  /// friction holds). Its passive energy error stays bounded where SemiImplicitEuler's grows
  /// (docs "Friction in discrete time", "Passive energy").
  Symplectic = 1,
};

/// What rollout() records, owned and sized by the caller (resize() once; rollout() checks the
/// sizes and allocates nothing). A matrix with zero columns is not recorded.
struct RolloutRecord {
  /// n_steps + 1: the time of each recorded state, s (entry 0 the start).
  Eigen::VectorXd t;
  /// n_joints x (n_steps + 1): column k the joint positions (rad or m) after k steps (column 0 the
  /// start). Column-major, so its memory is also a row-major (n_steps + 1, n_joints) array.
  Eigen::MatrixXd q;
  Eigen::MatrixXd q_dot;  ///< as q, joint velocities (rad/s or m/s)
  /// n_joints x n_steps or empty: column k the motors' tau_cmd of step k (N m or N,
  /// Data::commandTorques(); the input's ff_torques not included).
  Eigen::MatrixXd tau_command;
  /// n_joints x n_steps or empty: column k step k's friction torques, the friction impulses over
  /// dt (N m or N, Data::frictionTorques(); zero without friction).
  Eigen::MatrixXd friction_torque;
  /// 3 n_contacts x n_steps or empty: column k step k's contact forces, contact c in rows
  /// 3c .. 3c + 2 (the force the surface applies to the robot, base axes, N: impulses over dt).
  Eigen::MatrixXd contact_force;

  /// Sizes t, q, q_dot for `n_steps` steps of a model with `n_joints` joints, and tau_command,
  /// friction_torque (when asked) and contact_force (3 n_contacts rows; 0: not recorded).
  void resize(int n_joints, int n_steps, bool tau_command = false, bool friction_torque = false, int n_contacts = 0);
  /// As resize() above for `model`'s sizes: on a floating base q has nq rows, q_dot and
  /// tau_command nv (base_kind.hpp), friction_torque n_joints.
  void resize(const Model& model, int n_steps, bool tau_command = false, bool friction_torque = false,
              int n_contacts = 0);
};

/// Fills the input of the next step from the state: joint positions q (rad or m), velocities
/// q_dot (rad/s or m/s), the time t (s) at the start of the step. It may change anything in the
/// input (within its reserved capacity, for steps without allocation); what it writes to q, q_dot
/// and time_step is ignored (the simulator's state and dt are used).
using Controller =
    std::function<void(const Eigen::VectorXd& q, const Eigen::VectorXd& q_dot, double t, SolveInput& input)>;

/// A simulator on the exact velocity-level step (see the top of this file).
class Simulator {
 public:
  /// For `model` (copied: a Model shares its immutable data) with the time step `dt` (s, > 0 and
  /// finite), the integrator and the solver options (Data's). The state starts at rest at q = 0,
  /// t = 0 (a floating base at the world origin, unrotated: setNeutralBase()). status() reports an
  /// invalid model, invalid options or a bad dt. On a floating base (base_kind.hpp) the state has
  /// nq positions and nv velocities, and both integrators move the base on SE(3) (SE(2) for a
  /// planar base): step() and stepSymplectic() of data.hpp.
  Simulator(const Model& model, double dt, Integrator integrator = Integrator::SemiImplicitEuler,
            const SolverOptions& options = SolverOptions());

  /// Error::None, or why the simulator cannot step (every step() then returns it).
  Status status() const noexcept;
  const Model& model() const noexcept { return model_; }          ///< the simulator's model
  double timeStep() const noexcept { return dt_; }                ///< dt, s
  Integrator integrator() const noexcept { return integrator_; }  ///< the integrator

  /// Sets the state: q (rad or m), q_dot (rad/s or m/s), n_joints each (nq, nv) and finite, and the time t
  /// (s, finite). Error::SizeMismatch or NonfiniteInput (the state unchanged) otherwise.
  Status setState(const JointPositions& q, const JointVelocities& q_dot, double t = 0.0);
  const Eigen::VectorXd& q() const noexcept { return q_; }      ///< joint positions, n_joints (nq)
  const Eigen::VectorXd& qDot() const noexcept { return qd_; }  ///< joint velocities, n_joints (nv)
  /// Integrator::Symplectic's carried momentum (N m s or N s, n_joints or nv): H(q) q_dot after
  /// setState(), H(q_prev) u after a step. Zeros under SemiImplicitEuler (not used).
  const Eigen::VectorXd& momentum() const noexcept { return p_; }
  /// s: the t of setState() plus dt times the steps since (a product, not a running sum).
  double time() const noexcept { return t0_ + static_cast<double>(steps_) * dt_; }
  /// Sizes the friction workspace now (Data::reserveFriction()), so that no step allocates.
  void reserveFriction() { data_.reserveFriction(); }

  /// One step from the state with `input`'s ff_torques, task (constraints), f_ext and wrenches,
  /// friction, contacts, gravity and base acceleration; input.q, input.q_dot and input.time_step
  /// are ignored (the simulator's state and dt take their place). On success the state advances
  /// (t by dt) and data() holds the step's results: qdd the step's mean acceleration,
  /// commandTorques(), frictionTorques() and limitTorques() (impulses over dt, N m or N),
  /// contactForces() (impulses over dt, N), jointStatus() and contactStatus(). On failure the
  /// state is unchanged and the status says why (solve()'s messages).
  Status step(const SolveInput& input);
  /// The same step without copying `input`: the simulator's state and dt take the place of
  /// input.q, input.q_dot and input.time_step for the step (their vectors' buffers swapped) and
  /// the caller's own values are back in them on return, whatever the status.
  Status step(SolveInput& input);

  /// n_steps steps: before each, `controller` (may be empty: the input as given) fills `input`
  /// from the state; each step as step(input). Records into `record` (sized by
  /// RolloutRecord::resize for n_steps; Error::SizeMismatch otherwise, nothing stepped) the
  /// states and the outputs asked for. On a failing step the rollout stops, the state is the last
  /// good one, `steps_done` (if given) the number of steps done and the status the step's.
  Status rollout(int n_steps, const Controller& controller, SolveInput& input, RolloutRecord& record,
                 int* steps_done = nullptr);

  /// The results of the last step (of its solve over the step), see step().
  const Data& data() const noexcept { return data_; }
  /// The same, for Data's non-const queries (responseColumns() around the last step's state).
  Data& data() noexcept { return data_; }

 private:
  // One step from `at_state` (whose q, q_dot and time_step are the state and dt) into q_next_,
  // qd_next_ (and p_next_); adopt() makes them the state.
  Status advance(const SolveInput& at_state);
  void adopt() noexcept;
  Status checkRecord(int n_steps, const SolveInput& input, const RolloutRecord& record) const;
  void recordStep(int k, RolloutRecord& record) const;

  Model model_;
  Data data_;
  SolveInput work_;                            // step(const SolveInput&): a copy of the caller's input
  Eigen::VectorXd q_, qd_, p_;                 // the state (p_: Integrator::Symplectic's momentum)
  Eigen::VectorXd q_next_, qd_next_, p_next_;  // a step's results until it succeeds
  DynamicsData dynamics_;                      // setState()'s momentum H(q) q_dot
  double dt_ = 0.0, t0_ = 0.0;                 // t0_: the time setState() gave
  long steps_ = 0;                             // steps since setState()
  Integrator integrator_;
  Status status_;
};

}  // namespace vereshchagin
