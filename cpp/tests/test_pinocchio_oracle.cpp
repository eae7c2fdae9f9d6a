// Kinematics (kinematics.hpp), the dynamics companions (dynamics.hpp) and the solver's free
// motion (data.hpp) against Pinocchio's C++ algorithms on the same robots (pinocchio_bridge.hpp):
// random chains and trees with fixed joints, prismatic joints, rotor inertia (Pinocchio's
// armature) and frames offset from the segment tips. Tolerance 1e-9 relative.
#include <doctest/doctest.h>

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include "pinocchio_bridge.hpp"
#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/kinematics.hpp"

namespace {

using namespace vereshchagin;
using testutil::relErr;
constexpr double kTol = 1e-9;
const KDL::Vector kGravity(0.4, -0.3, -9.81);

struct Case {
  Model ours;
  testutil::PinRobot pin;
  pinocchio::Data pdata;
  Eigen::VectorXd q, qd, qdd, pq, pv, pa;
  Case(testutil::RandomGen& g, int trial)
      : ours(testutil::randomOracleModel(g, trial)), pin(ours, kGravity), pdata(pin.model) {
    const unsigned n = ours.nrOfJoints();
    q = g.q(n).data;
    qd = g.qdot(n).data;
    qdd = g.jntArray(n, -3.0, 3.0).data;
    pq = pin.toPin(q);
    pv = pin.toPin(qd);
    pa = pin.toPin(qdd);
  }
  // Segment i's frame at offset `in_tip` as Pinocchio's placement in its joint's frame.
  pinocchio::SE3 placement(const FrameRef& f) const { return pin.tip[f.segment] * testutil::toSE3(f.in_tip); }
  Eigen::Index nv() const { return static_cast<Eigen::Index>(ours.nrOfJoints()); }
};

Eigen::MatrixXd columnsFromPin(const testutil::PinRobot& pin, const Eigen::MatrixXd& J) {
  Eigen::MatrixXd out(J.rows(), J.cols());
  for (Eigen::Index j = 0; j < J.cols(); ++j) out.col(j) = J.col(pin.v_index[j]);
  return out;
}

}  // namespace

TEST_CASE("inverse dynamics, mass matrix, gravity and Coriolis equal Pinocchio's rnea and crba") {
  testutil::RandomGen g(21);
  for (int trial = 0; trial < 40; ++trial) {
    Case c(g, trial);
    DynamicsData dd(c.ours);
    const Eigen::Index n = c.nv();
    Eigen::VectorXd tau(n), grav(n), cor(n);
    Eigen::MatrixXd H(n, n);
    REQUIRE(inverseDynamics(c.ours, dd, JointPositions(c.q), JointVelocities(c.qd), JointAccelerations(c.qdd),
                            Matrix6X(6, 0), kGravity, tau)
                .ok());
    REQUIRE(massMatrix(c.ours, dd, JointPositions(c.q), H).ok());
    REQUIRE(gravityTorques(c.ours, dd, JointPositions(c.q), kGravity, grav).ok());
    REQUIRE(coriolisTorques(c.ours, dd, JointPositions(c.q), JointVelocities(c.qd), cor).ok());

    const Eigen::VectorXd rnea = pinocchio::rnea(c.pin.model, c.pdata, c.pq, c.pv, c.pa);
    CHECK(relErr(tau, c.pin.fromPin(rnea)) < kTol);
    pinocchio::crba(c.pin.model, c.pdata, c.pq, pinocchio::Convention::WORLD);
    Eigen::MatrixXd M = c.pdata.M;
    M.triangularView<Eigen::StrictlyLower>() = M.transpose();
    CHECK(relErr(H, columnsFromPin(c.pin, columnsFromPin(c.pin, M).transpose())) < kTol);
    const Eigen::VectorXd g_pin = pinocchio::computeGeneralizedGravity(c.pin.model, c.pdata, c.pq);
    CHECK(relErr(grav, c.pin.fromPin(g_pin)) < kTol);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
    const Eigen::VectorXd nle = pinocchio::rnea(c.pin.model, c.pdata, c.pq, c.pv, zero) - g_pin;
    CHECK(relErr(cor, c.pin.fromPin(nle)) < kTol);
  }
}

TEST_CASE("poses, twists, Jacobians and Jdot qd of frames equal Pinocchio's, base axes") {
  testutil::RandomGen g(22);
  for (int trial = 0; trial < 40; ++trial) {
    Case c(g, trial);
    KinematicsData kd(c.ours);
    REQUIRE(forwardKinematics(c.ours, kd, JointPositions(c.q), JointVelocities(c.qd)).ok());
    pinocchio::forwardKinematics(c.pin.model, c.pdata, c.pq, c.pv, Eigen::VectorXd::Zero(c.nv()));
    pinocchio::computeJointJacobians(c.pin.model, c.pdata, c.pq);
    for (int k = 0; k < 4; ++k) {
      const FrameRef f{g.integer(0, static_cast<int>(c.ours.nrOfSegments()) - 1), k == 0 ? KDL::Frame() : g.frame()};
      const pinocchio::SE3 placement = c.placement(f);
      const pinocchio::JointIndex joint = c.pin.joint_of[f.segment];
      KDL::Frame pose;
      REQUIRE(framePose(c.ours, kd, f, pose).ok());
      const pinocchio::SE3 oMf = c.pdata.oMi[joint] * placement;
      CHECK(relErr(testutil::toSE3(pose).toHomogeneousMatrix(), oMf.toHomogeneousMatrix()) < kTol);

      Vector6 twist, bias;
      REQUIRE(frameTwist(c.ours, kd, f, twist).ok());
      const pinocchio::Motion v =
          pinocchio::getFrameVelocity(c.pin.model, c.pdata, joint, placement, pinocchio::LOCAL_WORLD_ALIGNED);
      CHECK(relErr(twist, v.toVector()) < kTol);
      REQUIRE(frameBiasAcceleration(c.ours, kd, f, bias).ok());
      const pinocchio::Motion a = pinocchio::getFrameClassicalAcceleration(c.pin.model, c.pdata, joint, placement,
                                                                           pinocchio::LOCAL_WORLD_ALIGNED);
      CHECK(relErr(bias, a.toVector()) < kTol);

      Eigen::MatrixXd J(6, c.nv()), Jp = Eigen::MatrixXd::Zero(6, c.nv());
      REQUIRE(frameJacobian(c.ours, kd, f, J).ok());
      pinocchio::getFrameJacobian(c.pin.model, c.pdata, joint, placement, pinocchio::LOCAL_WORLD_ALIGNED, Jp);
      CHECK(relErr(J, columnsFromPin(c.pin, Jp)) < kTol);
    }
  }
}

TEST_CASE("solve without constraints equals Pinocchio's aba") {
  testutil::RandomGen g(23);
  for (int trial = 0; trial < 40; ++trial) {
    Case c(g, trial);
    const Eigen::VectorXd tau = g.jntArray(c.ours.nrOfJoints(), -5.0, 5.0).data;
    SolveInput input(c.ours);
    input.setState(JointPositions(c.q), JointVelocities(c.qd));
    input.ff_torques = tau;
    input.gravity = kGravity;
    Data data(c.ours);
    REQUIRE(solve(c.ours, data, input).ok());
    const Eigen::VectorXd qdd = pinocchio::aba(c.pin.model, c.pdata, c.pq, c.pv, c.pin.toPin(tau));
    CHECK(relErr(data.qdd(), c.pin.fromPin(qdd)) < kTol);
  }
}
