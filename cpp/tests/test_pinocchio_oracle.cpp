// Kinematics (kinematics.hpp), the dynamics and energy companions (dynamics.hpp, energy.hpp) and
// the solver's free motion (data.hpp) against Pinocchio's C++ algorithms on the same robots
// (pinocchio_bridge.hpp), in one translation unit so that Pinocchio's templates are compiled once.
// Tolerance 1e-9 relative.
//  * Fixed bases: random chains and trees with fixed joints, prismatic joints, rotor inertia
//    (Pinocchio's armature) and frames offset from the segment tips: rnea, crba, gravity and
//    Coriolis, frame poses, twists, Jacobians and Jdot qd, aba. The kinetic energy against
//    1/2 v^T M v with crba (armature included), the potential energy against
//    computePotentialEnergy, and dT/dq against C(q, v)^T v with computeCoriolisMatrix (its C has
//    M_dot - 2 C skew, so C^T v = dT/dq); then the energy companions' errors.
//  * Floating bases (base_kind.hpp), a JointModelFreeFlyer / JointModelPlanar root on random
//    trees: the mass matrix against crba, inverse dynamics against rnea, the energies and dT/dq
//    (base rows included) as above, and Data::frameJacobian (base columns first) against
//    getFrameJacobian in LOCAL_WORLD_ALIGNED; then: the companions do not allocate.
#include <doctest/doctest.h>

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/energy.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include <cmath>

#include "alloc_counter.hpp"
#include "floating_fixture.hpp"
#include "pinocchio_bridge.hpp"
#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/energy.hpp"
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

double relScalar(double a, double b) {
  return std::abs(a - b) / std::max(1.0, std::abs(b));
}

Model floatingModel(BaseKind kind, testutil::RandomGen& g) {
  testutil::TreeSpec spec;
  spec.n_joints = 8;
  return testutil::floatingTreeModel(kind, g, spec, 2.5);
}

// q with a unit quaternion (free-flyer) or (cos, sin) (planar) in its base part.
Eigen::VectorXd floatingQ(const Model& m, testutil::RandomGen& g) {
  Eigen::VectorXd q(m.nq());
  q.head(m.nq() - m.nrOfJoints()) = g.qdot(m.nq() - m.nrOfJoints()).data;
  q.tail(m.nrOfJoints()) = g.q(m.nrOfJoints()).data;
  if (m.baseKind() == BaseKind::FreeFlyer) {
    q.segment<4>(3).normalize();
  } else {
    const double yaw = 3.0 * q(2);
    q.segment<2>(2) << std::cos(yaw), std::sin(yaw);
  }
  return q;
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

TEST_CASE("kinetic energy, potential energy and dT/dq equal Pinocchio's") {
  testutil::RandomGen g(31);
  for (int trial = 0; trial < 40; ++trial) {
    const Model ours = testutil::randomOracleModel(g, trial);
    testutil::PinRobot pin(ours, kGravity);
    pinocchio::Data pdata(pin.model);
    const unsigned n = ours.nrOfJoints();
    const Eigen::VectorXd q = g.q(n).data, qd = g.qdot(n).data;
    const Eigen::VectorXd pq = pin.toPin(q), pv = pin.toPin(qd);
    DynamicsData dd(ours);
    double T = 0.0, V = 0.0;
    Eigen::VectorXd dTdq(n);
    REQUIRE(kineticEnergy(ours, dd, JointPositions(q), JointVelocities(qd), T).ok());
    REQUIRE(potentialEnergy(ours, dd, JointPositions(q), kGravity, V).ok());
    REQUIRE(kineticEnergyGradient(ours, dd, JointPositions(q), JointVelocities(qd), dTdq).ok());

    pinocchio::crba(pin.model, pdata, pq, pinocchio::Convention::WORLD);
    Eigen::MatrixXd M = pdata.M;
    M.triangularView<Eigen::StrictlyLower>() = M.transpose();
    CHECK(relScalar(T, 0.5 * pv.dot(M * pv)) < kTol);
    // Pinocchio leaves out the universe's own body (segments fixed to the base, merged into it):
    // its weight does not move, but our V counts it.
    const pinocchio::Inertia& fixed = pin.model.inertias[0];
    const double V_fixed = -fixed.mass() * pin.model.gravity.linear().dot(fixed.lever());
    CHECK(relScalar(V, pinocchio::computePotentialEnergy(pin.model, pdata, pq) + V_fixed) < kTol);
    const Eigen::MatrixXd C = pinocchio::computeCoriolisMatrix(pin.model, pdata, pq, pv);
    CHECK(relErr(dTdq, pin.fromPin(C.transpose() * pv)) < kTol);
  }
}

TEST_CASE("energy companions: bad input is an error with a message, never a crash") {
  testutil::RandomGen g(32);
  const Model m(g.chain(4));
  DynamicsData dd(m);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(4), short_q = Eigen::VectorXd::Zero(3);
  Eigen::VectorXd nan_qd = Eigen::VectorXd::Zero(4), out(4), out_short(3);
  nan_qd(2) = std::nan("");
  double e = 0.0;
  CHECK(kineticEnergy(m, dd, JointPositions(short_q), JointVelocities(q), e).code() == Error::SizeMismatch);
  CHECK(kineticEnergy(m, dd, JointPositions(q), JointVelocities(nan_qd), e).code() == Error::NonfiniteInput);
  CHECK(potentialEnergy(m, dd, JointPositions(q), KDL::Vector(0, 0, std::nan("")), e).code() == Error::NonfiniteInput);
  CHECK(kineticEnergyGradient(m, dd, JointPositions(q), JointVelocities(q), out_short).code() == Error::SizeMismatch);
  const Model other(g.chain(4));
  CHECK(kineticEnergy(other, dd, JointPositions(q), JointVelocities(q), e).code() == Error::NotUpToDate);
  CHECK(kineticEnergy(m, dd, JointPositions(short_q), JointVelocities(q), e).message()[0] != 0);
}

TEST_CASE("floating base: H, inverse dynamics and the energies equal Pinocchio's") {
  testutil::RandomGen g(28);
  for (int trial = 0; trial < 20; ++trial) {
    const Model ours = floatingModel(trial % 2 ? BaseKind::Planar : BaseKind::FreeFlyer, g);
    REQUIRE(ours.status());
    testutil::PinRobot pin(ours, kGravity);
    pinocchio::Data pdata(pin.model);
    const int nv = static_cast<int>(ours.nv());
    const Eigen::VectorXd q = floatingQ(ours, g), v = g.qdot(nv).data, a = g.qdot(nv).data;
    const Eigen::VectorXd pq = pin.toPinQ(q), pv = pin.toPin(v), pa = pin.toPin(a);
    DynamicsData dd(ours);
    Eigen::MatrixXd H(nv, nv);
    Eigen::VectorXd tau(nv), dTdq(nv);
    const Matrix6X none(6, 0);
    double T = 0.0, V = 0.0;
    REQUIRE(massMatrix(ours, dd, JointPositions(q), H).ok());
    REQUIRE(inverseDynamics(ours, dd, JointPositions(q), JointVelocities(v), JointAccelerations(a), none, kGravity, tau)
                .ok());
    REQUIRE(kineticEnergy(ours, dd, JointPositions(q), JointVelocities(v), T).ok());
    REQUIRE(potentialEnergy(ours, dd, JointPositions(q), kGravity, V).ok());
    REQUIRE(kineticEnergyGradient(ours, dd, JointPositions(q), JointVelocities(v), dTdq).ok());

    pinocchio::crba(pin.model, pdata, pq);
    Eigen::MatrixXd M = pdata.M;
    M.triangularView<Eigen::StrictlyLower>() = M.transpose();
    Eigen::MatrixXd M_ours(nv, nv);  // Pinocchio's M in our order
    for (int c = 0; c < nv; ++c) M_ours.col(c) = pin.fromPin(M * pin.toPin(Eigen::VectorXd::Unit(nv, c)));
    CHECK(relErr(H, M_ours) < kTol);
    CHECK(relErr(tau, pin.fromPin(pinocchio::rnea(pin.model, pdata, pq, pv, pa))) < kTol);
    CHECK(relScalar(T, 0.5 * pv.dot(M * pv)) < kTol);
    CHECK(relScalar(V, pinocchio::computePotentialEnergy(pin.model, pdata, pq)) < kTol);
    const Eigen::MatrixXd C = pinocchio::computeCoriolisMatrix(pin.model, pdata, pq, pv);
    CHECK(relErr(dTdq, pin.fromPin(C.transpose() * pv)) < kTol);
  }
}

TEST_CASE("floating base: the dynamics and energy companions do not allocate") {
  testutil::RandomGen g(29);
  for (BaseKind kind : {BaseKind::FreeFlyer, BaseKind::Planar}) {
    const Model m = floatingModel(kind, g);
    const int nv = static_cast<int>(m.nv());
    const Eigen::VectorXd q = floatingQ(m, g), v = g.qdot(nv).data;
    DynamicsData dd(m);
    Eigen::MatrixXd H(nv, nv);
    Eigen::VectorXd tau(nv);
    const Matrix6X f_ext = Matrix6X::Constant(6, m.nrOfSegments(), 0.5);
    double e = 0.0;
    const long before = g_new_calls.load() + g_malloc_calls.load();
    for (int it = 0; it < 5; ++it) {
      CHECK(massMatrix(m, dd, JointPositions(q), H).ok());
      CHECK(inverseDynamics(m, dd, JointPositions(q), JointVelocities(v), JointAccelerations(v), f_ext, kGravity, tau)
                .ok());
      CHECK(gravityTorques(m, dd, JointPositions(q), kGravity, tau).ok());
      CHECK(coriolisTorques(m, dd, JointPositions(q), JointVelocities(v), tau).ok());
      CHECK(kineticEnergyGradient(m, dd, JointPositions(q), JointVelocities(v), tau).ok());
      CHECK(potentialEnergy(m, dd, JointPositions(q), kGravity, e).ok());
    }
    CHECK(g_new_calls.load() + g_malloc_calls.load() == before);
    Eigen::VectorXd bad = q;
    bad(kind == BaseKind::FreeFlyer ? 6 : 2) *= 1.5;
    CHECK(massMatrix(m, dd, JointPositions(bad), H).code() == Error::NonfiniteInput);
    CHECK(massMatrix(m, dd, JointPositions(q.tail(m.nrOfJoints())), H).code() == Error::SizeMismatch);
  }
}

TEST_CASE("floating base: Data::frameJacobian equals Pinocchio's getFrameJacobian") {
  testutil::RandomGen g(30);
  for (int trial = 0; trial < 6; ++trial) {
    const Model ours = floatingModel(trial % 2 ? BaseKind::Planar : BaseKind::FreeFlyer, g);
    testutil::PinRobot pin(ours, kGravity);
    const int ns = static_cast<int>(ours.nrOfSegments()), nv = static_cast<int>(ours.nv());
    std::vector<pinocchio::FrameIndex> frames;
    for (int i = 0; i < ns; ++i)
      frames.push_back(pin.model.addFrame(
          pinocchio::Frame("tip" + std::to_string(i), pin.joint_of[i], pin.tip[i], pinocchio::FrameType::OP_FRAME)));
    pinocchio::Data pdata(pin.model);
    const Eigen::VectorXd q = floatingQ(ours, g), v = g.qdot(nv).data;
    Data data(ours);
    SolveInput in(ours);
    in.q = q;
    in.q_dot = v;
    REQUIRE(solve(ours, data, in));
    pinocchio::computeJointJacobians(pin.model, pdata, pin.toPinQ(q));
    pinocchio::updateFramePlacements(pin.model, pdata);
    Eigen::MatrixXd J(6, nv), Jp = Eigen::MatrixXd::Zero(6, nv), Jp_ours(6, nv);
    for (int i = 0; i < ns; ++i) {
      REQUIRE(data.frameJacobian(FrameRef{i, KDL::Frame::Identity()}, J).ok());
      Jp.setZero();
      pinocchio::getFrameJacobian(pin.model, pdata, frames[i], pinocchio::LOCAL_WORLD_ALIGNED, Jp);
      for (int c = 0; c < nv; ++c) Jp_ours.col(c) = Jp * pin.toPin(Eigen::VectorXd::Unit(nv, c));
      CHECK(relErr(J, Jp_ours) < kTol);
    }
    Eigen::MatrixXd short_J(6, ours.nrOfJoints());
    CHECK(data.frameJacobian(FrameRef{0, KDL::Frame::Identity()}, short_J).code() == Error::SizeMismatch);
  }
}
