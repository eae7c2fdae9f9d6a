// KDL-compatible drop-in classes over ChainHdSolver: KDL 1.5.1 (kdl_compat.hpp) and the secorolab
// fork (kdl_fork_compat.hpp). Conventions and differences in those headers.
#include "vereshchagin/kdl_compat.hpp"

#include <Eigen/Geometry>
#include <kdl/rigidbodyinertia.hpp>

#include <memory>
#include <utility>

#include "vereshchagin/kdl_fork_compat.hpp"
#include "vereshchagin/robot_chain.hpp"  // withRotorInertia

namespace vereshchagin {
namespace kdl_compat {

namespace {

SolverOptions compatOptions() {
  SolverOptions o;
  o.inertia_check = InertiaCheck::JointSpace;  // identified models, as KDL accepts them
  return o;
}

// No segment carries mass or rotational inertia and no joint a rotor inertia.
bool massless(const KDL::Chain& chain) {
  for (const KDL::Segment& seg : chain.segments) {
    const KDL::RigidBodyInertia I = seg.getInertia();
    const KDL::RotationalInertia Io = I.getRotationalInertia();  // a copy: the getter returns by value
    const Eigen::Map<const Eigen::Matrix3d> rot(Io.data);
    if (I.getMass() != 0.0 || !(rot.array() == 0.0).all() || seg.getJoint().getInertia() != 0.0) return false;
  }
  return chain.getNrOfJoints() > 0;
}

template <typename T>
void ensureSize(std::vector<T>& v, std::size_t n) {
  if (v.size() != n) v.resize(n);
}

}  // namespace

ChainHdSolver_Vereshchagin::ChainHdSolver_Vereshchagin(const KDL::Chain& chain, const KDL::Twist& root_acc,
                                                       const unsigned int nc)
    : source_(&chain), root_acc_(root_acc), nc_(nc), solver_(chain, root_acc, compatOptions()) {
  allocate();
}

ChainHdSolver_Vereshchagin::ChainHdSolver_Vereshchagin(KDL::Chain&& chain, const KDL::Twist& root_acc,
                                                       const unsigned int nc)
    : source_(nullptr), root_acc_(root_acc), nc_(nc), solver_(chain, root_acc, compatOptions()) {
  allocate();
}

void ChainHdSolver_Vereshchagin::allocate() {
  nj_ = solver_.nrOfJoints();
  ns_ = solver_.nrOfSegments();
  active_ = 0;
  alfa_on_ = ChainHdSolver::Matrix6X::Zero(6, nc_);
  f_ext_ = ChainHdSolver::Matrix6X::Zero(6, ns_);
  beta_all_ = beta_on_ = nu_ = w_f_ = w_t_ = w_f_on_ = w_t_on_ = Eigen::VectorXd::Zero(nc_);
  column_ = Eigen::VectorXi::Zero(nc_);
  total_ = felt_ = d_ = Eigen::VectorXd::Zero(nj_);
  not_up_to_date_ = false;
  weighted_ = false;
  degraded_ = false;
  poses_.assign(ns_, KDL::Frame::Identity());
  unit_.reset();
  if (massless(solver_.chain())) {
    KDL::Chain unit;
    for (const KDL::Segment& seg : solver_.chain().segments) {
      const bool fixed = seg.getJoint().getType() == KDL::Joint::Fixed;
      unit.addSegment(KDL::Segment(seg.getName(), withRotorInertia(seg.getJoint(), fixed ? 0.0 : 1.0),
                                   seg.getFrameToTip(), seg.getInertia()));
    }
    unit_ = std::make_unique<ChainHdSolver>(unit, root_acc_, compatOptions());
  }
}

void ChainHdSolver_Vereshchagin::updateInternalDataStructures() {
  if (source_ != nullptr) {
    solver_ = ChainHdSolver(*source_, root_acc_, compatOptions());
  } else {
    const KDL::Chain own = solver_.chain();
    solver_ = ChainHdSolver(own, root_acc_, compatOptions());
  }
  allocate();
}

void ChainHdSolver_Vereshchagin::effectiveBeta(const KDL::Jacobian&, const KDL::JntArray& beta,
                                               Eigen::VectorXd& out) const {
  out = beta.data;
}

const char* ChainHdSolver_Vereshchagin::errorMessage() const {
  if (degraded_ && error == E_DEGRADED)
    return "the chain has no mass and no rotor inertia: its dynamics leave q_dotdot free; q_dotdot is the smallest "
           "one that meets the constraints (no torque is needed)";
  if (not_up_to_date_)
    return "the chain given to the constructor has another number of segments than the solver's model: call "
           "updateInternalDataStructures()";
  return solver_.errorMessage();
}

const char* ChainHdSolver_Vereshchagin::strError(const int error) const {
  return solver_.strError(error);
}

int ChainHdSolver_Vereshchagin::setDriverWeights(const Eigen::VectorXd& w_f_ext, const Eigen::VectorXd& w_ff_torques) {
  if (w_f_ext.size() != nc_ || w_ff_torques.size() != nc_) return error = E_SIZE_MISMATCH;
  for (unsigned int c = 0; c < nc_; ++c)
    if (!(w_f_ext(c) >= 0.0 && w_f_ext(c) <= 1.0) || !(w_ff_torques(c) >= 0.0 && w_ff_torques(c) <= 1.0))
      return error = E_OUT_OF_RANGE;
  w_f_ = w_f_ext;
  w_t_ = w_ff_torques;
  weighted_ = (w_f_.array() != 0.0).any() || (w_t_.array() != 0.0).any();
  return error = E_NOERROR;
}

int ChainHdSolver_Vereshchagin::CartToJnt(const KDL::JntArray& q, const KDL::JntArray& q_dot, KDL::JntArray& q_dotdot,
                                          const KDL::Jacobian& alfa, const KDL::JntArray& beta,
                                          const KDL::Wrenches& f_ext, const KDL::JntArray& ff_torques,
                                          KDL::JntArray& constraint_torques) {
  // As KDL: a changed number of segments of the caller's chain is reported first.
  not_up_to_date_ = source_ != nullptr && source_->getNrOfSegments() != ns_;
  if (not_up_to_date_) return error = E_NOT_UP_TO_DATE;
  if (q.rows() != nj_ || q_dot.rows() != nj_ || q_dotdot.rows() != nj_ || ff_torques.rows() != nj_ ||
      constraint_torques.rows() != nj_ || f_ext.size() != ns_ || alfa.columns() != nc_ || beta.rows() != nc_)
    return error = E_SIZE_MISMATCH;
  effectiveBeta(alfa, beta, beta_all_);
  // Zero columns disable their constraints (KDL's convention): solve with the others only.
  active_ = 0;
  for (unsigned int c = 0; c < nc_; ++c) {
    if ((alfa.data.col(c).array() == 0.0).all()) continue;
    alfa_on_.col(active_) = alfa.data.col(c);
    beta_on_(active_) = beta_all_(c);
    w_f_on_(active_) = w_f_(c);
    w_t_on_(active_) = w_t_(c);
    column_(active_++) = static_cast<int>(c);
  }
  for (unsigned int i = 0; i < ns_; ++i)
    for (int k = 0; k < 3; ++k) {
      f_ext_(k, i) = f_ext[i].force(k);
      f_ext_(3 + k, i) = f_ext[i].torque(k);
    }
  applyDriverWeights(solver_);
  degraded_ = false;
  const int rc =
      solver_.solve(q.data, q_dot.data, alfa_on_.leftCols(active_), beta_on_.head(active_), f_ext_, ff_torques.data);
  if (rc == ChainHdSolver::E_DEGENERATE_INERTIA && masslessAnswer(q, q_dot, ff_torques, q_dotdot, constraint_torques))
    return error = E_DEGRADED;
  if (rc != E_NOERROR) return error = rc;
  q_dotdot.data = solver_.qdd();
  nu_.setZero();
  const auto nu = solver_.nu();
  for (int k = 0; k < active_; ++k) nu_(column_(k)) = nu(k);
  if (convention_ == TorqueConvention::Command) {
    constraint_torques.data = solver_.commandTorques();
    total_ = ff_torques.data + solver_.commandTorques();
  } else {
    feltTorques(q, nu_, alfa);
    constraint_torques.data = felt_;
    total_ = d_.cwiseProduct(solver_.qdd());
  }
  return error = E_NOERROR;
}

// The driver pass-through weights of the enabled columns (setDriverWeights()) on `solver`, or none.
void ChainHdSolver_Vereshchagin::applyDriverWeights(ChainHdSolver& solver) {
  if (weighted_) {
    solver.setPassThrough(w_f_on_.head(active_), w_t_on_.head(active_));
  } else if (solver.passThroughColumns() >= 0) {
    solver.clearPassThrough();
  }
}

// A chain without any mass or rotor inertia, driven by no torque and no wrench, has dynamics that
// leave every acceleration free (KDL computes NaN there and returns 0). The answer given instead:
// the smallest q_dotdot that meets the constraints (least squares where they conflict), which is
// the Gauss-optimal motion of the same chain with unit rotor inertia on every joint (H = I, the
// Gauss function 1/2 |q_dotdot|^2), solved by unit_; no torque is needed for it.
bool ChainHdSolver_Vereshchagin::masslessAnswer(const KDL::JntArray& q, const KDL::JntArray& q_dot,
                                                const KDL::JntArray& ff_torques, KDL::JntArray& q_dotdot,
                                                KDL::JntArray& constraint_torques) {
  if (!unit_ || !(ff_torques.data.array() == 0.0).all() || !(f_ext_.array() == 0.0).all()) return false;
  applyDriverWeights(*unit_);
  const Eigen::VectorXd no_torques;  // empty: zero torques (no allocation)
  if (unit_->solve(q.data, q_dot.data, alfa_on_.leftCols(active_), beta_on_.head(active_), f_ext_, no_torques) !=
      E_NOERROR)
    return false;
  q_dotdot.data = unit_->qdd();
  total_.setZero();
  nu_.setZero();
  constraint_torques.data.setZero();
  degraded_ = true;
  return true;
}

void ChainHdSolver_Vereshchagin::getTransformedLinkAcceleration(Twists& x_dotdot) {
  ensureSize(x_dotdot, ns_ + 1);
  const auto& acc = answered().linkAccelerations();
  for (unsigned int i = 0; i <= ns_; ++i)
    x_dotdot[i] =
        KDL::Twist(KDL::Vector(acc(0, i), acc(1, i), acc(2, i)), KDL::Vector(acc(3, i), acc(4, i), acc(5, i)));
}

void ChainHdSolver_Vereshchagin::getTotalTorque(KDL::JntArray& total_tau) {
  if (total_tau.rows() != nj_) total_tau.resize(nj_);
  total_tau.data = total_;
}

void ChainHdSolver_Vereshchagin::getCommandTorques(KDL::JntArray& tau) {
  if (tau.rows() != nj_) tau.resize(nj_);
  if (degraded_)
    tau.data.setZero();  // a massless chain needs no torque for any motion
  else
    tau.data = solver_.commandTorques();
}

// KDL's constraint_torques entry j is -Z_j^T E_j nu: the constraint wrench alfa nu on the last
// tip, carried inward through the articulated bodies, each joint passed on the way projected
// out (E_{i-1} = E_i - U_i Z_i^T E_i / D_i, U_i = P_i Z_i, D_i = Z_i^T P_i Z_i + rotor_i, P_i the
// articulated inertia), and felt at joint j before its own projection. Computed here in one
// inward sweep with every quantity in base axes about the base origin (frame-independent
// scalars), KDL's articulated inertia D_j along the way (for getTotalTorque()).
void ChainHdSolver_Vereshchagin::feltTorques(const KDL::JntArray& q, const Eigen::VectorXd& nu_all,
                                             const KDL::Jacobian& alfa) {
  updateBasePoses();
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  using Matrix3 = Eigen::Matrix<double, 3, 3>;
  const KDL::Chain& chain = solver_.chain();
  // alfa nu: force f and moment about the last tip's origin -> moment about the base origin.
  Vector6 e = alfa.data * nu_all;
  const KDL::Vector tip = ns_ > 0 ? poses_[ns_ - 1].p : KDL::Vector::Zero();
  const Eigen::Vector3d p(tip.x(), tip.y(), tip.z());
  e.tail<3>() += p.cross(Eigen::Vector3d(e.head<3>()));
  Matrix6 P = Matrix6::Zero();
  int j = static_cast<int>(nj_) - 1;
  for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) {
    const KDL::Segment& seg = chain.getSegment(i);
    // Rigid-body inertia in base axes about the base origin: [m 1, -m [c]x; m [c]x, I_O].
    const KDL::RigidBodyInertia I = poses_[i] * seg.getInertia();
    const double m = I.getMass();
    const KDL::Vector h = m * I.getCOG();
    Matrix3 hx;
    hx << 0.0, -h.z(), h.y(), h.z(), 0.0, -h.x(), -h.y(), h.x(), 0.0;
    P.topLeftCorner<3, 3>() += m * Matrix3::Identity();
    P.topRightCorner<3, 3>() -= hx;
    P.bottomLeftCorner<3, 3>() += hx;
    P.bottomRightCorner<3, 3>() +=
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(I.getRotationalInertia().data);
    if (seg.getJoint().getType() == KDL::Joint::Fixed) continue;
    // Joint unit twist: in the segment's root axes about its tip -> base axes about the base origin.
    const KDL::Rotation R_parent = i > 0 ? poses_[i - 1].M : KDL::Rotation::Identity();
    const KDL::Twist t = (R_parent * seg.twist(q(j), 1.0)).RefPoint(-poses_[i].p);
    Vector6 S;
    S << t.vel.x(), t.vel.y(), t.vel.z(), t.rot.x(), t.rot.y(), t.rot.z();
    const Vector6 U = P * S;
    const double D = S.dot(U) + seg.getJoint().getInertia();
    const double se = S.dot(e);
    felt_(j) = -se;
    d_(j) = D;
    e.noalias() -= U * (se / D);
    P.noalias() -= U * (U.transpose() / D);
    --j;
  }
}

void ChainHdSolver_Vereshchagin::getContraintForceMagnitude(Eigen::VectorXd& nu_out) {
  nu_out = nu_;
}

void ChainHdSolver_Vereshchagin::updateBasePoses() {
  KDL::Frame parent = KDL::Frame::Identity();
  for (unsigned int i = 0; i < ns_; ++i) {
    parent = parent * answered().linkLocalPose(i);
    poses_[i] = parent;
  }
}

void ChainHdSolver_Vereshchagin::getLinkCartesianPose(Frames& x_base) {
  updateBasePoses();
  ensureSize(x_base, ns_);
  for (unsigned int i = 0; i < ns_; ++i) x_base[i] = poses_[i];
}

void ChainHdSolver_Vereshchagin::getLinkCartesianVelocity(Twists& xDot_base) {
  updateBasePoses();
  ensureSize(xDot_base, ns_);
  for (unsigned int i = 0; i < ns_; ++i) xDot_base[i] = poses_[i].M * answered().linkLocalVelocity(i);
}

void ChainHdSolver_Vereshchagin::getLinkCartesianAcceleration(Twists& xDotDot_base) {
  updateBasePoses();
  ensureSize(xDotDot_base, ns_);
  for (unsigned int i = 0; i < ns_; ++i) xDotDot_base[i] = poses_[i].M * answered().linkLocalAcceleration(i);
}

void ChainHdSolver_Vereshchagin::getLinkPose(Frames& x_local) {
  ensureSize(x_local, ns_);
  for (unsigned int i = 0; i < ns_; ++i) x_local[i] = answered().linkLocalPose(i);
}

void ChainHdSolver_Vereshchagin::getLinkVelocity(Twists& xDot_local) {
  ensureSize(xDot_local, ns_);
  for (unsigned int i = 0; i < ns_; ++i) xDot_local[i] = answered().linkLocalVelocity(i);
}

void ChainHdSolver_Vereshchagin::getLinkAcceleration(Twists& xDotdot_local) {
  ensureSize(xDotdot_local, ns_);
  for (unsigned int i = 0; i < ns_; ++i) xDotdot_local[i] = answered().linkLocalAcceleration(i);
}

}  // namespace kdl_compat
}  // namespace vereshchagin

// ---- kdl_fork_compat.hpp: the secorolab fork's classes ----

namespace vereshchagin {
namespace kdl_fork {

void ChainHdSolver_Vereshchagin::effectiveBeta(const KDL::Jacobian& alfa, const KDL::JntArray& beta,
                                               Eigen::VectorXd& out) const {
  const KDL::Twist& a = rootAcceleration();
  Eigen::Matrix<double, 6, 1> acc;
  acc << a.vel.x(), a.vel.y(), a.vel.z(), a.rot.x(), a.rot.y(), a.rot.z();
  out = beta.data;
  out.noalias() += alfa.data.transpose() * acc;
}

ChainHdSolver_Vereshchagin_Fext_FixedJoint::ChainHdSolver_Vereshchagin_Fext_FixedJoint(const KDL::Chain& chain,
                                                                                       const KDL::Twist& root_acc,
                                                                                       const unsigned int nc)
    : ChainHdSolver_Vereshchagin(chain, root_acc, nc), nc_(nc) {
  prioritizeExternalWrenches();
}

ChainHdSolver_Vereshchagin_Fext_FixedJoint::ChainHdSolver_Vereshchagin_Fext_FixedJoint(KDL::Chain&& chain,
                                                                                       const KDL::Twist& root_acc,
                                                                                       const unsigned int nc)
    : ChainHdSolver_Vereshchagin(std::move(chain), root_acc, nc), nc_(nc) {
  prioritizeExternalWrenches();
}

void ChainHdSolver_Vereshchagin_Fext_FixedJoint::updateInternalDataStructures() {
  ChainHdSolver_Vereshchagin::updateInternalDataStructures();
  prioritizeExternalWrenches();
}

void ChainHdSolver_Vereshchagin_Fext_FixedJoint::prioritizeExternalWrenches() {
  setDriverWeights(Eigen::VectorXd::Ones(nc_), Eigen::VectorXd::Zero(nc_));
}

}  // namespace kdl_fork
}  // namespace vereshchagin
