// The contact stage on a floating base (contact_stage.hpp): what the base changes in it. The
// contact points' positions, velocities, Jacobians and bias accelerations in WORLD axes (the base
// axes of every other input on a floating base, docs/floating-base.md), from the joints'
// kinematics relative to the base body (kin_, base frame) and the base's pose and LOCAL twist;
// the end velocity of step() (a held joint exactly at rest, and the base when every joint is held
// and the sticking points fix it); the Gauss value's H^-1 (no articulated inverse with the base).
//
// With the base at R_b, p_b, its LOCAL twist (v_b, w_b) = S qd_b (base axes), and a point at x
// (base frame) moving at v, w relative to the base, with joint Jacobian J and bias b (classical
// acceleration relative to the base at qdd = 0, kinematics.hpp):
//   position  p_b + R_b x;  velocity  R_b (v_b + w_b x x + v);  angular velocity  R_b (w_b + w);
//   Jacobian  [R_b, -R_b [x]x; 0, R_b] S  for the base's columns, R_b J for the joints';
//   bias      R_b (w_b x v_b + w_b x (w_b x x) + 2 w_b x v + b_lin),  R_b (w_b x w + b_ang),
// the second time derivatives of the position and angle at qdd = 0, whose base rows are the time
// derivatives of the LOCAL twist's components (base_kind.hpp).
#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "hd_core.hpp"
#include "vereshchagin/dynamics.hpp"

namespace vereshchagin {
namespace detail {

struct FloatingGauss {
  explicit FloatingGauss(const Model& model)
      : dyn(model), q(Eigen::VectorXd::Zero(model.nq())), H(model.nv(), model.nv()), llt(model.nv()) {}
  DynamicsData dyn;
  Eigen::VectorXd q;  // the solve's configuration (floatingBase)
  Eigen::MatrixXd H;
  Eigen::LLT<Eigen::MatrixXd> llt;
};

std::shared_ptr<FloatingGauss> makeFloatingGauss(const Model& model) {
  return std::make_shared<FloatingGauss>(model);
}

double ContactStage::floatingInverseInertiaDot(const Eigen::VectorXd& tau) {
  FloatingGauss& g = *floating_gauss_;
  if (!massMatrix(model_, g.dyn, JointPositions(g.q), g.H)) return std::numeric_limits<double>::quiet_NaN();
  g.llt.compute(g.H);
  gauss_out_ = g.llt.solve(tau);
  return tau.dot(gauss_out_);
}

void ContactStage::floatingBase(const SolveInput& in) {
  floating_gauss_->q = in.q;
  if (nbv_ == 6) {  // free-flyer: (x, y, z, qx, qy, qz, qw), (v, omega)
    const Eigen::Quaterniond quat(in.q(6), in.q(3), in.q(4), in.q(5));
    base_R_ = quat.normalized().toRotationMatrix();
    base_p_ = in.q.head<3>();
    base_v_ = in.q_dot.head<6>();
  } else {  // planar: (x, y, cos yaw, sin yaw), (v_x, v_y, omega_z)
    const double n = std::hypot(in.q(2), in.q(3)), c = in.q(2) / n, s = in.q(3) / n;
    base_R_ << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
    base_p_ << in.q(0), in.q(1), 0.0;
    base_v_.setZero();
    base_v_(0) = in.q_dot(0), base_v_(1) = in.q_dot(1), base_v_(5) = in.q_dot(2);
  }
}

void ContactStage::floatingPointState(const PointContact& pc, Point& p) {
  const KDL::Vector point(pc.point(0), pc.point(1), pc.point(2));
  KDL::Frame at;
  Vector6 twist;
  (void)framePose(model_, kin_, FrameRef{pc.segment, KDL::Frame(point)}, at);
  (void)frameTwist(model_, kin_, FrameRef{pc.segment, KDL::Frame(point)}, twist);
  KDL::Frame tip;
  (void)framePose(model_, kin_, FrameRef{pc.segment, KDL::Frame::Identity()}, tip);
  const KDL::Vector r = tip.M * point;  // point - tip origin, base frame
  const Vector3 x(at.p.x(), at.p.y(), at.p.z());
  const Vector3 wb = base_v_.tail<3>();
  p.r = base_R_ * Vector3(r.x(), r.y(), r.z());
  p.v = base_R_ * (base_v_.head<3>() + wb.cross(x) + twist.head<3>());
}

void ContactStage::floatingPointKinematics(const PointContact& pc, Vector6& bias) {
  const FrameRef at{pc.segment, KDL::Frame(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)))};
  KDL::Frame pose;
  Vector6 twist, b;
  (void)framePose(model_, kin_, at, pose);
  (void)frameTwist(model_, kin_, at, twist);
  (void)frameJacobian(model_, kin_, at, jac_b_);
  (void)frameBiasAcceleration(model_, kin_, at, b);
  const Vector3 x(pose.p.x(), pose.p.y(), pose.p.z());
  const Vector3 vb = base_v_.head<3>(), wb = base_v_.tail<3>(), v = twist.head<3>(), w = twist.tail<3>();
  Matrix6 B;  // the base's LOCAL twist to the point's (world axes)
  B << base_R_, -base_R_ * skew(x), Matrix3::Zero(), base_R_;
  jac_.leftCols(nbv_).noalias() = B * base_S_;
  jac_.rightCols(jac_b_.cols()).topRows<3>().noalias() = base_R_ * jac_b_.topRows<3>();
  jac_.rightCols(jac_b_.cols()).bottomRows<3>().noalias() = base_R_ * jac_b_.bottomRows<3>();
  bias.head<3>() = base_R_ * (wb.cross(vb) + wb.cross(wb.cross(x)) + 2.0 * wb.cross(v) + b.head<3>());
  bias.tail<3>() = base_R_ * (wb.cross(w) + b.tail<3>());
}

bool ContactStage::baseHeld(const SolveInput& in) {
  Matrix6 G = Matrix6::Zero();  // sum over the sticking points of Jb^T Jb, Jb their base columns
  bool any = false;
  for (int k = 0; k < count; ++k) {
    if (status[k] != ContactStatus::Sticking) continue;
    Vector6 bias;
    pointKinematics(in.contacts[k], bias);
    G.topLeftCorner(nbv_, nbv_).noalias() += jac_.topLeftCorner(3, nbv_).transpose() * jac_.topLeftCorner(3, nbv_);
    any = true;
  }
  if (!any) return false;
  const double top = G.topLeftCorner(nbv_, nbv_).diagonal().maxCoeff();
  for (int i = nbv_; i < 6; ++i) G(i, i) = top;  // (a planar base's unused directions)
  const Eigen::SelfAdjointEigenSolver<Matrix6> eig(G, Eigen::EigenvaluesOnly);
  return eig.eigenvalues()(0) > 1e-10 * top;
}

void floatingEndVelocity(DataImpl& d, const SolveInput& in, Eigen::Ref<Eigen::VectorXd> qd_next) {
  const int nb = d.core.model.nbv;
  qd_next = in.q_dot + in.time_step * d.core.res.qdd;
  bool all_held = true;
  for (std::size_t j = 0; j < d.status_per_joint.size(); ++j) {
    if (d.status_per_joint[j] == JointStatus::Stick)
      qd_next(nb + static_cast<Eigen::Index>(j)) = 0.0;
    else
      all_held = false;
  }
  if (all_held && d.contacts_last && d.contact_stage->count > 0 && d.contact_stage->baseHeld(in))
    qd_next.head(nb).setZero();
}

}  // namespace detail
}  // namespace vereshchagin
