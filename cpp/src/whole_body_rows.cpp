// WholeBodySolver's affine map (whole_body.hpp): the forward dynamics of the input alone (qdd0),
// the response columns of the actuated joints' torques and of the supports' forces (R), and the
// conditions as rows E x = e: each task column alfa_c^T Xdd = beta_c and each support's classical
// point acceleration zero, with Xdd = Xdd0 + J R x (J the frame's 6 x nv Jacobian about its point).
#include <algorithm>

#include "vereshchagin/task.hpp"
#include "whole_body_impl.hpp"

namespace vereshchagin {

namespace {

Vector3 toVector3(const KDL::Vector& v) {
  return Vector3(v.x(), v.y(), v.z());
}

// The frame's origin relative to its segment's tip origin (base axes), and its twist there.
Vector3 offset(const Data& data, const FrameRef& frame) {
  const KDL::Frame tip = data.framePose(FrameRef{frame.segment, KDL::Frame::Identity()});
  return toVector3(tip.M * frame.in_tip.p);
}

Vector6 twistOf(const Data& data, const FrameRef& frame) {
  const KDL::Twist t = data.frameTwist(frame);
  Vector6 v;
  v << toVector3(t.vel), toVector3(t.rot);
  return v;
}

}  // namespace

Status WholeBodySolver::Impl::columns(const SolveInput& in) {
  free.q = in.q;
  free.q_dot = in.q_dot;
  free.f_ext = in.f_ext;
  free.wrenches = in.wrenches;
  free.ff_torques = in.ff_torques;
  free.gravity = in.gravity;
  if (const Status st = vereshchagin::solve(*model, data, free); !st) return st;
  qdd0 = data.qdd();
  if (na > 0) {
    const Status st = data.responseColumns(joints.head(na), R.leftCols(na), dtau.leftCols(na));
    if (!st) return st;
  }
  for (int c = 0; c < k; ++c) {
    const PointContact& pc = in.contacts[c];
    KDL::Frame at(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)));
    const Vector3 r = offset(data, FrameRef{pc.segment, at});
    for (int i = 0; i < 3; ++i) {
      segs(3 * c + i) = pc.segment;
      W.col(3 * c + i) << Vector3::Unit(i), r.cross(Vector3::Unit(i));
    }
  }
  if (k > 0) return data.wrenchResponseColumns(segs.head(3 * k), W.leftCols(3 * k), R.middleCols(na, 3 * k));
  return Status();
}

void WholeBodySolver::Impl::rows(const SolveInput& in) {
  const Matrix6X& acc = data.linkAccelerations();
  int row = 0;
  // One frame: rows alfa^T (Xdd0 + J R x) = beta for the 6 x cols alfa and beta given.
  auto frameRows = [&](const FrameRef& f, const Eigen::Ref<const Eigen::MatrixXd>& alfa,
                       const Eigen::Ref<const Eigen::VectorXd>& beta) {
    const Vector3 r = offset(data, f);
    const Vector6 a = acc.col(f.segment + 1);
    Vector6 x0;
    x0 << a.head<3>() + a.tail<3>().cross(r), a.tail<3>();
    (void)data.frameJacobian(f, J6);
    JR.leftCols(p).noalias() = J6 * R.leftCols(p);
    const long cols = alfa.cols();
    E.block(row, 0, cols, p).noalias() = alfa.transpose() * JR.leftCols(p);
    e.segment(row, cols) = beta;
    e.segment(row, cols).noalias() -= alfa.transpose() * x0;  // no temporary
    row += static_cast<int>(cols);
  };
  for (const ConstraintBlock& b : in.constraints) {
    if (b.columns == 0) continue;
    if (b.segment == kCenterOfMass) {
      comRows(in, b, row);
      continue;
    }
    const FrameRef f{b.segment, KDL::Frame(KDL::Vector(b.point(0), b.point(1), b.point(2)))};
    const auto alfa = b.alfa.leftCols(b.columns);
    Vector6 beta = b.beta;
    if (b.classical)
      beta.head(b.columns).noalias() =
          alfa.transpose() * spatialFromClassical(b.classical_acceleration, twistOf(data, f), in.gravity);
    frameRows(f, alfa, beta.head(b.columns));
  }
  const Eigen::Matrix<double, 6, 3> lin =
      (Eigen::Matrix<double, 6, 3>() << Matrix3::Identity(), Matrix3::Zero()).finished();
  for (const PointContact& pc : in.contacts) {
    const FrameRef f{pc.segment, KDL::Frame(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)))};
    const Vector3 beta = spatialFromClassical(Vector6::Zero(), twistOf(data, f), in.gravity).head<3>();
    frameRows(f, lin, beta);
  }
}

// A centre-of-mass block on a free-flyer: alfa_f^T (c_ddot - gravity) = beta with
// M (c_ddot - gravity) = F (the external forces, world axes) + sum_c lambda_c.
void WholeBodySolver::Impl::comRows(const SolveInput& in, const ConstraintBlock& b, int& row) {
  Vector3 force = in.f_ext.topRows<3>().rowwise().sum();
  for (const FrameWrench& w : in.wrenches) force += w.wrench.head<3>();
  const KDL::Rotation Rb = data.framePose(FrameRef{-1, KDL::Frame::Identity()}).M;
  const KDL::Vector fb = Rb * KDL::Vector(in.ff_torques(0), in.ff_torques(1), in.ff_torques(2));
  force += toVector3(fb);
  const auto alfa = b.alfa.topRows<3>().leftCols(b.columns);
  const int cols = b.columns;
  for (int c = 0; c < cols; ++c) {
    double beta = b.beta(c);
    if (b.classical) {
      const Vector3 g = toVector3(in.gravity);
      beta = alfa.col(c).dot(b.classical_acceleration.head<3>() - g);
    }
    E.row(row + c).head(p).setZero();
    for (int k3 = 0; k3 < k; ++k3) E.block(row + c, na + 3 * k3, 1, 3) = alfa.col(c).transpose() / mass;
    e(row + c) = beta - alfa.col(c).dot(force) / mass;
  }
  row += cols;
}

}  // namespace vereshchagin
