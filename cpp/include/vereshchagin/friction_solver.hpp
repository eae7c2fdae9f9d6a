/// @file
/// Popov-Vereshchagin hybrid dynamics with static (breakaway) joint friction, solved exactly.
///
/// Problem (Vereshchagin's max-min as in D. Vukcevic, TR 03-2018, H-BRS 2018; stated in full in
/// docs/friction.md): joints at rest (|qd_j| <= velocity_tolerance) with breakaway
/// friction f_j > 0 get the friction torque -mu_j, |mu_j| <= f_j, that maximises the dissipation:
///
///   qdd* = argmin_qdd  Z0(qdd) + sum_{j at rest} f_j |qdd_j|   subject to the task,
///   mu*  = argmax_{|mu| <= f}  g(mu),  g(mu) = c^T mu - 1/2 mu^T Q mu,
///
/// with Z0 the frictionless Gauss function, Q = W G W^T (G the constrained inverse inertia of
/// HdSolver::responseColumns, W the selection of resting joints) and c = W qdd(0). Moving
/// joints get the kinetic (Coulomb) friction -fk_j sign(qd_j) as a feed-forward torque.
///
/// Method: one full solve, the response columns of the resting joints (O(n) each, no
/// refactorisation; half the outward work when every joint rests, G being symmetric), then the
/// k x k box QP by an active-set method (exact: complementarity holds to round-off; singular Q
/// handled through zero-curvature directions): a few primal-dual working-set rounds on definite
/// faces, then primal steps whose free-set L D L^T follows each newly bound variable by a
/// rank-one update. When several mu give the same qdd* (the task fixes some resting joints'
/// accelerations), the one minimising the motor command ||tau_cmd||^2 is chosen (a least-distance
/// problem on the optimal face, solved in the range space of Q_StSt): static friction holds what
/// it can and the motors add only the rest.
///
/// Over a time step (SolveInput::time_step > 0 through solve(model, data, input); data.hpp's
/// step()): every joint with friction takes part, bounded by its static friction at rest and its
/// kinetic friction while moving, and the max-min is on the end velocities qd + dt qdd: the box
/// QP's c is shifted by W qd / dt; the least-command rule and the outputs follow (a joint that ends
/// the step at rest is Stick, one at rest that breaks away SlipPositive / SlipNegative).
///
/// Units, frames, segment and joint order are those of the underlying HdSolver (ChainHdSolver for
/// a chain, TreeHdSolver for a tree; hd_solver.hpp). Outputs after solve():
///  * qdd (n): joint accelerations.
///  * commandTorques (n): tau_cmd = -J^T alfa nu at the optimum: what the motors add to
///    ff_torques. Forward dynamics with ff_torques + tau_cmd + frictionTorques reproduces qdd.
///  * frictionTorques (n): the physical friction torque on each joint (-mu* at rest, at most f_j
///    in size; -fk sign(qd) when moving).
///  * limitTorques (n): the reaction of joint limits (>= 0 at a lower limit, <= 0 at an upper
///    one): what friction cannot hold of the total -mu* at a joint resting on its limit.
///  * status (n): Moving, Stick, SlipPositive (qdd > 0) or SlipNegative (qdd < 0).
///  * nu, constraint rank: as HdSolver at the optimum.
///  * gaussValue(): Z0(qdd*) + sum_rest f_j |qdd*_j|, with Z0(qdd) = 1/2 (qdd - qdd_free)^T H
///    (qdd - qdd_free) and qdd_free the unconstrained motion under ff_torques and kinetic friction.
///    Computed on request as 1/2 dtau^T H^-1 dtau, dtau = H (qdd* - qdd_free) the command plus the
///    resting joints' friction and limit torques, by one articulated pass on the last solve's
///    inertias (HdSolver::inverseInertiaTimes; a fraction of a solve). NaN before a successful
///    solve; Inf or NaN when the value is beyond the double range (friction or torques times
///    accelerations near 1e300). The Python API raises then.
///  * iterations(): active-set iterations of the last solve's box QP (at most 5 (k + 1) 3^k + 4, k
///    the resting joints with friction or on a limit; the argument is in friction_box_qp.cpp's
///    boxQp()). Bland's smallest-index rule takes over if a face-optimal value fails to decrease.
///    FrictionModel::max_iterations bounds them for real time (default 6 k + 16): at the bound
///    solve() returns E_DEGRADED (1, a result) with the fallback of docs/friction.md, "Real-time
///    bound": the last iterate scaled along the ray from zero to the dual's best point on it, so
///    every friction torque stays within its bound and friction does no positive work in sum.
/// No heap allocation in solve() or gaussValue().
/// Threads: as HdSolver (hd_solver.hpp, "Threads"): solve(), setRootAcceleration(),
/// setPassThrough(), clearPassThrough() and setOptions() entered while another thread is inside a
/// call on the same object return HdSolver::E_CONCURRENT_CALL without touching it (errorMessage()
/// belongs to the other call; HdSolver::strError() has the text); linkAccelerations() then returns
/// what it holds and gaussValue() NaN. One solver object per thread.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_model.hpp"
#include "vereshchagin/tree_hd_solver.hpp"

namespace vereshchagin {

namespace detail {
class FrictionCore;
}  // namespace detail

/// The hybrid dynamics solver with exact static joint friction (see the top of this file), on a chain
/// or a tree.
class FrictionSolver {
 public:
  /// Per joint after solve(): Moving (|qd_j| > velocity_tolerance), or at rest: Stick (qdd_j = 0),
  /// SlipPositive (qdd_j > 0) or SlipNegative (qdd_j < 0).
  enum JointStatus : signed char { Moving = 0, Stick = 1, SlipPositive = 2, SlipNegative = 3 };
  enum {
    E_DEGRADED = 1,             ///< a result with the documented fallback: FrictionModel::max_iterations was hit
    E_INVALID_FRICTION = -110,  ///< sizes, negative or non-finite values, kinetic > static
    E_NOT_CONVERGED = -111,     ///< the iteration bound was exceeded (not expected), or the task
                                ///< drives a joint into its limit (unbounded reaction)
  };

  /// On a serial chain, with ChainHdSolver's segment and joint order; root_acc and options as for
  /// ChainHdSolver.
  FrictionSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options = SolverOptions());
  /// The same on the tree below root_segment (empty: the tree's root), with TreeHdSolver's segment
  /// and joint order (tree_hd_solver.hpp).
  FrictionSolver(const KDL::Tree& tree, const KDL::Twist& root_acc, const SolverOptions& options = SolverOptions(),
                 const std::string& root_segment = std::string());

  /// alfa (6 x m) and f_ext (6 x n_segments or empty) as in HdSolver::solve(): any column-major
  /// matrix with 6 rows (or no columns), else E_SIZE_MISMATCH naming the argument. Returns 0,
  /// E_DEGRADED (a result with the real-time fallback; errorMessage() says so) or an error code
  /// (message in errorMessage(), emptied by a successful solve).
  int solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
            const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
            const Eigen::Ref<const Eigen::MatrixXd>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques,
            const FrictionModel& friction);
  /// The same with constraints on any segments (column c of alfa on segment segments(c); see
  /// ChainHdSolver's overload).
  int solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
            const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
            const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
            const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction);

  const Eigen::VectorXd& qdd() const;              ///< joint accelerations at the optimum (n)
  const Eigen::VectorXd& commandTorques() const;   ///< tau_cmd at the optimum (n), see the top of this file
  const Eigen::VectorXd& frictionTorques() const;  ///< friction torque on each joint (n)
  const Eigen::VectorXd& limitTorques() const;     ///< joint limit reactions (n)
  const std::vector<signed char>& status() const;  ///< JointStatus of each joint (n)
  Eigen::Map<const Eigen::VectorXd> nu() const;    ///< constraint force magnitudes at the optimum (m)
  /// Link accelerations at the optimum (base axes, tip origins): one outward pass on first request.
  const ChainHdSolver::Matrix6X& linkAccelerations();
  int constraintRank() const;  ///< constraint rank, as HdSolver::constraintRank()
  int iterations() const;      ///< active-set iterations of the last solve
  double gaussValue();         ///< Z0(qdd*) + sum_rest f_j |qdd*_j|, see the top of this file

  /// The underlying solver; after solve() it holds the solve without static friction (its
  /// accelerations are the optimum's once linkAccelerations() was called) — its responseColumns()
  /// are valid for the optimum too.
  HdSolver& hdSolver();
  /// The Model and Data of hdSolver() (hd_solver.hpp): solve(model(), data(), input) with
  /// input.friction set runs this same friction stage on that Data.
  const Model& model() const;
  Data& data();                                         ///< see model()
  const char* errorMessage() const;                     ///< detail of the last error (empty after a successful solve)
  int modelError() const;                               ///< the model's error code, as HdSolver::modelError()
  int setRootAcceleration(const KDL::Twist& root_acc);  ///< 0 or E_CONCURRENT_CALL
  /// Driver pass-through weights as ChainHdSolver::setPassThrough: they weight f_ext and
  /// ff_torques only; friction (kinetic and the max-min's static) is always compensated along the
  /// constraints. Returns ChainHdSolver's codes (message in errorMessage()).
  int setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                     const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through);
  int clearPassThrough();                        ///< 0 or E_CONCURRENT_CALL
  int setOptions(const SolverOptions& options);  ///< as HdSolver::setOptions(), or E_CONCURRENT_CALL

  ~FrictionSolver();
  FrictionSolver(FrictionSolver&&) noexcept;             ///< moves the solver (model, workspace, results)
  FrictionSolver& operator=(FrictionSolver&&) noexcept;  ///< moves the solver (model, workspace, results)

 private:
  detail::FrictionCore& core() const;
  int solveEntered(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                   const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                   const Eigen::Ref<const Eigen::VectorXi>* segments, const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
                   const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction);

  std::unique_ptr<HdSolver> hd_;                // ChainHdSolver or TreeHdSolver: Model and Data
  std::unique_ptr<detail::FrictionCore> core_;  // the friction stage on hd_'s core (friction_core.hpp)
};

}  // namespace vereshchagin
