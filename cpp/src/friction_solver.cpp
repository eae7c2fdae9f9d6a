// Static-friction max-min on top of the Popov-Vereshchagin solver. Math in friction_solver.hpp.
#include "vereshchagin/friction_solver.hpp"

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <utility>

#include "entry_guard.hpp"
#include "facade_state.hpp"
#include "friction_core.hpp"
#include "hd_core.hpp"
#include "model_validation.hpp"

namespace vereshchagin {

// The public API: a ChainHdSolver or TreeHdSolver face (its Model and Data) and the friction
// stage on that Data's core.
FrictionSolver::FrictionSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options)
    : hd_(std::make_unique<ChainHdSolver>(chain, root_acc, options)),
      core_(std::make_unique<detail::FrictionCore>(hd_->core())) {}

FrictionSolver::FrictionSolver(const KDL::Tree& tree, const KDL::Twist& root_acc, const SolverOptions& options,
                               const std::string& root_segment)
    : hd_(std::make_unique<TreeHdSolver>(tree, root_acc, options, root_segment)),
      core_(std::make_unique<detail::FrictionCore>(hd_->core())) {}

FrictionSolver::~FrictionSolver() = default;
FrictionSolver::FrictionSolver(FrictionSolver&&) noexcept = default;
FrictionSolver& FrictionSolver::operator=(FrictionSolver&&) noexcept = default;

namespace {

using detail::EntryGuard;
using detail::sixRows;

}  // namespace

// The friction stage bound to the face's current core (setOptions() may have replaced it).
detail::FrictionCore& FrictionSolver::core() const {
  core_->bind(hd_->core());
  return *core_;
}

int FrictionSolver::solveEntered(const Eigen::Ref<const Eigen::VectorXd>& q,
                                 const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                                 const Eigen::Ref<const Eigen::MatrixXd>& alfa,
                                 const Eigen::Ref<const Eigen::VectorXd>& beta,
                                 const Eigen::Ref<const Eigen::VectorXi>* segments,
                                 const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
                                 const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  detail::FrictionCore& c = core();
  const EntryGuard hd_guard(hd_->core().busy);
  if (!hd_guard) return c.failFromHd(HdSolver::E_CONCURRENT_CALL);
  if (const int rc = hd_->solveArgsProblem(alfa, f_ext)) return c.failFromHd(rc);
  hd_->state().install();
  return c.solveImpl(q, q_dot, sixRows(alfa), beta, segments, sixRows(f_ext), ff_torques, friction);
}

int FrictionSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                          const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
                          const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  const EntryGuard guard(core_->busy_);
  if (!guard) return HdSolver::E_CONCURRENT_CALL;
  return solveEntered(q, q_dot, alfa, beta, nullptr, f_ext, ff_torques, friction);
}

int FrictionSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                          const Eigen::Ref<const Eigen::VectorXi>& segments,
                          const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
                          const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  const EntryGuard guard(core_->busy_);
  if (!guard) return HdSolver::E_CONCURRENT_CALL;
  return solveEntered(q, q_dot, alfa, beta, &segments, f_ext, ff_torques, friction);
}

const Eigen::VectorXd& FrictionSolver::qdd() const {
  return core_->qdd_;
}
const Eigen::VectorXd& FrictionSolver::commandTorques() const {
  return core_->tau_cmd_;
}
const Eigen::VectorXd& FrictionSolver::frictionTorques() const {
  return core_->friction_;
}
const Eigen::VectorXd& FrictionSolver::limitTorques() const {
  return core_->limit_;
}
const std::vector<signed char>& FrictionSolver::status() const {
  return core_->status_;
}
Eigen::Map<const Eigen::VectorXd> FrictionSolver::nu() const {
  return Eigen::Map<const Eigen::VectorXd>(core_->nu_.data(), core_->m_keep_);
}
const ChainHdSolver::Matrix6X& FrictionSolver::linkAccelerations() {
  const EntryGuard guard(core_->busy_);
  if (!guard) return hd_->linkAccelerations();  // another thread is inside: what hd_ holds
  return core().linkAccelerations();
}
int FrictionSolver::constraintRank() const {
  return hd_->constraintRank();
}
int FrictionSolver::iterations() const {
  return core_->iterations_;
}
double FrictionSolver::gaussValue() {
  const EntryGuard guard(core_->busy_);
  if (!guard) return std::numeric_limits<double>::quiet_NaN();  // another thread is inside
  return core().gaussValue();
}
HdSolver& FrictionSolver::hdSolver() {
  return *hd_;
}
const Model& FrictionSolver::model() const {
  return hd_->model();
}
Data& FrictionSolver::data() {
  return hd_->data();
}
const char* FrictionSolver::errorMessage() const {
  return core_->message_.data();
}
int FrictionSolver::modelError() const {
  return hd_->modelError();
}
int FrictionSolver::setRootAcceleration(const KDL::Twist& root_acc) {
  const EntryGuard guard(core_->busy_);
  if (!guard) return HdSolver::E_CONCURRENT_CALL;
  return hd_->setRootAcceleration(root_acc);
}
int FrictionSolver::setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                                   const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through) {
  const EntryGuard guard(core_->busy_);
  if (!guard) return HdSolver::E_CONCURRENT_CALL;
  const int rc = hd_->setPassThrough(f_ext_pass_through, ff_pass_through);
  if (rc != HdSolver::E_NOERROR) return core().failFromHd(rc);
  core_->solved_ = false;
  return rc;
}
int FrictionSolver::clearPassThrough() {
  const EntryGuard guard(core_->busy_);
  if (!guard) return HdSolver::E_CONCURRENT_CALL;
  return hd_->clearPassThrough();
}
int FrictionSolver::setOptions(const SolverOptions& options) {
  const EntryGuard guard(core_->busy_);
  if (!guard) return HdSolver::E_CONCURRENT_CALL;
  const int rc = hd_->setOptions(options);
  detail::FrictionCore& c = core();  // resized for a new constraint capacity
  if (rc != HdSolver::E_NOERROR) return c.failFromHd(rc);
  return rc;
}

namespace detail {

FrictionCore::FrictionCore(HdCore& hd) : hd_(&hd) {
  nj_ = hd.model.nj;
  const int n = static_cast<int>(nj_);
  qdd_ = tau_cmd_ = friction_ = limit_ = tau0_ = qdd0_ = tau_cmd0_ = ff_driver_ = Eigen::VectorXd::Zero(n);
  fbound_ = shift_ = xg_ = Eigen::VectorXd::Zero(n);
  slide_.assign(static_cast<std::size_t>(n), 0);
  status_.assign(n, Moving);
  rest_ = state_ = free_idx_ = rows_ = Eigen::VectorXi::Zero(n);
  Gc_ = Q_ = work_ = L_ = Eigen::MatrixXd::Zero(n, n);
  V_ = U_ = R_ = Eigen::MatrixXd::Zero(n, n);
  ys_ = ts_ = lam_ = Eigen::VectorXd::Zero(n);
  side_ = cols_ = piv_ = Eigen::VectorXi::Zero(n);
  c_ = x_ = lo_ = hi_ = grad_ = p_ = d_ = tmp_ = tmp2_ = eig_ = invdiag_ = dpiv_ = Eigen::VectorXd::Zero(n);
  bind(hd);
}

void FrictionCore::bind(HdCore& hd) {
  hd_ = &hd;
  const int mcap = hd.mcap;
  if (dnu_.rows() != mcap) {  // the constraint capacity changed (not on the solve path)
    dnu_ = Eigen::MatrixXd::Zero(mcap, static_cast<int>(nj_));
    nu0_ = nu_ = Eigen::VectorXd::Zero(mcap);
  }
}

int FrictionCore::failFromHd(int rc) {
  if (rc == HdSolver::E_CONCURRENT_CALL)  // hd_'s message belongs to the other thread's call
    return fail(rc,
                "the underlying solver (hdSolver()) is in use by another thread: a solver object must not be used "
                "from two threads at once (use one solver per thread)");
  return fail(rc, "%s", hd_->message.data());
}

int FrictionCore::fail(int code, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(message_.data(), message_.size(), fmt, args);
  va_end(args);
  solved_ = false;
  return code;
}

int FrictionCore::hdSolve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa,
                          const Eigen::Ref<const Eigen::VectorXd>& beta,
                          const Eigen::Ref<const Eigen::VectorXi>* segments,
                          const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                          const Eigen::Ref<const Eigen::VectorXd>& tau) {
  // The pass-through's feed-forward driver is ff_torques alone, not the friction in tau.
  hd_->ws.pt.driver = &ff_driver_;
  const int rc = segments ? hd_->solveSegments(q, q_dot, alfa, beta, *segments, f_ext, tau)
                          : hd_->solveLast(q, q_dot, alfa, beta, f_ext, tau);
  hd_->ws.pt.driver = nullptr;
  if (rc == ChainHdSolver::E_NOERROR) hd_->message[0] = '\0';
  return rc;
}

// Stage 0: the friction model's sizes and values (0 or E_INVALID_FRICTION with a message).
int FrictionCore::checkFriction(const FrictionModel& friction) {
  const long n = nj_;
  if (friction.max_iterations < -1)
    return fail(E_INVALID_FRICTION,
                "friction.max_iterations must be -1 (the real-time default), 0 (exhaustive) or > 0, got %d",
                friction.max_iterations);
  if (friction.empty()) return ChainHdSolver::E_NOERROR;  // no friction (restingJoints reads zeros)
  const Eigen::VectorXd& fs = friction.static_friction;
  const Eigen::VectorXd& fk = friction.kinetic_friction.size() ? friction.kinetic_friction : friction.static_friction;
  if (fs.size() != n)
    return fail(E_INVALID_FRICTION, "friction.static_friction has %ld entries, expected %ld (joints)", (long)fs.size(),
                n);
  if (fk.size() != n)
    return fail(E_INVALID_FRICTION, "friction.kinetic_friction has %ld entries, expected %ld (joints) or 0",
                (long)fk.size(), n);
  if (!std::isfinite(friction.velocity_tolerance) || friction.velocity_tolerance < 0.0)
    return fail(E_INVALID_FRICTION, "friction.velocity_tolerance must be finite and >= 0, got %g",
                friction.velocity_tolerance);
  for (long j = 0; j < n; ++j) {
    if (!std::isfinite(fs(j)) || fs(j) < 0.0)
      return fail(E_INVALID_FRICTION, "friction.static[%ld] (static_friction(%ld)) must be finite and >= 0, got %g", j,
                  j, fs(j));
    if (!std::isfinite(fk(j)) || fk(j) < 0.0 || fk(j) > fs(j))
      return fail(E_INVALID_FRICTION,
                  "friction.kinetic[%ld] (kinetic_friction(%ld)) must be in [0, friction.static[%ld] = %g] (kinetic "
                  "<= static), got %g",
                  j, j, j, fs(j), fk(j));
  }
  if (friction.lower.size() == 0 && friction.upper.size() == 0) return ChainHdSolver::E_NOERROR;
  if (friction.lower.size() != n || friction.upper.size() != n)
    return fail(E_INVALID_FRICTION, "friction.lower and friction.upper must have %ld entries each (or both be empty)",
                n);
  if (!std::isfinite(friction.limit_tolerance) || friction.limit_tolerance < 0.0)
    return fail(E_INVALID_FRICTION, "friction.limit_tolerance must be finite and >= 0, got %g",
                friction.limit_tolerance);
  for (long j = 0; j < n; ++j)
    if (std::isnan(friction.lower(j)) || std::isnan(friction.upper(j)) || friction.lower(j) > friction.upper(j))
      return fail(E_INVALID_FRICTION,
                  "friction.lower[%ld] and friction.upper[%ld] (friction.lower(%ld), friction.upper(%ld)) must satisfy "
                  "lower <= upper, neither NaN, got %g > %g",
                  j, j, j, j, friction.lower(j), friction.upper(j));
  return ChainHdSolver::E_NOERROR;
}

// Stage 1: kinetic friction of moving joints as feed-forward (into tau0_); the resting joints
// with friction or on a limit into rest_, with the bounds of their mu (friction torque -mu):
// [-f, f], opened to -inf at a lower limit (the reaction pushes up) and to +inf at an upper one.
// Over a time step every joint with friction goes into rest_ (f: kinetic while moving) and its
// row is shifted by qd / dt (shift_); of those, the moving ones are first guessed sliding (slide_,
// their kinetic friction in tau0_, not in rest_: friction_step_guess.cpp). Returns k.
int FrictionCore::restingJoints(const Eigen::Ref<const Eigen::VectorXd>& q,
                                const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                                const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction) {
  int k = 0;
  step_k_ = dt_ > 0.0 ? 0 : -1;
  row_scale_ = 0.0;
  for (long j = 0; j < static_cast<long>(nj_); ++j) {
    tau0_(j) = ff_driver_(j) = ff_torques.size() ? ff_torques(j) : 0.0;
    shift_(j) = dt_ > 0.0 ? q_dot(j) / dt_ : 0.0;
    fbound_(j) = xg_(j) = 0.0;
    slide_[static_cast<std::size_t>(j)] = 0;
    const JointFriction jf = jointFriction(friction, j, q(j), q_dot(j));
    if (jf.moving && dt_ == 0.0) {
      tau0_(j) -= jf.f * (q_dot(j) > 0.0 ? 1.0 : -1.0);
      continue;
    }
    // At rest, or over a time step (friction against the end velocity, kinetic while moving).
    if (jf.unknown(dt_) && jf.moving) {  // (over a step only): the slide guess
      ++step_k_;
      fbound_(j) = jf.f;
      xg_(j) = jf.f * (q_dot(j) > 0.0 ? 1.0 : -1.0);
      tau0_(j) -= xg_(j);
      slide_[static_cast<std::size_t>(j)] = 1;
    } else if (jf.unknown(dt_)) {
      step_k_ += dt_ > 0.0 ? 1 : 0;
      lo_(k) = jf.at_lower ? -kInf : -jf.f;
      hi_(k) = jf.at_upper ? kInf : jf.f;
      fbound_(j) = jf.f;
      rest_(k++) = static_cast<int>(j);
    }
  }
  return k;
}

// Stage 2: the max-min over the k resting joints, from the solve without static friction in hd_:
// the box QP on Q = W G W^T, the least-command tie-break, and the outputs updated from the
// response columns (they are affine in the friction torques: no new solve).
int FrictionCore::optimiseResting(int k) {
  int rc = restingProblem(k);
  if (rc != ChainHdSolver::E_NOERROR) return rc;
  rc = boxQp(k);
  if (rc != ChainHdSolver::E_NOERROR) return rc;
  tau_cmd_known_ = false;
  // (The tie-break is for the optimal face only; a strictly convex QP has one optimum.)
  if (degraded_ == 0 && !qp_unique_) leastCommand(k);
  applyResting(k);
  return ChainHdSolver::E_NOERROR;
}

// The box QP's data for the k joints in rest_: the base qdd0_ / nu0_ / tau_cmd0_ without their
// friction (hd_'s solve, plus back the friction of guessed slides now in rest_), the response
// columns Gc_ / dnu_, Q_, c_ and qscale_.
int FrictionCore::restingProblem(int k) {
  qdd0_ = hd_->res.qdd;
  tau_cmd0_ = hd_->res.tau_cmd;
  const int m = hd_->res.m;
  nu0_.head(m) = hd_->nu();
  // d qdd and d nu per resting joint; tau_cmd follows from nu (commandTorquesOf), so its columns
  // are not formed.
  Eigen::Ref<Eigen::MatrixXd> dnu = dnu_.leftCols(k);
  int rc = hd_->responseColumns(rest_.head(k), Gc_.leftCols(k), Tc_.leftCols(0), &dnu);
  if (rc != ChainHdSolver::E_NOERROR) return failFromHd(rc);
  if (dt_ > 0.0)  // (over a step) a refuted slide's guessed friction -xg_ was in hd_'s solve
    for (int a = 0; a < k; ++a)
      if (const double xg = xg_(rest_(a)); xg != 0.0) {
        qdd0_ += xg * Gc_.col(a);
        nu0_.head(m) += xg * dnu.col(a).head(m);
      }
  for (int a = 0; a < k; ++a) {
    c_(a) = qdd0_(rest_(a)) + shift_(rest_(a));  // (over a time step: the end velocity over dt)
    for (int b = 0; b < k; ++b) Q_(a, b) = 0.5 * (Gc_(rest_(a), b) + Gc_(rest_(b), a));
  }
  // Scale of Q for every "is it zero" decision: max over the resting joints of Q_jj and of
  // 1 / D_j <= (H^-1)_jj (a task can make Q vanish up to round-off; its entries are then no
  // scale for themselves).
  qscale_ = 0.0;
  for (int a = 0; a < k; ++a)
    qscale_ = std::max({qscale_, Q_(a, a), hd_->ws.seg[hd_->model.joint_segment[rest_(a)]].Dinv});  // (= 1 / D)
  for (unsigned int j = 0; j < nj_; ++j)  // (over a step) the standing guesses are unknowns too
    if (slide_[j] == 1) qscale_ = std::max(qscale_, hd_->ws.seg[hd_->model.joint_segment[j]].Dinv);
  return ChainHdSolver::E_NOERROR;
}

// The outputs at the friction x_ of the k joints in rest_: qdd_, nu_ and (unless leastCommand
// left it) tau_cmd_, affine from the base and the response columns.
void FrictionCore::applyResting(int k) {
  qdd_ = qdd0_;
  for (int a = 0; a < k; ++a) qdd_ -= x_(a) * Gc_.col(a);  // (k is small: no matrix-vector kernel)
  const int m = hd_->res.m;
  nu_.head(m) = nu0_.head(m);
  nu_.head(m).noalias() -= dnu_.topLeftCorner(m, k) * x_.head(k);
  if (!tau_cmd_known_) (void)hd_->commandTorquesOf(nu_.head(m), tau_cmd_);  // (else kept by leastCommand)
}

// Stage 3: friction and limit torques and the status of every joint at the optimum (k resting
// joints in rest_ with their -mu in x_).
void FrictionCore::frictionOutputs(const Eigen::Ref<const Eigen::VectorXd>& q_dot, const FrictionModel& friction,
                                   int k) {
  const long n = nj_;
  const Eigen::VectorXd& fs = friction.static_friction;
  const Eigen::VectorXd& fk = friction.kinetic_friction.size() ? friction.kinetic_friction : friction.static_friction;
  const double acc_scale = std::max(1.0, n ? qdd_.cwiseAbs().maxCoeff() : 0.0);  // (no joints: empty)
  int a = 0;
  for (long j = 0; j < n; ++j) {
    const bool moving = std::abs(q_dot(j)) > friction.velocity_tolerance;
    const double fsj = fs.size() ? fs(j) : 0.0, fkj = fk.size() ? fk(j) : 0.0;  // (empty: none)
    if (moving && dt_ == 0.0) {
      friction_(j) = -fkj * (q_dot(j) > 0.0 ? 1.0 : -1.0);
      limit_(j) = 0.0;
      status_[j] = Moving;
      continue;
    }
    friction_(j) = 0.0;
    limit_(j) = 0.0;
    const bool unknown = a < k && rest_(a) == j;
    if (unknown || slide_[static_cast<std::size_t>(j)] == 1) {  // (a standing slide guess: -xg_)
      // Friction holds what it can (up to its bound); a limit reaction takes the rest.
      const double total = unknown ? -x_(a++) : -xg_(j), f = moving ? fkj : fsj;
      friction_(j) = std::min(f, std::max(-f, total));
      limit_(j) = total - friction_(j);
    }
    const double row = qdd_(j) + shift_(j);  // the acceleration, or the end velocity over dt
    status_[j] = std::abs(row) <= 1e-9 * acc_scale ? Stick : moving ? Moving : row > 0.0 ? SlipPositive : SlipNegative;
  }
}

int FrictionCore::solveImpl(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                            const Eigen::Ref<const ChainHdSolver::Matrix6X>& alfa,
                            const Eigen::Ref<const Eigen::VectorXd>& beta,
                            const Eigen::Ref<const Eigen::VectorXi>* segments,
                            const Eigen::Ref<const ChainHdSolver::Matrix6X>& f_ext,
                            const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const FrictionModel& friction,
                            double time_step) {
  solved_ = false;
  dt_ = time_step;
  const long n = nj_;
  int rc = checkFriction(friction);
  if (rc != ChainHdSolver::E_NOERROR) return rc;
  if (q.size() != n || q_dot.size() != n || (ff_torques.size() != n && ff_torques.size() != 0) || !q_dot.allFinite() ||
      !q.allFinite()) {
    // Let the hybrid-dynamics solver report the size or value problem with its message.
    rc = hdSolve(q, q_dot, alfa, beta, segments, f_ext, ff_torques);
    return failFromHd(rc);
  }
  int k = restingJoints(q, q_dot, ff_torques, friction);
  rc = hdSolve(q, q_dot, alfa, beta, segments, f_ext, tau0_);
  if (rc != ChainHdSolver::E_NOERROR) return failFromHd(rc);
  iterations_ = 0;
  max_iterations_ = friction.max_iterations;
  degraded_ = 0;
  if (dt_ > 0.0) {
    rc = optimiseStep(k);
    if (rc != ChainHdSolver::E_NOERROR) return rc;
  } else if (k > 0) {
    rc = optimiseResting(k);
    if (rc != ChainHdSolver::E_NOERROR) return rc;
  } else {
    qdd_ = hd_->res.qdd;
    tau_cmd_ = hd_->res.tau_cmd;
    nu_.head(hd_->res.m) = hd_->nu();
  }
  m_keep_ = hd_->res.m;
  link_acc_known_ = k == 0;
  frictionOutputs(q_dot, friction, k);
  // The optimum is affine in finite friction bounds, but huge values can still overflow.
  if (!(bounded(qdd_) && bounded(tau_cmd_) && bounded(friction_) && bounded(limit_) && bounded(nu_.head(m_keep_))))
    return fail(ChainHdSolver::E_NONFINITE_RESULT,
                "the results overflow (Inf/NaN or beyond 1e150): friction or other inputs too large (max static "
                "friction %g)",
                n ? friction.static_friction.cwiseAbs().maxCoeff() : 0.0);
  solved_ = true;
  message_[0] = '\0';
  if (degraded_ == 0) return ChainHdSolver::E_NOERROR;
  if (degraded_ == 1)
    std::snprintf(message_.data(), message_.size(),
                  "friction: the real-time bound of %ld active-set iterations (friction.max_iterations) was hit: the "
                  "fallback friction is taken (the last iterate, scaled so that friction does no positive work)",
                  bound_);
  else
    std::snprintf(message_.data(), message_.size(),
                  "friction: the real-time iteration bound (friction.max_iterations) was hit in the least-command "
                  "tie-break: the motion is the optimum's, the split between motors and friction the last iterate's");
  return FrictionSolver::E_DEGRADED;
}

const ChainHdSolver::Matrix6X& FrictionCore::linkAccelerations() {
  if (!link_acc_known_ && solved_) {
    // The optimum's joint accelerations through the last solve's kinematics (same q, q_dot): one
    // outward pass instead of a solve with the friction torques as feed-forward.
    if (hd_->res.solved) hd_->accelerationsOf(qdd_);
    link_acc_known_ = true;
  }
  return hd_->linkAccelerations();
}

double FrictionCore::gaussValue() {
  if (!solved_) return std::numeric_limits<double>::quiet_NaN();
  // H (qdd* - qdd_free) = dtau = tau_cmd* + the friction and limit torques of the resting joints,
  // with qdd_free the unconstrained motion under ff torques and kinetic friction; so
  // Z0 = 1/2 dtau^T H^-1 dtau, from the articulated inertias of hd_'s last solve (same q).
  double dissipation = 0.0;
  for (unsigned int j = 0; j < nj_; ++j) {
    const bool resting = status_[j] != Moving || fbound_(j) > 0.0;  // (over a step: moving, bounded)
    tmp_(j) = tau_cmd_(j) + (resting ? friction_(j) + limit_(j) : 0.0);
    // A sticking joint has qdd = 0: its round-off residual times a huge f (up to 1e308) must not
    // overflow the sum.
    if (resting && status_[j] != Stick) dissipation += fbound_(j) * std::abs(qdd_(j) + shift_(j));
  }
  if (!hd_->res.solved) return std::numeric_limits<double>::quiet_NaN();
  hd_->inverseInertia(tmp_, tmp2_);
  return 0.5 * tmp_.dot(tmp2_) + dissipation;
}

}  // namespace detail
}  // namespace vereshchagin
