// The symplectic step (src/symplectic_step.hpp, the Simulator's Integrator::Symplectic): without
// friction it equals a dense symplectic Euler in momentum form built from massMatrix,
// gravityTorques and kineticEnergyGradient (checked against Pinocchio in test_pinocchio_oracle);
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

namespace {

// A revolute chain with everything a symplectic step needs; advance() takes one step and moves
// the state (q, u in `in`, the momentum p) on.
struct Rig {
  Model m;
  Data data;
  detail::SymplecticWorkspace ws;
  DynamicsData dd;
  SolveInput in;
  Eigen::VectorXd p, q1, u1, p1;
  Rig(RandomGen& g, int n)
      : m(g.chain(n, /*allow_prismatic=*/false)), data(m), ws(m), dd(m), in(m), p(n), q1(n), u1(n), p1(n) {
    in.q = g.q(n).data;
    in.time_step = 1e-3;
  }
  void setVelocity(const Eigen::VectorXd& v) {
    in.q_dot = v;
    p = mass(m, dd, in.q) * v;
  }
  Status advance(int max_iterations = 100) {
    const Status s = detail::symplecticStep(m, data, ws, in, p, q1, u1, p1, max_iterations);
    if (s) in.q = q1, in.q_dot = u1, p = p1;
    return s;
  }
};

// Breakaway friction factor (1.5 |g(q)| + 0.2) at every joint, kinetic 0.8 of it.
FrictionModel holding(const Model& m, const Eigen::VectorXd& q, double factor) {
  DynamicsData dd(m);
  Eigen::VectorXd g(q.size());
  REQUIRE(gravityTorques(m, dd, JointPositions(q), kGravity, g));
  FrictionModel fm;
  fm.static_friction = factor * (1.5 * g.cwiseAbs() + Eigen::VectorXd::Constant(q.size(), 0.2));
  fm.kinetic_friction = 0.8 * fm.static_friction;
  return fm;
}

}  // namespace

TEST_CASE("a passive chain's energy stays bounded under the symplectic step, grows under step()") {
  RandomGen g(42);
  Rig r(g, 7);
  const Eigen::VectorXd q0 = r.in.q, v0 = Eigen::VectorXd::Constant(7, 2.0);
  r.setVelocity(v0);
  const double E0 = energy(r.m, r.dd, q0, r.p);
  double sym_worst = 0.0;
  for (int k = 0; k < 10000; ++k) {  // 10 s
    REQUIRE(r.advance().code() == Error::None);
    sym_worst = std::max(sym_worst, std::abs(energy(r.m, r.dd, r.in.q, r.p) - E0));
  }
  Eigen::VectorXd q = q0, u = v0;
  double semi_gain = 0.0;
  for (int k = 0; k < 10000; ++k) {
    r.in.q = q;
    r.in.q_dot = u;
    REQUIRE(step(r.m, r.data, r.in, q, u));
    semi_gain = std::max(semi_gain, energy(r.m, r.dd, q, mass(r.m, r.dd, q) * u) - E0);
  }
  MESSAGE("E0 " << E0 << " J; symplectic max |E - E0| " << sym_worst << " J; semi-implicit gain " << semi_gain);
  CHECK(sym_worst < 0.03 * E0);  // measured 1.1 % (2.8 J of 253 J)
  CHECK(semi_gain > 3.0 * sym_worst);
}

TEST_CASE("symplectic step: a chain held by friction keeps q bitwise with one solve per step") {
  RandomGen g(43);
  Rig r(g, 7);
  const FrictionModel fm = holding(r.m, r.in.q, 1.0);
  r.in.friction = &fm;
  r.setVelocity(Eigen::VectorXd::Zero(7));
  const Eigen::VectorXd q0 = r.in.q;
  for (int k = 0; k < 10000; ++k) {
    REQUIRE(r.advance().code() == Error::None);
    REQUIRE(r.ws.iterations == 1);
  }
  CHECK(r.in.q == q0);
  CHECK(r.in.q_dot.isZero(0.0));
}

TEST_CASE("symplectic step: a moving chain friction can stop comes to exact rest") {
  RandomGen g(44);
  Rig r(g, 6);
  const FrictionModel fm = holding(r.m, r.in.q, 3.0);
  r.in.friction = &fm;
  r.setVelocity(Eigen::VectorXd::Constant(6, 0.05));
  for (int k = 0; k < 6000; ++k) REQUIRE(r.advance());  // joint 0 decelerates slowly (friction 0.2 floor)
  CHECK(r.in.q_dot.isZero(0.0));
  const Eigen::VectorXd rest = r.in.q;
  REQUIRE(r.advance());
  CHECK(r.in.q == rest);
}

TEST_CASE("symplectic step: the iteration bound's fallback is Degraded, bad input an error") {
  RandomGen g(45);
  Rig r(g, 5);
  r.setVelocity(Eigen::VectorXd::Constant(5, 3.0));
  const Eigen::VectorXd short_p(4);
  CHECK(detail::symplecticStep(r.m, r.data, r.ws, r.in, short_p, r.q1, r.u1, r.p1).code() == Error::SizeMismatch);
  const Status s = r.advance(/*max_iterations=*/1);
  CHECK(s.code() == Error::Degraded);
  CHECK(s.ok());
  CHECK(r.ws.iterations == 1);
  r.in.time_step = 0.0;
  CHECK(r.advance().code() == Error::OutOfRange);
}
