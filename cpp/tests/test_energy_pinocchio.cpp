// The energy companions (energy.hpp) against Pinocchio's C++ algorithms on random chains and trees
// (pinocchio_bridge.hpp): the kinetic energy against 1/2 v^T M v with Pinocchio's crba (armature
// included), the potential energy against computePotentialEnergy, and dT/dq against C(q, v)^T v
// with Pinocchio's computeCoriolisMatrix (its C has M_dot - 2 C skew, so C^T v = dT/dq).
// Tolerance 1e-9 relative. Then the errors.
#include <doctest/doctest.h>

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/energy.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include <cmath>

#include "pinocchio_bridge.hpp"
#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/energy.hpp"

namespace {

using namespace vereshchagin;
using testutil::relErr;
constexpr double kTol = 1e-9;
const KDL::Vector kGravity(0.4, -0.3, -9.81);

double relScalar(double a, double b) {
  return std::abs(a - b) / std::max(1.0, std::abs(b));
}

}  // namespace

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
