// The dynamics and energy companions on a floating base (dynamics.hpp, energy.hpp, base_kind.hpp)
// against Pinocchio's C++ algorithms with a JointModelFreeFlyer / JointModelPlanar root
// (pinocchio_bridge.hpp) on random trees: the mass matrix against crba, inverse dynamics against
// rnea, the kinetic energy against 1/2 v^T M v, the potential energy against
// computePotentialEnergy and dT/dq (base rows included) against C(q, v)^T v of
// computeCoriolisMatrix, and Data::frameJacobian (base columns first) against getFrameJacobian in
// LOCAL_WORLD_ALIGNED. Tolerance 1e-9 relative. Then: the companions do not allocate.
#include <doctest/doctest.h>

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/energy.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include <cmath>

#include "alloc_counter.hpp"
#include "pinocchio_bridge.hpp"
#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/energy.hpp"

namespace {

using namespace vereshchagin;
using testutil::relErr;
constexpr double kTol = 1e-9;
const KDL::Vector kGravity(0.4, -0.3, -9.81);

Model floatingModel(BaseKind kind, testutil::RandomGen& g) {
  testutil::TreeSpec spec;
  spec.n_joints = 8;
  ModelOptions options;
  options.base = kind;
  options.base_inertia = KDL::RigidBodyInertia(2.5, KDL::Vector(0.05, -0.02, 0.01),
                                               KDL::RotationalInertia(0.2, 0.3, 0.25, 0.01, 0.0, -0.02));
  return Model(testutil::randomTree(g, spec), "", options);
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

double relScalar(double a, double b) {
  return std::abs(a - b) / std::max(1.0, std::abs(b));
}

}  // namespace

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
