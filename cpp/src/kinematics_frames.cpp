// Pose, twist, Jacobian and bias acceleration of a frame (kinematics.hpp) from the base-frame
// sweep of kinematics.cpp. A body's spatial velocity V = [v_O; w] about the base origin O gives the
// velocity of its point at P as v_O + w x P; so does every Jacobian column.
#include "kinematics_impl.hpp"

namespace vereshchagin {

namespace {

KDL::Frame toFrame(const Pose& X) {
  return KDL::Frame(
      KDL::Rotation(X.R(0, 0), X.R(0, 1), X.R(0, 2), X.R(1, 0), X.R(1, 1), X.R(1, 2), X.R(2, 0), X.R(2, 1), X.R(2, 2)),
      KDL::Vector(X.p.x(), X.p.y(), X.p.z()));
}

// A motion vector about the base origin, moved to the point P: [v_O + w x P; w].
Vector6 atPoint(const Vector6& m, const Vector3& P) {
  Vector6 out;
  out.head<3>() = m.head<3>() + m.tail<3>().cross(P);
  out.tail<3>() = m.tail<3>();
  return out;
}

}  // namespace

Status framePose(const Model& model, KinematicsData& kdata, const FrameRef& frame, KDL::Frame& pose) {
  detail::KinematicsImpl& k = kdata.impl();
  if (const Status s = k.checkModel(model); !s) return s;
  if (const Status s = k.checkFrame(frame, false); !s) return s;
  pose = frame.segment < 0 ? frame.in_tip : toFrame(k.st[static_cast<std::size_t>(frame.segment)].X) * frame.in_tip;
  return Status();
}

Status frameTwist(const Model& model, KinematicsData& kdata, const FrameRef& frame, Vector6& twist) {
  detail::KinematicsImpl& k = kdata.impl();
  if (const Status s = k.checkModel(model); !s) return s;
  if (const Status s = k.checkFrame(frame, true); !s) return s;
  if (frame.segment < 0) {
    twist.setZero();
    return Status();
  }
  twist = atPoint(k.st[static_cast<std::size_t>(frame.segment)].V, k.origin(frame));
  return k.checkResult(twist);
}

Status frameJacobian(const Model& model, KinematicsData& kdata, const FrameRef& frame,
                     Eigen::Ref<Eigen::MatrixXd> jacobian) {
  detail::KinematicsImpl& k = kdata.impl();
  if (const Status s = k.checkModel(model); !s) return s;
  if (jacobian.rows() != 6 || jacobian.cols() != k.nj)
    return k.fail(Error::SizeMismatch, "jacobian is %ldx%ld, expected 6x%d", static_cast<long>(jacobian.rows()),
                  static_cast<long>(jacobian.cols()), k.nj);
  if (const Status s = k.checkFrame(frame, false); !s) return s;
  jacobian.setZero();
  if (frame.segment < 0) return Status();
  const Vector3 P = k.origin(frame);
  for (int i = frame.segment; i >= 0; i = k.seg[static_cast<std::size_t>(i)].parent) {
    const int j = k.seg[static_cast<std::size_t>(i)].joint;
    if (j >= 0) jacobian.col(j) = atPoint(k.st[static_cast<std::size_t>(i)].S, P);
  }
  return Status();
}

// In the base frame a joint axis moves with its body: dS_i/dt = V_i x S_i, so at q_ddot = 0 the
// spatial acceleration of segment i is A = sum over the joints on its path of V_k x S_k q_dot_k.
// The classical acceleration of the body point at P is then A_O + dw x P + w x v_P.
Status frameBiasAcceleration(const Model& model, KinematicsData& kdata, const FrameRef& frame, Vector6& bias) {
  detail::KinematicsImpl& k = kdata.impl();
  if (const Status s = k.checkModel(model); !s) return s;
  if (const Status s = k.checkFrame(frame, true); !s) return s;
  bias.setZero();
  if (frame.segment < 0) return Status();
  // q_dot of each joint is recovered from the velocities: V_i - V_parent = S_i q_dot_i.
  Vector6 A = Vector6::Zero();
  for (int i = frame.segment; i >= 0; i = k.seg[static_cast<std::size_t>(i)].parent) {
    const detail::KinState& x = k.st[static_cast<std::size_t>(i)];
    if (k.seg[static_cast<std::size_t>(i)].joint < 0) continue;
    const int p = k.seg[static_cast<std::size_t>(i)].parent;
    const Vector6 joint_rate = p < 0 ? x.V : Vector6(x.V - k.st[static_cast<std::size_t>(p)].V);
    A += crossMotion(x.V, joint_rate);
  }
  const Vector3 P = k.origin(frame);
  const Vector6& V = k.st[static_cast<std::size_t>(frame.segment)].V;
  const Vector3 w = V.tail<3>();
  const Vector3 v_P = V.head<3>() + w.cross(P);
  bias.head<3>() = A.head<3>() + A.tail<3>().cross(P) + w.cross(v_P);
  bias.tail<3>() = A.tail<3>();
  return k.checkResult(bias);
}

}  // namespace vereshchagin
