// The private side of FrictionSolver: its workspace, results and stages (math in
// friction_solver.hpp; stage 1, the box QP, in friction_box_qp.cpp; stage 2, the least-command
// tie-break, in friction_least_command.cpp).
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "vereshchagin/friction_solver.hpp"

#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Curvatures (eigenvalues of Q, Cholesky pivots) below this fraction of Q's scale are zero.
constexpr double kZeroCurvature = 1e-10;
// Gradient entries (accelerations) below this fraction of the gradient's scale are zero.
constexpr double kGradientTolerance = 1e-11;
// The real-time default of FrictionModel::max_iterations = -1: this many iterations per resting
// joint plus the base, per stage (docs/friction.md, "Real-time bound", has the measurements).
constexpr long kDefaultIterationsPerJoint = 6;
constexpr long kDefaultIterationsBase = 16;
// The exhaustive bound (P + 1) (k + 1) 3^k + P of the box QP (friction_box_qp.cpp), capped at 1e8.
long exhaustiveIterationBound(int k);

// One joint's friction in a solve (shared by the friction stage and the contact stage so that both
// read a FrictionModel alike): moving when |qd_j| exceeds the velocity tolerance; f its bound, the
// kinetic friction while moving and the static one at rest (0 for an empty model); on a lower or
// upper limit (at rest only). At the instant a moving joint's friction is the known torque
// -f sign(qd_j); at rest, or over a time step, the joint is an unknown when f > 0 or on a limit.
struct JointFriction {
  bool moving = false, at_lower = false, at_upper = false;
  double f = 0.0;
  bool unknown(double dt) const { return (!moving || dt > 0.0) && (f > 0.0 || at_lower || at_upper); }
};

inline JointFriction jointFriction(const FrictionModel& m, long j, double q, double q_dot) {
  const Eigen::VectorXd& fk = m.kinetic_friction.size() ? m.kinetic_friction : m.static_friction;
  JointFriction out;
  out.moving = std::abs(q_dot) > m.velocity_tolerance;
  const Eigen::VectorXd& bound = out.moving ? fk : m.static_friction;
  out.f = bound.size() ? bound(j) : 0.0;  // (an empty model: none)
  const bool limits = !out.moving && m.lower.size() != 0;
  out.at_lower = limits && q <= m.lower(j) + m.limit_tolerance;
  out.at_upper = limits && q >= m.upper(j) - m.limit_tolerance;
  return out;
}

class FrictionCore {
 public:
  using JointStatus = FrictionSolver::JointStatus;
  static constexpr JointStatus Moving = FrictionSolver::Moving, Stick = FrictionSolver::Stick,
                               SlipPositive = FrictionSolver::SlipPositive, SlipNegative = FrictionSolver::SlipNegative;
  static constexpr int E_INVALID_FRICTION = FrictionSolver::E_INVALID_FRICTION,
                       E_NOT_CONVERGED = FrictionSolver::E_NOT_CONVERGED;

  // The friction stage on `hd` (a Data's core): workspace O(n^2 + n m).
  explicit FrictionCore(HdCore& hd);
  // The core to run on (a face's Data is replaced when its options change); resizes for its
  // constraint capacity (not on the solve path).
  void bind(HdCore& hd);
  const ChainHdSolver::Matrix6X& linkAccelerations();
  double gaussValue();
  int fail(int code, const char* fmt, ...);
  int failFromHd(int rc);  // hd_'s error with its message (unless hd_ is busy in another thread)
  int solveImpl(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                const Eigen::Ref<const Eigen::VectorXi>* segments,
                const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction,
                double time_step = 0.0);
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
  int restingProblem(int k);  // optimiseResting's data: base, response columns, Q_, c_, qscale_
  void applyResting(int k);   // optimiseResting's outputs at x_: qdd_, nu_, tau_cmd_
  void frictionOutputs(const Eigen::Ref<const Eigen::VectorXd>& q_dot, const FrictionModel& friction, int k);
  // Over a step, the slide guess (friction_step_guess.cpp): from hd_'s solve with every guessed
  // slide's kinetic friction in tau0_ and the k resting joints in rest_, the rounds of refuting
  // guesses and solving the box QP on the rest; k becomes the final number of unknowns.
  int optimiseStep(int& k);
  int refuteSlides();                // clears slide_ (marks 2) of each guess its end velocity refutes; how many
  int mergeRefuted(int k);           // the refuted guesses into rest_ (joint order kept); the new k
  int stepFallback(int& k);          // boxQp's bound hit in a round: the fallback on the full problem (its k)
  int boxQp(int k);                  // stage 1 on Q_, c_, lo_, hi_ -> x_
  long iterationBound(int k) const;  // iterations a stage on k unknowns may spend (max_iterations_)
  long iterationEnd(int k) const;    // where boxQp's count (iterations_ on entry) stops (iterationBound)
  void boxQpFallback(int k);         // stage 1's real-time fallback at its bound (sets x_)
  void leastCommand(int k);          // stage 2: tie-break on the optimal face
  // Stage 2's solvers on the sticking set (ns joints, Q_StSt = V_ V_^T of rank r < ns), from
  // ys_ = x*_St with target ts_ and bounds p_ / eig_ (see leastCommand).
  void leastOnLine(int ns, int r);                    // ns - r = 1: closed form
  bool leastActiveSet(int ns, int r, double yscale);  // range-space primal active set (false: bound hit)
  int projectOffRange(int ns, int r);                 // its steps (friction_least_command.cpp)
  bool stepToBound(int ns, double step_tol);
  void faceMultipliers(int r, int rf);
  int releaseIndex(int ns, int r, double mult_tol, bool bland) const;
  // Subproblem on the free set: p = -Q_FF^+ g_F, and a zero-curvature descent direction d
  // (returns true) when g_F has a component in null(Q_FF).
  bool freeStep(int nf);
  bool primalDualRound(int k, int nf, double tol_g);
  // One unknown of positive curvature: boxQp's answer and counts without its machinery (false:
  // not that case, boxQp iterates).
  bool boxQpOne(double cmax, double torque_scale, long max_iterations);
  // Two unknowns whose Newton step from 0 stays in the box: boxQp's first round, inline.
  bool boxQpTwo(double cmax, double torque_scale, long max_iterations);
  bool qp_unique_ = false;  // boxQpOne / boxQpTwo answered: a strictly convex QP, no tie to break
  int primalStep(int nf, bool zero_curvature, bool& face_optimal);
  int wrongSignMultiplier(int k, double tol_g, bool bland) const;
  void gradient(int k);
  void factorDelete(int q, int nf);

  std::atomic<bool> busy_{false};  // a call is inside (entry_guard.hpp)
  HdCore* hd_;                     // the core of the problem (bind())
  unsigned int nj_ = 0;
  std::array<char, 512> message_{};
  Eigen::VectorXd qdd_, tau_cmd_, friction_, limit_, tau0_, qdd0_, tau_cmd0_, nu0_, nu_;
  Eigen::VectorXd ff_driver_;  // ff_torques of the last solve (zero if empty): hd_'s pass-through driver
  Eigen::MatrixXd dnu_;
  int m_keep_ = 0;
  bool link_acc_known_ = false;
  std::vector<signed char> status_;
  int iterations_ = 0;
  int max_iterations_ = -1;      // FrictionModel::max_iterations of the current solve
  int degraded_ = 0;             // the bound was hit: 0 no, 1 in the box QP, 2 in the least command
  double qscale_ = 0.0;          // scale of Q (see solve())
  double gscale_ = 0.0;          // scale of the QP gradient (see boxQp())
  bool free_full_rank_ = false;  // the last free-set factorisation had full rank
  bool solved_ = false;
  // A solve over a time step dt (SolveInput::time_step; 0: the instant): every joint with friction
  // is resting-like (bounded by its static friction at rest, its kinetic one while moving), its
  // row qdd_j + qd_j / dt (shift_ = qd / dt: the QP's c is shifted by it).
  double dt_ = 0.0;
  Eigen::VectorXd shift_;
  // The slide guess over a step (friction_step_guess.cpp): each moving joint with friction is
  // first taken as sliding through the step with its kinetic friction, x = xg_ = F sign(qd) (its
  // friction torque -xg_ in tau0_); slide_ 1 while the guess stands, 2 refuted and not yet in
  // rest_, 0 otherwise. step_k_ is the full problem's number of unknowns (every joint with
  // friction or on a limit; -1 at the instant), row_scale_ the guess solve's largest end-velocity
  // row (a scale for boxQp, 0 at the instant), bound_ the iteration end boxQp last used.
  Eigen::VectorXd xg_;
  std::vector<char> slide_;
  int step_k_ = -1;
  double row_scale_ = 0.0;
  long bound_ = 0;
  Eigen::VectorXd fbound_;  // each resting joint's friction bound of the last solve (gaussValue())
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

}  // namespace detail
}  // namespace vereshchagin
