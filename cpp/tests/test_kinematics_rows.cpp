// kinematics_rows.cpp (kinematics.hpp): poses as homogeneous matrices and back with every message of
// poseFromArray, and framePoses, frameTwists and segmentPoses equal row by row to the one-state
// functions; frameTwist's overflow.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "kuka_lwr4.hpp"
#include "vereshchagin/kinematics.hpp"

namespace {

namespace vs = vereshchagin;

vs::ArrayArg array4x4(const vs::Homogeneous& T) {
  vs::ArrayArg a;
  a.data = T.data();
  a.ndim = 2;
  a.shape[0] = a.shape[1] = 4;
  return a;
}

}  // namespace

TEST_CASE("poses become homogeneous matrices and matrices poses, or say why not") {
  const KDL::Frame pose(KDL::Rotation::RPY(0.1, -0.4, 2.0), KDL::Vector(1.0, -2.0, 0.5));
  const vs::Homogeneous T = vs::homogeneous(pose);
  CHECK(T.row(3) == Eigen::RowVector4d(0, 0, 0, 1));
  KDL::Frame back;
  CHECK(vs::poseFromArray(array4x4(T), "T", back).empty());
  CHECK(back == pose);
  vs::Homogeneous bad = T;
  bad(3, 3) = 2.0;
  CHECK(vs::poseFromArray(array4x4(bad), "T", back) == "T must have last row [0, 0, 0, 1]");
  bad = T;
  bad(0, 0) = -bad(0, 0);
  CHECK(vs::poseFromArray(array4x4(bad), "T", back) ==
        "T: the upper-left 3x3 block must be a rotation matrix (orthonormal, det +1)");
  bad = T;
  bad(1, 2) = NAN;
  CHECK(vs::poseFromArray(array4x4(bad), "T", back) == "T contains NaN or Inf (flat index 6)");
  vs::ArrayArg flat = array4x4(T);
  flat.ndim = 1;
  flat.shape[0] = 16;
  CHECK(vs::poseFromArray(flat, "T", back) == "T must be a 4x4 homogeneous transform, got shape (16,)");
  CHECK(back == pose);  // unchanged by the failures
}

TEST_CASE("several states at once equal one state at a time") {
  const vs::Model model(testutil::kukaLwr4());
  vs::KinematicsData kd(model), ref(model);
  const int n = static_cast<int>(model.nrOfJoints()), ns = static_cast<int>(model.nrOfSegments());
  vs::JointRows q(3, n), qd(3, n);
  for (int r = 0; r < 3; ++r) {
    for (int j = 0; j < n; ++j) {
      q(r, j) = 0.1 * (r + 1) * (j - 3);
      qd(r, j) = 0.3 - 0.05 * r * j;
    }
  }
  const vs::FrameRef frame{ns - 1, KDL::Frame(KDL::Vector(0.0, 0.0, 0.1))};
  vs::PoseRows poses(3, 16);
  vs::TwistRows twists(3, 6);
  REQUIRE(vs::framePoses(model, kd, q, frame, poses).ok());
  REQUIRE(vs::frameTwists(model, kd, q, qd, frame, twists).ok());
  for (int r = 0; r < 3; ++r) {
    const Eigen::VectorXd qr = q.row(r).transpose(), qdr = qd.row(r).transpose();
    REQUIRE(vs::forwardKinematics(model, ref, vs::JointPositions(qr), vs::JointVelocities(qdr)).ok());
    KDL::Frame pose;
    vs::Vector6 twist;
    REQUIRE(vs::framePose(model, ref, frame, pose).ok());
    REQUIRE(vs::frameTwist(model, ref, frame, twist).ok());
    CHECK(Eigen::Map<const vs::Homogeneous>(poses.row(r).data()) == vs::homogeneous(pose));
    CHECK(twists.row(r) == twist.transpose());
  }
  vs::PoseRows all(ns, 16);
  const Eigen::VectorXd q0 = q.row(0).transpose();
  REQUIRE(vs::segmentPoses(model, kd, vs::JointPositions(q0), all).ok());
  REQUIRE(vs::forwardKinematics(model, ref, vs::JointPositions(q0)).ok());
  for (int i = 0; i < ns; ++i) {
    KDL::Frame pose;
    REQUIRE(vs::framePose(model, ref, vs::FrameRef{i, KDL::Frame::Identity()}, pose).ok());
    CHECK(Eigen::Map<const vs::Homogeneous>(all.row(i).data()) == vs::homogeneous(pose));
  }
  vs::TwistRows two(2, 6);
  CHECK(vs::frameTwists(model, kd, q, qd, frame, two).code() == vs::Error::SizeMismatch);
  vs::PoseRows wrong(ns + 1, 16);
  CHECK(vs::segmentPoses(model, kd, vs::JointPositions(q0), wrong).code() == vs::Error::SizeMismatch);
  qd.setConstant(1e308);
  const vs::Status s = vs::frameTwists(model, kd, q, qd, frame, twists);
  CHECK(s.code() == vs::Error::NonfiniteResult);
  CHECK(std::string(s.message()) == "the result overflows the double range");
}
