// HdSolver: the public face of HdCore (hd_core.hpp). Every call forwards; error codes are kept in
// KDL::SolverI::error. Conventions in hd_solver.hpp.
#include "vereshchagin/hd_solver.hpp"

#include "entry_guard.hpp"
#include "facade_state.hpp"
#include "hd_core.hpp"
#include "model_impl.hpp"

namespace vereshchagin {

namespace {

using detail::EntryGuard;
using detail::sixRows;

Vector6 toVector(const KDL::Twist& t) {
  Vector6 v;
  for (int k = 0; k < 3; ++k) {
    v(k) = t.vel(k);
    v(3 + k) = t.rot(k);
  }
  return v;
}

KDL::Twist toTwist(const Vector6& v) {
  return KDL::Twist(KDL::Vector(v(0), v(1), v(2)), KDL::Vector(v(3), v(4), v(5)));
}

}  // namespace

HdSolver::HdSolver(const Model& model, const KDL::Twist& root_acc, const SolverOptions& options)
    : state_(std::make_unique<detail::FacadeState>(model, toVector(root_acc), options)) {}

HdSolver::~HdSolver() = default;
HdSolver::HdSolver(HdSolver&&) noexcept = default;
HdSolver& HdSolver::operator=(HdSolver&&) noexcept = default;

detail::HdCore& HdSolver::core() {
  return state_->core();
}
const detail::HdCore& HdSolver::core() const {
  return state_->core();
}
const Model& HdSolver::model() const {
  return state_->model;
}
Data& HdSolver::data() {
  return state_->data;
}

void HdSolver::rebuild(const Model& model) {
  state_->reset(model, core().options);
}

void HdSolver::updateInternalDataStructures() {
  {
    const EntryGuard guard(core().busy);
    if (!guard) {
      state_->stale_model.store(true, std::memory_order_relaxed);  // reported by the next solves
      return;
    }
    rebuild(state_->model);
    state_->stale_model.store(false, std::memory_order_relaxed);
  }
  state_->dropRetired();  // the guard above held its flag
}

int HdSolver::record(int rc) {
  if (rc != E_NOERROR) {
    error = rc;
  } else {
    core().message[0] = '\0';
  }
  return rc;
}

int HdSolver::solveChecked(int rc) {
  if (rc == E_NOERROR) core().message[0] = '\0';
  return error = rc;
}

// 0 if alfa and f_ext have 6 rows (or no columns) and the model was not left stale, else the
// error code with its message.
int HdSolver::solveArgsProblem(const Eigen::Ref<const Eigen::MatrixXd>& alfa,
                               const Eigen::Ref<const Eigen::MatrixXd>& f_ext) {
  if (state_->stale_model.load(std::memory_order_relaxed))
    return core().fail(E_CONCURRENT_CALL,
                       "updateInternalDataStructures() was called while another thread was inside a call on this "
                       "solver and could not rebuild the model: call it again (a solver object must not be used "
                       "from two threads at once; use one solver per thread)");
  if (alfa.rows() != 6 && alfa.cols() != 0)
    return core().fail(E_SIZE_MISMATCH, "alfa is %ldx%ld, expected 6 rows (6 x m constraint wrenches, m <= %d)",
                       (long)alfa.rows(), (long)alfa.cols(), maxConstraints());
  if (f_ext.rows() != 6 && f_ext.cols() != 0)
    return core().fail(E_SIZE_MISMATCH, "f_ext is %ldx%ld, expected 6 x %u (one wrench per segment) or empty",
                       (long)f_ext.rows(), (long)f_ext.cols(), nrOfSegments());
  return E_NOERROR;
}

int HdSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                    const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
                    const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  return solveEntered(q, q_dot, alfa, beta, f_ext, ff_torques);
}

int HdSolver::solveEntered(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                           const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                           const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
                           const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  if (const int rc = solveArgsProblem(alfa, f_ext)) return solveChecked(rc);
  state_->install();
  return solveChecked(core().solveLast(q, q_dot, sixRows(alfa), beta, sixRows(f_ext), ff_torques));
}

int HdSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                    const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
                    const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  if (const int rc = solveArgsProblem(alfa, f_ext)) return solveChecked(rc);
  state_->install();
  return solveChecked(core().solveSegments(q, q_dot, sixRows(alfa), beta, segments, sixRows(f_ext), ff_torques));
}

int HdSolver::maxConstraints() const {
  return core().mcap;
}
const Eigen::VectorXd& HdSolver::qdd() const {
  return core().res.qdd;
}
const Eigen::VectorXd& HdSolver::commandTorques() const {
  return core().res.tau_cmd;
}
Eigen::Map<const Eigen::VectorXd> HdSolver::nu() const {
  return core().nu();
}
const HdSolver::Matrix6X& HdSolver::linkAccelerations() const {
  const EntryGuard guard(core().busy);
  if (!guard) return core().res.link_acc;  // another thread is inside: no lazy computation
  return core().linkAccelerations();
}
int HdSolver::setJointAccelerations(const Eigen::Ref<const Eigen::VectorXd>& qdd) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  if (!core().res.solved)
    return record(core().fail(E_NO_SOLUTION, "setJointAccelerations() needs a successful solve() first"));
  if (qdd.size() != static_cast<Eigen::Index>(nrOfJoints()))
    return record(
        core().fail(E_SIZE_MISMATCH, "qdd has %ld entries, expected %u (joints)", (long)qdd.size(), nrOfJoints()));
  core().accelerationsOf(qdd);
  return record(E_NOERROR);
}
int HdSolver::inverseInertiaTimes(const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> out) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  if (!core().res.solved)
    return record(core().fail(E_NO_SOLUTION, "inverseInertiaTimes() needs a successful solve() first"));
  const auto n = static_cast<Eigen::Index>(nrOfJoints());
  if (tau.size() != n || out.size() != n)
    return record(core().fail(E_SIZE_MISMATCH, "tau has %ld and out %ld entries, expected %u (joints)",
                              (long)tau.size(), (long)out.size(), nrOfJoints()));
  core().inverseInertia(tau, out);
  return record(E_NOERROR);
}
int HdSolver::constraintCount() const {
  return core().res.m;
}
KDL::Frame HdSolver::linkLocalPose(unsigned int i) const {
  const Pose& X = core().ws.seg[i].X;
  return KDL::Frame(
      KDL::Rotation(X.R(0, 0), X.R(0, 1), X.R(0, 2), X.R(1, 0), X.R(1, 1), X.R(1, 2), X.R(2, 0), X.R(2, 1), X.R(2, 2)),
      KDL::Vector(X.p(0), X.p(1), X.p(2)));
}
KDL::Twist HdSolver::linkLocalVelocity(unsigned int i) const {
  return toTwist(core().ws.seg[i].v);
}
KDL::Twist HdSolver::linkLocalAcceleration(unsigned int i) const {
  return toTwist(core().ws.seg[i].xdd);
}
double HdSolver::articulatedInertia(unsigned int joint) const {
  return core().ws.seg[core().model.joint_segment[joint]].D;
}
int HdSolver::constraintRank() const {
  return core().res.rank;
}
double HdSolver::smallestSingularValue() const {
  const EntryGuard guard(core().busy);
  if (!guard) return core().res.sigma_min;  // another thread is inside: no lazy computation
  return core().smallestSingularValue();
}

void HdSolver::getTransformedLinkAcceleration(std::vector<KDL::Twist>& x_dotdot) const {
  const Matrix6X& acc = linkAccelerations();
  x_dotdot.resize(acc.cols());
  for (Eigen::Index i = 0; i < acc.cols(); ++i) x_dotdot[i] = toTwist(acc.col(i));
}

int HdSolver::responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                              Eigen::Ref<Eigen::MatrixXd> dtau_cmd) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  return record(core().responseColumns(joints, dqdd, dtau_cmd, nullptr));
}

int HdSolver::responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                              Eigen::Ref<Eigen::MatrixXd> dtau_cmd, Eigen::Ref<Eigen::MatrixXd> dnu) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  const int m = core().res.m;
  if (core().res.solved && (dnu.rows() < m || dnu.cols() < joints.size()))
    return record(core().fail(E_SIZE_MISMATCH, "dnu is %ldx%ld, expected at least %dx%ld", (long)dnu.rows(),
                              (long)dnu.cols(), m, (long)joints.size()));
  return record(core().responseColumns(joints, dqdd, dtau_cmd, &dnu));
}

int HdSolver::commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  return record(core().commandTorquesOf(nu, tau_cmd));
}

int HdSolver::setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                             const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  return record(core().setPassThrough(f_ext_pass_through, ff_pass_through, state_->weights));
}
int HdSolver::clearPassThrough() {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  state_->weights.m = -1;
  state_->weights.f_any = state_->weights.t_any = false;
  core().res.solved = false;
  return E_NOERROR;
}
int HdSolver::passThroughColumns() const {
  return state_->weights.m;
}

int HdSolver::setRootAcceleration(const KDL::Twist& root_acc) {
  const EntryGuard guard(core().busy);
  if (!guard) return E_CONCURRENT_CALL;
  state_->root_acc = toVector(root_acc);
  return E_NOERROR;
}
int HdSolver::setOptions(const SolverOptions& options) {
  int rc = E_NOERROR;
  {
    const EntryGuard guard(core().busy);
    if (!guard) return E_CONCURRENT_CALL;
    rc = setOptionsEntered(options);
  }
  state_->dropRetired();  // the guard above held its flag
  return rc;
}

int HdSolver::setOptionsEntered(const SolverOptions& options) {
  const int capacity = core().mcap;
  const int rc = core().setOptions(options);  // validates; resizes the workspace for a new capacity
  if (rc != E_NOERROR) return record(rc);
  if (options.inertia_check != state_->model.options().inertia_check) {
    ModelOptions model_options = state_->model.options();
    model_options.inertia_check = options.inertia_check;
    state_->reset(detail::ModelAccess::withOptions(state_->model, model_options), options);
    return record(core().model_error);
  }
  if (core().mcap != capacity) state_->reset(state_->model, options);  // weights are per capacity
  return record(core().model_error);
}
const SolverOptions& HdSolver::options() const {
  return core().options;
}
unsigned int HdSolver::nrOfJoints() const {
  return core().model.nj;
}
unsigned int HdSolver::nrOfSegments() const {
  return core().model.ns;
}
int HdSolver::modelError() const {
  return core().model_error;
}
const char* HdSolver::errorMessage() const {
  return core().message.data();
}

const char* HdSolver::strError(const int code) const {
  switch (code) {
    case E_NONFINITE_INPUT:
      return "An input contains NaN or Inf";
    case E_INVALID_MODEL:
      return "The robot's physical parameters are invalid";
    case E_DEGENERATE_INERTIA:
      return "A joint has zero articulated inertia";
    case E_TOO_MANY_CONSTRAINTS:
      return "More than 6 constraints on one segment";
    case E_NO_SOLUTION:
      return "No successful solve to take the response from";
    case E_INVALID_OPTIONS:
      return "Invalid solver options";
    case E_NONFINITE_RESULT:
      return "The results overflow (inputs too large)";
    case E_CONCURRENT_CALL:
      return "Another thread is inside a call on this solver: a solver object must not be used from two threads "
             "at once (use one solver per thread)";
    case E_STATE_OUT_OF_RANGE:
      return "The state is out of range: round-off dominates the articulated inertias (a diverged state?)";
    default:
      return KDL::SolverI::strError(code);
  }
}

}  // namespace vereshchagin
