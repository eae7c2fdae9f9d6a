// HdSolver: the public face of HdCore (hd_core.hpp). Every call forwards; error codes are kept in
// KDL::SolverI::error. Conventions in hd_solver.hpp.
#include "vereshchagin/hd_solver.hpp"

#include "hd_core.hpp"

namespace vereshchagin {

namespace {

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

HdSolver::HdSolver(const detail::ModelSource& source, const KDL::Twist& root_acc, const SolverOptions& options)
    : core_(std::make_unique<detail::HdCore>(source, toVector(root_acc), options)) {}

HdSolver::~HdSolver() = default;
HdSolver::HdSolver(HdSolver&&) noexcept = default;
HdSolver& HdSolver::operator=(HdSolver&&) noexcept = default;

void HdSolver::rebuild(const detail::ModelSource& source) {
  core_->rebuild(source);
}

void HdSolver::updateInternalDataStructures() {
  core_->rebuild(core_->model.source);
}

int HdSolver::record(int rc) {
  if (rc != E_NOERROR) error = rc;
  return rc;
}

int HdSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                    const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  return error = core_->solveLast(q, q_dot, alfa, beta, f_ext, ff_torques);
}

int HdSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                    const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
                    const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  return error = core_->solveSegments(q, q_dot, alfa, beta, segments, f_ext, ff_torques);
}

int HdSolver::maxConstraints() const {
  return core_->mcap;
}
const Eigen::VectorXd& HdSolver::qdd() const {
  return core_->res.qdd;
}
const Eigen::VectorXd& HdSolver::commandTorques() const {
  return core_->res.tau_cmd;
}
Eigen::Map<const Eigen::VectorXd> HdSolver::nu() const {
  return core_->nu();
}
const HdSolver::Matrix6X& HdSolver::linkAccelerations() const {
  return core_->linkAccelerations();
}
int HdSolver::setJointAccelerations(const Eigen::Ref<const Eigen::VectorXd>& qdd) {
  if (!core_->res.solved)
    return record(core_->fail(E_NO_SOLUTION, "setJointAccelerations() needs a successful solve() first"));
  if (qdd.size() != static_cast<Eigen::Index>(nrOfJoints()))
    return record(
        core_->fail(E_SIZE_MISMATCH, "qdd has %ld entries, expected %u (joints)", (long)qdd.size(), nrOfJoints()));
  core_->accelerationsOf(qdd);
  return E_NOERROR;
}
int HdSolver::inverseInertiaTimes(const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> out) {
  if (!core_->res.solved)
    return record(core_->fail(E_NO_SOLUTION, "inverseInertiaTimes() needs a successful solve() first"));
  const auto n = static_cast<Eigen::Index>(nrOfJoints());
  if (tau.size() != n || out.size() != n)
    return record(core_->fail(E_SIZE_MISMATCH, "tau has %ld and out %ld entries, expected %u (joints)",
                              (long)tau.size(), (long)out.size(), nrOfJoints()));
  core_->inverseInertia(tau, out);
  return E_NOERROR;
}
int HdSolver::constraintCount() const {
  return core_->res.m;
}
KDL::Frame HdSolver::linkLocalPose(unsigned int i) const {
  const Pose& X = core_->ws.seg[i].X;
  return KDL::Frame(
      KDL::Rotation(X.R(0, 0), X.R(0, 1), X.R(0, 2), X.R(1, 0), X.R(1, 1), X.R(1, 2), X.R(2, 0), X.R(2, 1), X.R(2, 2)),
      KDL::Vector(X.p(0), X.p(1), X.p(2)));
}
KDL::Twist HdSolver::linkLocalVelocity(unsigned int i) const {
  return toTwist(core_->ws.seg[i].v);
}
KDL::Twist HdSolver::linkLocalAcceleration(unsigned int i) const {
  return toTwist(core_->ws.seg[i].xdd);
}
double HdSolver::articulatedInertia(unsigned int joint) const {
  return core_->ws.seg[core_->model.joint_segment[joint]].D;
}
int HdSolver::constraintRank() const {
  return core_->res.rank;
}
double HdSolver::smallestSingularValue() const {
  return core_->smallestSingularValue();
}

void HdSolver::getTransformedLinkAcceleration(std::vector<KDL::Twist>& x_dotdot) const {
  const Matrix6X& acc = linkAccelerations();
  x_dotdot.resize(acc.cols());
  for (Eigen::Index i = 0; i < acc.cols(); ++i) x_dotdot[i] = toTwist(acc.col(i));
}

int HdSolver::responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                              Eigen::Ref<Eigen::MatrixXd> dtau_cmd) {
  return record(core_->responseColumns(joints, dqdd, dtau_cmd, nullptr));
}

int HdSolver::responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                              Eigen::Ref<Eigen::MatrixXd> dtau_cmd, Eigen::Ref<Eigen::MatrixXd> dnu) {
  const int m = core_->res.m;
  if (core_->res.solved && (dnu.rows() < m || dnu.cols() < joints.size()))
    return record(core_->fail(E_SIZE_MISMATCH, "dnu is %ldx%ld, expected at least %dx%ld", (long)dnu.rows(),
                              (long)dnu.cols(), m, (long)joints.size()));
  return record(core_->responseColumns(joints, dqdd, dtau_cmd, &dnu));
}

int HdSolver::commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) {
  return record(core_->commandTorquesOf(nu, tau_cmd));
}

int HdSolver::setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                             const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through) {
  return record(core_->setPassThrough(f_ext_pass_through, ff_pass_through));
}
void HdSolver::clearPassThrough() {
  core_->clearPassThrough();
}
int HdSolver::passThroughColumns() const {
  return core_->ws.pt.m;
}

void HdSolver::setRootAcceleration(const KDL::Twist& root_acc) {
  core_->root_acc = toVector(root_acc);
}
int HdSolver::setOptions(const SolverOptions& options) {
  return record(core_->setOptions(options));
}
const SolverOptions& HdSolver::options() const {
  return core_->options;
}
unsigned int HdSolver::nrOfJoints() const {
  return core_->model.nj;
}
unsigned int HdSolver::nrOfSegments() const {
  return core_->model.ns;
}
int HdSolver::modelError() const {
  return core_->model_error;
}
const char* HdSolver::errorMessage() const {
  return core_->message.data();
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
    default:
      return KDL::SolverI::strError(code);
  }
}

}  // namespace vereshchagin
