// The symplectic step (src/symplectic_step.hpp, the Simulator's Integrator::Symplectic): without
// friction it equals a dense symplectic Euler in momentum form built from massMatrix,
// gravityTorques and kineticEnergyGradient (checked against Pinocchio in test_energy_pinocchio);
// a passive chain's energy stays bounded where semi-implicit Euler (step()) gains; a chain held by
// friction keeps q bitwise with one solve per step; the iteration bound's fallback is Degraded.
#include <doctest/doctest.h>

#include <cmath>

#include <Eigen/Dense>

#include "../src/symplectic_step.hpp"
#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/energy.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

const KDL::Vector kGravity(0.0, 0.0, -9.81);
const Eigen::Map<const Matrix6X> kNone(nullptr, 6, 0);

Eigen::MatrixXd mass(const Model& m, DynamicsData& dd, const Eigen::VectorXd& q) {
  Eigen::MatrixXd H(m.nrOfJoints(), m.nrOfJoints());
  REQUIRE(massMatrix(m, dd, JointPositions(q), H));
  return H;
}

// E(q, H(q)^-1 p): the energy of the momentum state.
double energy(const Model& m, DynamicsData& dd, const Eigen::VectorXd& q, const Eigen::VectorXd& p) {
  const Eigen::VectorXd v = mass(m, dd, q).ldlt().solve(p);
  double T = 0.0, V = 0.0;
  REQUIRE(kineticEnergy(m, dd, JointPositions(q), JointVelocities(v), T));
  REQUIRE(potentialEnergy(m, dd, JointPositions(q), kGravity, V));
  return T + V;
}

// Dense symplectic Euler: H u+ = p + dt (tau - g + dT/dq(q, u+)), fixed point to 1e-14.
Eigen::VectorXd denseStep(const Model& m, DynamicsData& dd, const Eigen::VectorXd& q, const Eigen::VectorXd& u,
                          const Eigen::VectorXd& p, const Eigen::VectorXd& tau, double dt) {
  const Eigen::LDLT<Eigen::MatrixXd> H(mass(m, dd, q));
  Eigen::VectorXd g(u.size()), t(u.size()), it = u;
  REQUIRE(gravityTorques(m, dd, JointPositions(q), kGravity, g));
  for (int k = 0; k < 200; ++k) {
    REQUIRE(kineticEnergyGradient(m, dd, JointPositions(q), JointVelocities(it), t));
    const Eigen::VectorXd next = H.solve(p + dt * (tau - g + t));
    if ((next - it).lpNorm<Eigen::Infinity>() < 1e-15 * std::max(1.0, next.lpNorm<Eigen::Infinity>())) return next;
    it = next;
  }
  return it;
}

}  // namespace

TEST_CASE("symplectic step without friction equals a dense symplectic Euler") {
  RandomGen g(41);
  for (int trial = 0; trial < 20; ++trial) {
    const Model m(g.chain(g.integer(2, 9)));
    const int n = static_cast<int>(m.nrOfJoints());
    Data data(m);
    detail::SymplecticWorkspace ws(m);
    DynamicsData dd(m);
    SolveInput in(m);
    in.q = g.q(n).data;
    in.q_dot = g.qdot(n).data;
    in.ff_torques = g.jntArray(n, -2.0, 2.0).data;
    in.time_step = 1e-3;
    const Eigen::VectorXd p = mass(m, dd, in.q) * in.q_dot + g.jntArray(n, -0.1, 0.1).data;
    Eigen::VectorXd q1(n), u1(n), p1(n);
    REQUIRE(detail::symplecticStep(m, data, ws, in, p, q1, u1, p1).code() == Error::None);
    const Eigen::VectorXd u_ref = denseStep(m, dd, in.q, in.q_dot, p, in.ff_torques, in.time_step);
    CHECK(testutil::relErr(u1, u_ref) < 1e-9);
    CHECK(testutil::relErr(p1, mass(m, dd, in.q) * u_ref) < 1e-9);
    CHECK(testutil::relErr(q1, in.q + in.time_step * u_ref) < 1e-12);
    CHECK(data.commandTorques().norm() == 0.0);  // no task: no command torques (hd_solver.hpp)
  }
}

TEST_CASE("a passive chain's energy stays bounded under the symplectic step, grows under step()") {
  RandomGen g(42);
  const Model m(g.chain(7, /*allow_prismatic=*/false));  // revolute: a bounded motion
  const int n = 7;
  Data data(m);
  detail::SymplecticWorkspace ws(m);
  DynamicsData dd(m);
  SolveInput in(m);
  in.time_step = 1e-3;
  const Eigen::VectorXd q0 = g.q(n).data, v0 = Eigen::VectorXd::Constant(n, 2.0);
  const double E0 = energy(m, dd, q0, mass(m, dd, q0) * v0);
  Eigen::VectorXd q = q0, u = v0, p = mass(m, dd, q0) * v0, q1(n), u1(n), p1(n);
  double sym_worst = 0.0;
  for (int k = 0; k < 10000; ++k) {  // 10 s
    in.q = q;
    in.q_dot = u;
    REQUIRE(detail::symplecticStep(m, data, ws, in, p, q1, u1, p1).code() == Error::None);
    q = q1, u = u1, p = p1;
    sym_worst = std::max(sym_worst, std::abs(energy(m, dd, q, p) - E0));
  }
  q = q0, u = v0;
  double semi_gain = 0.0;
  for (int k = 0; k < 10000; ++k) {
    in.q = q;
    in.q_dot = u;
    REQUIRE(step(m, data, in, q, u));
    semi_gain = std::max(semi_gain, energy(m, dd, q, mass(m, dd, q) * u) - E0);
  }
  MESSAGE("E0 " << E0 << " J; symplectic max |E - E0| " << sym_worst << " J; semi-implicit gain " << semi_gain);
  CHECK(sym_worst < 0.03 * E0);  // measured 1.9 % (4.8 J of 253 J)
  CHECK(semi_gain > 3.0 * sym_worst);
}

namespace {

// Breakaway friction 1.5 |g(q)| + 0.2 at every joint, kinetic 0.8 of it.
FrictionModel holding(const Model& m, const Eigen::VectorXd& q) {
  DynamicsData dd(m);
  Eigen::VectorXd g(q.size());
  REQUIRE(gravityTorques(m, dd, JointPositions(q), kGravity, g));
  FrictionModel fm;
  fm.static_friction = 1.5 * g.cwiseAbs() + Eigen::VectorXd::Constant(q.size(), 0.2);
  fm.kinetic_friction = 0.8 * fm.static_friction;
  return fm;
}

}  // namespace

TEST_CASE("symplectic step: a chain held by friction keeps q bitwise with one solve per step") {
  RandomGen g(43);
  const Model m(g.chain(7, false));
  Data data(m);
  detail::SymplecticWorkspace ws(m);
  SolveInput in(m);
  in.q = g.q(7).data;
  const FrictionModel fm = holding(m, in.q);
  in.friction = &fm;
  in.time_step = 1e-3;
  const Eigen::VectorXd q0 = in.q;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(7), q1(7), u1(7), p1(7);
  for (int k = 0; k < 10000; ++k) {
    REQUIRE(detail::symplecticStep(m, data, ws, in, p, q1, u1, p1).code() == Error::None);
    REQUIRE(ws.iterations == 1);
    in.q = q1, in.q_dot = u1, p = p1;
  }
  CHECK(in.q == q0);
  CHECK(in.q_dot.isZero(0.0));
}

TEST_CASE("symplectic step: a moving chain friction can stop comes to exact rest") {
  RandomGen g(44);
  const Model m(g.chain(6, false));
  Data data(m);
  detail::SymplecticWorkspace ws(m);
  DynamicsData dd(m);
  SolveInput in(m);
  in.q = g.q(6).data;
  FrictionModel fm = holding(m, in.q);
  fm.static_friction *= 3.0;
  fm.kinetic_friction *= 3.0;
  in.friction = &fm;
  in.time_step = 1e-3;
  in.q_dot = Eigen::VectorXd::Constant(6, 0.05);
  Eigen::VectorXd p = mass(m, dd, in.q) * in.q_dot, q1(6), u1(6), p1(6);
  for (int k = 0; k < 6000; ++k) {  // joint 0 decelerates slowly (its friction is the 0.2 floor)
    REQUIRE(detail::symplecticStep(m, data, ws, in, p, q1, u1, p1));
    in.q = q1, in.q_dot = u1, p = p1;
  }
  CHECK(in.q_dot.isZero(0.0));
  const Eigen::VectorXd rest = in.q;
  REQUIRE(detail::symplecticStep(m, data, ws, in, p, q1, u1, p1));
  CHECK(q1 == rest);
}

TEST_CASE("symplectic step: the iteration bound's fallback is Degraded, bad input an error") {
  RandomGen g(45);
  const Model m(g.chain(5, false));
  Data data(m);
  detail::SymplecticWorkspace ws(m);
  DynamicsData dd(m);
  SolveInput in(m);
  in.q = g.q(5).data;
  in.q_dot = Eigen::VectorXd::Constant(5, 3.0);
  in.time_step = 1e-3;
  const Eigen::VectorXd p = mass(m, dd, in.q) * in.q_dot;
  Eigen::VectorXd q1(5), u1(5), p1(5), short_p(4);
  const Status s = detail::symplecticStep(m, data, ws, in, p, q1, u1, p1, /*max_iterations=*/1);
  CHECK(s.code() == Error::Degraded);
  CHECK(s.ok());
  CHECK(ws.iterations == 1);
  CHECK(detail::symplecticStep(m, data, ws, in, short_p, q1, u1, p1).code() == Error::SizeMismatch);
  in.time_step = 0.0;
  CHECK(detail::symplecticStep(m, data, ws, in, p, q1, u1, p1).code() == Error::OutOfRange);
}
