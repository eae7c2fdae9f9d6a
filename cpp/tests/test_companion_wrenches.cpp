// addFrameWrench (dynamics.hpp): a wrench about a point of a segment's frame moved to the tip, by
// hand on a one-joint arm, and on random trees against the Jacobian of that point (its generalized
// force J_P^T w is what inverseDynamics subtracts); then its errors.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <kdl/chain.hpp>

#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/dynamics.hpp"

namespace {

namespace vs = vereshchagin;

// A revolute z joint whose 1 m link points along x, then a fixed segment.
KDL::Chain oneJointArm() {
  KDL::Chain chain;
  const KDL::RigidBodyInertia inertia(1.0, KDL::Vector(0.5, 0.0, 0.0), KDL::RotationalInertia(0.1, 0.1, 0.1));
  chain.addSegment(KDL::Segment("arm", KDL::Joint(KDL::Joint::RotZ), KDL::Frame(KDL::Vector(1.0, 0.0, 0.0)), inertia));
  chain.addSegment(KDL::Segment("tool", KDL::Joint(KDL::Joint::Fixed), KDL::Frame(KDL::Vector(0.0, 0.0, 0.2))));
  return chain;
}

}  // namespace

TEST_CASE("a wrench about a point is moved to the tip by hand") {
  const vs::Model model(oneJointArm());
  REQUIRE(model.status().ok());
  vs::KinematicsData kd(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, M_PI / 2);  // the tip axes turned by +90 deg about z
  REQUIRE(vs::forwardKinematics(model, kd, vs::JointPositions(q)).ok());
  const vs::FrameRef frame{0, KDL::Frame(KDL::Rotation::RotX(0.3), KDL::Vector(0.5, 0.0, 0.0))};  // half way back
  vs::Vector6 wrench;
  wrench << 0.0, 0.0, -10.0, 1.0, 2.0, 3.0;  // 10 N down, moment about the frame's origin
  vs::Matrix6X f_ext = vs::Matrix6X::Ones(6, 2);
  REQUIRE(vs::addFrameWrench(model, kd, frame, wrench, f_ext).ok());
  // The origin is (0, 0.5, 0) from the tip in base axes: n_tip = n + (0, 0.5, 0) x (0, 0, -10) =
  // (1, 2, 3) + (-5, 0, 0); column 0 had ones already.
  vs::Vector6 expected;
  expected << 1.0, 1.0, -9.0, -3.0, 3.0, 4.0;
  CHECK(testutil::relErr(f_ext.col(0), expected) < 1e-15);
  CHECK(f_ext.col(1) == vs::Vector6::Ones());
}

TEST_CASE("inverse dynamics with a moved wrench subtracts J_P^T w on random trees") {
  for (unsigned long long seed = 1; seed <= 20; ++seed) {
    CAPTURE(seed);
    testutil::RandomGen g(seed);
    testutil::TreeSpec spec;
    spec.n_joints = g.integer(1, 12);
    const vs::Model model(testutil::randomTree(g, spec));
    REQUIRE(model.status().ok());
    vs::DynamicsData dd(model);
    const unsigned int n = model.nrOfJoints();
    const int ns = static_cast<int>(model.nrOfSegments());
    const Eigen::VectorXd q = g.q(n).data, qd = g.qdot(n).data, qdd = g.torques(n).data;
    const KDL::Vector gravity = g.vector(-10.0, 10.0);
    Eigen::VectorXd tau0(n), tau(n), expected(n);
    REQUIRE(vs::inverseDynamics(model, dd, vs::JointPositions(q), vs::JointVelocities(qd), vs::JointAccelerations(qdd),
                                vs::Matrix6X(6, 0), gravity, tau0)
                .ok());
    vs::Matrix6X f_ext = vs::Matrix6X::Zero(6, ns);
    expected = tau0;
    Eigen::MatrixXd J(6, n);
    for (int k = 0; k < 3; ++k) {  // three wrenches, possibly on one segment
      const vs::FrameRef frame{g.integer(0, ns - 1), g.frame(0.7)};
      vs::Vector6 wrench;
      for (int r = 0; r < 6; ++r) wrench(r) = g.uniform(-3.0, 3.0);
      REQUIRE(vs::addFrameWrench(model, dd.kinematics(), frame, wrench, f_ext).ok());
      REQUIRE(vs::frameJacobian(model, dd.kinematics(), frame, J).ok());
      expected -= J.transpose() * wrench;
    }
    REQUIRE(vs::inverseDynamics(model, dd, vs::JointPositions(q), vs::JointVelocities(qd), vs::JointAccelerations(qdd),
                                f_ext, gravity, tau)
                .ok());
    CHECK(testutil::relErr(tau, expected) < 1e-9);
  }
}

TEST_CASE("addFrameWrench refuses a missing state, the base, a wrong size and NaN") {
  const vs::Model model(oneJointArm()), other(oneJointArm());
  vs::KinematicsData kd(model);
  vs::Matrix6X f_ext = vs::Matrix6X::Zero(6, 2), narrow = vs::Matrix6X::Zero(6, 1);
  vs::FrameRef frame{1};
  vs::Vector6 wrench = vs::Vector6::Ones();
  CHECK(vs::addFrameWrench(model, kd, frame, wrench, f_ext).code() == vs::Error::NoSolution);
  REQUIRE(vs::forwardKinematics(model, kd, vs::JointPositions(Eigen::VectorXd::Zero(1))).ok());
  CHECK(vs::addFrameWrench(other, kd, frame, wrench, f_ext).code() == vs::Error::NotUpToDate);
  CHECK(vs::addFrameWrench(model, kd, frame, wrench, narrow).code() == vs::Error::SizeMismatch);
  for (const int bad : {-1, 2}) {
    frame.segment = bad;
    const vs::Status s = vs::addFrameWrench(model, kd, frame, wrench, f_ext);
    CHECK(s.code() == vs::Error::OutOfRange);
    CHECK(std::string(s.message()).find("out of range [0, 2)") != std::string::npos);
  }
  frame.segment = 0;
  frame.in_tip.p.x(NAN);
  CHECK(vs::addFrameWrench(model, kd, frame, wrench, f_ext).code() == vs::Error::NonfiniteInput);
  frame.in_tip.p.x(0.0);
  wrench(4) = INFINITY;
  CHECK(vs::addFrameWrench(model, kd, frame, wrench, f_ext).code() == vs::Error::NonfiniteInput);
  CHECK(f_ext.isZero(0.0));  // nothing added on a failure
}
