// Kinematics of several states at once and poses as homogeneous matrices (kinematics.hpp): the
// loops and layouts behind the batched fk and twist of the Python companions, one state per row.
#include <cmath>
#include <string>

#include "kinematics_impl.hpp"

namespace vereshchagin {

namespace {

Eigen::Map<const Eigen::VectorXd> row(const Eigen::Ref<const JointRows>& rows, Eigen::Index r) {
  return Eigen::Map<const Eigen::VectorXd>(rows.row(r).data(), rows.cols());
}

}  // namespace

Homogeneous homogeneous(const KDL::Frame& pose) {
  Homogeneous T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T(r, c) = r < 3 ? (c < 3 ? pose.M(r, c) : pose.p(r)) : (c == 3 ? 1.0 : 0.0);
  return T;
}

std::string poseFromArray(const ArrayArg& T, const char* name, KDL::Frame& pose) {
  if (T.ndim != 2 || T.shape[0] != 4 || T.shape[1] != 4)
    return std::string(name) + " must be a 4x4 homogeneous transform, got shape " + T.shapeString();
  if (std::string why = nonfiniteMessage(T, name); !why.empty()) return why;
  const Eigen::Map<const Homogeneous> t(T.data);
  if (std::abs(t(3, 0)) > 1e-12 || std::abs(t(3, 1)) > 1e-12 || std::abs(t(3, 2)) > 1e-12 ||
      std::abs(t(3, 3) - 1.0) > 1e-12)
    return std::string(name) + " must have last row [0, 0, 0, 1]";
  const Matrix3 R = t.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Matrix3::Identity()).cwiseAbs().maxCoeff() > 1e-9 || R.determinant() < 0.0)
    return std::string(name) + ": the upper-left 3x3 block must be a rotation matrix (orthonormal, det +1)";
  pose = KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
                    KDL::Vector(t(0, 3), t(1, 3), t(2, 3)));
  return "";
}

Status framePoses(const Model& model, KinematicsData& kdata, const Eigen::Ref<const JointRows>& q,
                  const FrameRef& frame, Eigen::Ref<PoseRows> poses) {
  if (poses.rows() != q.rows())
    return kdata.impl().fail(Error::SizeMismatch, "poses has %ld rows, q has %ld", static_cast<long>(poses.rows()),
                             static_cast<long>(q.rows()));
  KDL::Frame pose;
  for (Eigen::Index r = 0; r < q.rows(); ++r) {
    if (const Status s = forwardKinematics(model, kdata, JointPositions(row(q, r))); !s) return s;
    if (const Status s = framePose(model, kdata, frame, pose); !s) return s;
    Eigen::Map<Homogeneous>(poses.row(r).data()) = homogeneous(pose);
  }
  return Status();
}

Status frameTwists(const Model& model, KinematicsData& kdata, const Eigen::Ref<const JointRows>& q,
                   const Eigen::Ref<const JointRows>& q_dot, const FrameRef& frame, Eigen::Ref<TwistRows> twists) {
  if (q_dot.rows() != q.rows() || twists.rows() != q.rows())
    return kdata.impl().fail(Error::SizeMismatch, "q has %ld rows, q_dot %ld and twists %ld",
                             static_cast<long>(q.rows()), static_cast<long>(q_dot.rows()),
                             static_cast<long>(twists.rows()));
  Vector6 twist;
  for (Eigen::Index r = 0; r < q.rows(); ++r) {
    if (const Status s = forwardKinematics(model, kdata, JointPositions(row(q, r)), JointVelocities(row(q_dot, r))); !s)
      return s;
    if (const Status s = frameTwist(model, kdata, frame, twist); !s) return s;
    twists.row(r) = twist.transpose();
  }
  return Status();
}

Status segmentPoses(const Model& model, KinematicsData& kdata, const JointPositions& q, Eigen::Ref<PoseRows> poses) {
  if (const Status s = forwardKinematics(model, kdata, q); !s) return s;
  const int ns = kdata.impl().ns;
  if (poses.rows() != ns)
    return kdata.impl().fail(Error::SizeMismatch, "poses has %ld rows, expected %d (one per segment)",
                             static_cast<long>(poses.rows()), ns);
  KDL::Frame pose;
  for (int i = 0; i < ns; ++i) {
    if (const Status s = framePose(model, kdata, FrameRef{i, KDL::Frame::Identity()}, pose); !s) return s;
    Eigen::Map<Homogeneous>(poses.row(i).data()) = homogeneous(pose);
  }
  return Status();
}

}  // namespace vereshchagin
