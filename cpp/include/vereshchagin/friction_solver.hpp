// Popov-Vereshchagin hybrid dynamics with static (breakaway) joint friction, solved exactly.
//
// Problem (Vereshchagin's max-min as in D. Vukcevic, TR 03-2018, H-BRS 2018; stated in full in
// docs/friction.md): joints at rest (|qd_j| <= velocity_tolerance) with breakaway
// friction f_j > 0 get the friction torque -mu_j, |mu_j| <= f_j, that maximises the dissipation:
//
//   qdd* = argmin_qdd  Z0(qdd) + sum_{j at rest} f_j |qdd_j|   subject to the task,
//   mu*  = argmax_{|mu| <= f}  g(mu),  g(mu) = c^T mu - 1/2 mu^T Q mu,
//
// with Z0 the frictionless Gauss function, Q = W G W^T (G the constrained inverse inertia of
// HdSolver::responseColumns, W the selection of resting joints) and c = W qdd(0). Moving
// joints get the kinetic (Coulomb) friction -fk_j sign(qd_j) as a feed-forward torque.
//
// Method: one full solve, the response columns of the resting joints (O(n) each, no
// refactorisation; half the outward work when every joint rests, G being symmetric), then the
// k x k box QP by an active-set method (exact: complementarity holds to round-off; singular Q
// handled through zero-curvature directions): a few primal-dual working-set rounds on definite
// faces, then primal steps whose free-set L D L^T follows each newly bound variable by a
// rank-one update. When several mu give the same qdd* (the task fixes some resting joints'
// accelerations), the one minimising the motor command ||tau_cmd||^2 is chosen (a least-distance
// problem on the optimal face, solved in the range space of Q_StSt): static friction holds what
// it can and the motors add only the rest.
//
// Units, frames, segment and joint order are those of the underlying HdSolver (ChainHdSolver for
// a chain, TreeHdSolver for a tree; hd_solver.hpp). Outputs after solve():
//  * qdd (n): joint accelerations.
//  * commandTorques (n): tau_cmd = -J^T alfa nu at the optimum: what the motors add to
//    ff_torques. Forward dynamics with ff_torques + tau_cmd + frictionTorques reproduces qdd.
//  * frictionTorques (n): the physical friction torque on each joint (-mu* at rest, at most f_j
//    in size; -fk sign(qd) when moving).
//  * limitTorques (n): the reaction of joint limits (>= 0 at a lower limit, <= 0 at an upper
//    one): what friction cannot hold of the total -mu* at a joint resting on its limit.
//  * status (n): Moving, Stick, SlipPositive (qdd > 0) or SlipNegative (qdd < 0).
//  * nu, constraint rank: as HdSolver at the optimum.
//  * gaussValue(): Z0(qdd*) + sum_rest f_j |qdd*_j|, with Z0(qdd) = 1/2 (qdd - qdd_free)^T H
//    (qdd - qdd_free) and qdd_free the unconstrained motion under ff_torques and kinetic friction.
//    Computed on request as 1/2 dtau^T H^-1 dtau, dtau = H (qdd* - qdd_free) the command plus the
//    resting joints' friction and limit torques, by one articulated pass on the last solve's
//    inertias (HdSolver::inverseInertiaTimes; a fraction of a solve). NaN before a successful
//    solve; Inf or NaN when the value is beyond the double range (friction or torques times
//    accelerations near 1e300). The Python API raises then.
//  * iterations(): active-set iterations of the last solve (at most 5 (k + 1) 3^k + 4, k the
//    resting joints with friction or on a limit; the argument is in friction_solver.cpp's
//    boxQp()). Bland's smallest-index rule takes over if a face-optimal value fails to decrease.
// No heap allocation in solve() or gaussValue().
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/tree_hd_solver.hpp"

namespace vereshchagin {

struct FrictionModel {
  Eigen::VectorXd static_friction;   // f_j >= 0 per joint (N m or N)
  Eigen::VectorXd kinetic_friction;  // 0 <= fk_j <= f_j per joint; empty: equal to static_friction
  double velocity_tolerance = 1e-6;  // |qd_j| at or below this: the joint is at rest
  // Joint position limits (Vukcevic 2018, sec. 5.2: a second dissipative force). A joint at rest
  // with q_j <= lower_j + limit_tolerance (or >= upper_j - limit_tolerance) gets, in the same
  // optimisation, a one-sided reaction that stops it from moving further into the limit (no
  // bound on its size). Empty vectors: no limits; +-infinity entries: no limit on that side.
  Eigen::VectorXd lower, upper;
  double limit_tolerance = 1e-9;
};

class FrictionSolver {
 public:
  enum JointStatus : signed char { Moving = 0, Stick = 1, SlipPositive = 2, SlipNegative = 3 };
  enum {
    E_INVALID_FRICTION = -110,  // sizes, negative or non-finite values, kinetic > static
    E_NOT_CONVERGED = -111,     // the iteration bound was exceeded (not expected), or the task
                                // drives a joint into its limit (unbounded reaction)
  };

  FrictionSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options = SolverOptions());
  // The same on the tree below root_segment (empty: the tree's root), with TreeHdSolver's segment
  // and joint order (tree_hd_solver.hpp).
  FrictionSolver(const KDL::Tree& tree, const KDL::Twist& root_acc, const SolverOptions& options = SolverOptions(),
                 const std::string& root_segment = std::string());

  int solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
            const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
            const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques,
            const FrictionModel& friction);
  // The same with constraints on any segments (column c of alfa on segment segments(c); see
  // ChainHdSolver's overload).
  int solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
            const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
            const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
            const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction);

  const Eigen::VectorXd& qdd() const { return qdd_; }
  const Eigen::VectorXd& commandTorques() const { return tau_cmd_; }
  const Eigen::VectorXd& frictionTorques() const { return friction_; }
  const Eigen::VectorXd& limitTorques() const { return limit_; }
  const std::vector<signed char>& status() const { return status_; }
  Eigen::Map<const Eigen::VectorXd> nu() const { return Eigen::Map<const Eigen::VectorXd>(nu_.data(), m_keep_); }
  // Link accelerations at the optimum (base axes, tip origins): one extra solve on first request.
  const ChainHdSolver::Matrix6X& linkAccelerations();
  int constraintRank() const { return hd_.constraintRank(); }
  int iterations() const { return iterations_; }
  double gaussValue();

  // The underlying solver; after solve() it holds the solve without static friction (before
  // linkAccelerations() is called) — its responseColumns() are valid for the optimum too.
  HdSolver& hdSolver() { return hd_; }
  const char* errorMessage() const { return message_.data(); }
  int modelError() const { return hd_.modelError(); }
  void setRootAcceleration(const KDL::Twist& root_acc) { hd_.setRootAcceleration(root_acc); }
  // Driver pass-through weights as ChainHdSolver::setPassThrough: they weight f_ext and
  // ff_torques only; friction (kinetic and the max-min's static) is always compensated along the
  // constraints. Returns ChainHdSolver's codes (message in errorMessage()).
  int setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                     const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through);
  void clearPassThrough() { hd_.clearPassThrough(); }
  int setOptions(const SolverOptions& options);

 private:
  explicit FrictionSolver(std::unique_ptr<HdSolver> hd);
  int fail(int code, const char* fmt, ...);
  int solveImpl(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                const Eigen::Ref<const Eigen::VectorXi>* segments,
                const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction);
  // The hybrid-dynamics solve of the current problem with joint torques tau (segments or not).
  int hdSolve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
              const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
              const Eigen::Ref<const Eigen::VectorXi>* segments, const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
              const Eigen::Ref<const Eigen::VectorXd>& tau);
  // The stages of solveImpl: the friction model's checks; the resting joints (rest_, their bounds
  // lo_ / hi_, kinetic friction into tau0_), returning their number k; the max-min over them from
  // hd_'s solve without static friction (boxQp, leastCommand, outputs updated affinely); the
  // friction and limit torques and the status per joint.
  int checkFriction(const FrictionModel& friction);
  int restingJoints(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction);
  int optimiseResting(int k);
  void frictionOutputs(const Eigen::Ref<const Eigen::VectorXd>& q_dot, const FrictionModel& friction, int k);
  int boxQp(int k);          // stage 1 on Q_, c_, lo_, hi_ -> x_
  void leastCommand(int k);  // stage 2: tie-break on the optimal face
  // Stage 2's solvers on the sticking set (ns joints, Q_StSt = V_ V_^T of rank r < ns), from
  // ys_ = x*_St with target ts_ and bounds p_ / eig_ (see leastCommand).
  void leastOnLine(int ns, int r);                    // ns - r = 1: closed form
  void leastActiveSet(int ns, int r, double yscale);  // range-space primal active set
  int projectOffRange(int ns, int r);                 // its steps (friction_solver.cpp)
  bool stepToBound(int ns, double step_tol);
  void faceMultipliers(int r, int rf);
  int releaseIndex(int ns, int r, double mult_tol, bool bland) const;
  // Subproblem on the free set: p = -Q_FF^+ g_F, and a zero-curvature descent direction d
  // (returns true) when g_F has a component in null(Q_FF).
  bool freeStep(int nf);
  void gradient(int k);
  void factorDelete(int q, int nf);

  std::unique_ptr<HdSolver> hd_owner_;  // the solver of the problem
  HdSolver& hd_;
  unsigned int nj_ = 0;
  std::array<char, 512> message_{};
  Eigen::VectorXd qdd_, tau_cmd_, friction_, limit_, tau0_, qdd0_, tau_cmd0_, nu0_, nu_;
  Eigen::VectorXd ff_driver_;  // ff_torques of the last solve (zero if empty): hd_'s pass-through driver
  Eigen::MatrixXd dnu_;
  int m_keep_ = 0, k_ = 0;
  bool link_acc_known_ = false;
  std::vector<signed char> status_;
  int iterations_ = 0;
  double qscale_ = 0.0;          // scale of Q (see solve())
  double gscale_ = 0.0;          // scale of the QP gradient (see boxQp())
  bool free_full_rank_ = false;  // the last free-set factorisation had full rank
  bool solved_ = false;
  Eigen::VectorXd fstatic_;  // static friction of the last solve (gaussValue())
  // Optimisation workspace (k <= n resting joints).
  Eigen::VectorXi rest_;                    // joint index of each resting joint
  Eigen::MatrixXd Gc_, Tc_, Q_, work_, L_;  // Tc_ stays empty (0 x 0): tau_cmd follows from nu
  Eigen::VectorXd c_, x_, lo_, hi_, grad_, p_, d_, tmp_, tmp2_, eig_, invdiag_, dpiv_;
  // Free-set factor L D L^T kept across blocked steps (freeStep / factorDelete): valid for the
  // free set of size factor_n_, rank factor_r_ (n or n - 1, then remainder_ is the last pivot).
  bool factor_valid_ = false;
  bool tau_cmd_known_ = false;  // leastCommand() left tau_cmd_ at the final x
  int factor_n_ = 0, factor_r_ = 0;
  double remainder_ = 0.0;
  Eigen::VectorXi state_, free_idx_, rows_;
  // Stage-2 workspace (leastCommand): Q_StSt = V V^T (V ns x r); the iterate y and target t on
  // St; U R = V_F (column-pivoted QR of V with the held rows zeroed, U's columns kept at V's
  // column index); lam_ the face multipliers of V^T y = const; side_ the working set; cols_ / piv_
  // the QR's and the Cholesky's pivot orders.
  Eigen::MatrixXd V_, U_, R_;
  Eigen::VectorXd ys_, ts_, lam_;
  Eigen::VectorXi side_, cols_, piv_;
};

}  // namespace vereshchagin
