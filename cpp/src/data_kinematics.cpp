// Data's kinematics at the last solve's state (data.hpp): from the poses X_i (tip in parent tip)
// and rotations R_base_i the outward sweep stored, walking from the frame's segment to the base:
// O(depth), no allocation. On a floating base, in the world frame (the base's pose included).
#include "vereshchagin/data.hpp"

#include "data_impl.hpp"

namespace vereshchagin {

namespace {

using detail::HdCore;

Vector3 toVector3(const KDL::Vector& v) {
  return Vector3(v.x(), v.y(), v.z());
}

// Rotation of the base frame: the identity, or a floating base's orientation in the world.
Matrix3 baseRotation(const HdCore& c) {
  return c.model.floating ? c.ws.base.X.R : Matrix3::Identity();
}

// Rotation of a segment's parent tip frame in the base (the world on a floating base).
Matrix3 parentRotation(const HdCore& c, int i) {
  const int p = c.model.parent(i);
  return p >= 0 ? c.ws.seg[p].R_base : baseRotation(c);
}

// Origin of frame (segment, in_tip) in base coordinates (world coordinates on a floating base).
Vector3 frameOrigin(const HdCore& c, const FrameRef& frame) {
  const Vector3 base = c.model.floating ? c.ws.base.X.p : Vector3::Zero();
  if (frame.segment < 0) return base + baseRotation(c) * toVector3(frame.in_tip.p);
  Vector3 p = base + c.ws.seg[frame.segment].R_base * toVector3(frame.in_tip.p);
  for (int i = frame.segment; i >= 0; i = c.model.parent(i)) p += parentRotation(c, i) * c.ws.seg[i].X.p;
  return p;
}

}  // namespace

KDL::Frame Data::framePose(const FrameRef& frame) const {
  const HdCore& c = impl_->core;
  const Matrix3 R = frame.segment >= 0 ? c.ws.seg[frame.segment].R_base : baseRotation(c);
  const Vector3 p = frameOrigin(c, frame);
  const KDL::Rotation Rb(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
  return KDL::Frame(Rb * frame.in_tip.M, KDL::Vector(p(0), p(1), p(2)));
}

// The tip's spatial velocity (tip axes, tip origin) in base axes, moved to the frame's origin.
KDL::Twist Data::frameTwist(const FrameRef& frame) const {
  const HdCore& c = impl_->core;
  if (frame.segment < 0 && !c.model.floating) return KDL::Twist::Zero();
  const bool base = frame.segment < 0;  // a floating base's own frames
  const Matrix3& R = base ? c.ws.base.X.R : c.ws.seg[frame.segment].R_base;
  const Vector6& vel = base ? c.ws.base.v : c.ws.seg[frame.segment].v;
  const Vector3 w = R * vel.tail<3>();
  const Vector3 r = R * toVector3(frame.in_tip.p);
  const Vector3 v = R * vel.head<3>() + w.cross(r);
  return KDL::Twist(KDL::Vector(v(0), v(1), v(2)), KDL::Vector(w(0), w(1), w(2)));
}

// Column of joint j (segment k on the path): S_k in base axes, moved from k's tip origin to the
// frame's origin: [R v + (R w) x d; R w], d = origin(k) - origin(frame).
namespace {

// A floating base's columns: its LOCAL twist S_b qd_b = (v, w) moves the frame's origin o by
// R_b v + (R_b w) x (o - p_b) and turns the frame by R_b w (world axes).
void baseColumns(const HdCore& c, const FrameRef& frame, Eigen::Ref<Eigen::MatrixXd> J) {
  const Matrix3& R = c.ws.base.X.R;
  const Vector3 r = frameOrigin(c, frame) - c.ws.base.X.p;
  Matrix6 B;
  B << R, -skew(r) * R, Matrix3::Zero(), R;
  J.noalias() = B * c.model.S_base;
}

}  // namespace

Status Data::frameJacobian(const FrameRef& frame, Eigen::Ref<Eigen::MatrixXd> jacobian) const {
  HdCore& c = impl_->core;
  const int nb = c.model.floating ? c.model.nbv : 0;  // a floating base's columns first
  if (jacobian.rows() != 6 || jacobian.cols() != static_cast<Eigen::Index>(c.model.nj) + nb)
    return impl_->status(c.fail(KDL::SolverI::E_SIZE_MISMATCH, "jacobian is %ldx%ld, expected 6x%u",
                                (long)jacobian.rows(), (long)jacobian.cols(), c.model.nj + nb));
  if (frame.segment >= static_cast<int>(c.model.ns))
    return impl_->status(
        c.fail(KDL::SolverI::E_OUT_OF_RANGE, "frame.segment = %d is out of range [-1, %u)", frame.segment, c.model.ns));
  jacobian.setZero();
  if (nb != 0) baseColumns(c, frame, jacobian.leftCols(nb));
  if (frame.segment < 0) return Status();
  // d: from the frame's origin to the current segment's tip origin, base axes.
  Vector3 d = -(c.ws.seg[frame.segment].R_base * toVector3(frame.in_tip.p));
  for (int i = frame.segment; i >= 0; i = c.model.parent(i)) {
    const detail::SegmentModel& sm = c.model.seg[i];
    const Matrix3& R = c.ws.seg[i].R_base;
    if (sm.joint >= 0) {
      const Vector3 w = R * sm.S.tail<3>();
      jacobian.col(nb + sm.joint).head<3>() = R * sm.S.head<3>() + w.cross(-d);
      jacobian.col(nb + sm.joint).tail<3>() = w;
    }
    d -= parentRotation(c, i) * c.ws.seg[i].X.p;  // to the parent's tip origin
  }
  return Status();
}

}  // namespace vereshchagin
