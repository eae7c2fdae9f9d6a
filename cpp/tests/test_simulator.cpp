// The Simulator (simulator.hpp): a 7-joint arm held by friction keeps q bitwise over 10^5 steps;
// its steps equal step() of data.hpp bitwise; rollout() equals repeated step() bitwise, records
// what it is asked for and stops at a failing step; bad dt, state, sizes give error statuses; the
// symplectic integrator holds bitwise, equals stepSymplectic() and starts from p = H(q) q_dot.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "holding_friction.hpp"
#include "random_chain.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/simulator.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

bool same(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && (a.array() == b.array()).all();
}

}  // namespace

TEST_CASE("an arm held by friction keeps q bitwise over 10^5 steps of the Simulator") {
  RandomGen g(81);
  const Model model(g.chain(7));
  Simulator sim(model, 1e-3);
  REQUIRE(sim.status());
  const Eigen::VectorXd q0 = g.q(7).data;
  REQUIRE(sim.setState(JointPositions(q0), JointVelocities(Eigen::VectorXd::Zero(7)), 2.0));
  const FrictionModel fm = testutil::holdingFriction(model, q0, 1.2, 0.05);
  SolveInput in(model);
  in.friction = &fm;
  bool ok = true;
  const int steps = testutil::longRunSteps(100000);
  for (int k = 0; k < steps && ok; ++k) ok = static_cast<bool>(sim.step(in));
  REQUIRE(ok);
  CHECK(same(sim.q(), q0));
  CHECK((sim.qDot().array() == 0.0).all());
  CHECK(sim.time() == 2.0 + steps * 1e-3);
  for (const JointStatus s : sim.data().jointStatus()) CHECK(s == JointStatus::Stick);
}

TEST_CASE("a Simulator step equals step() of data.hpp bitwise and ignores the input's state") {
  RandomGen g(82);
  const Model model(g.chain(6));
  Simulator sim(model, 2e-3);
  const Eigen::VectorXd q0 = g.q(6).data, qd0 = g.qdot(6).data;
  REQUIRE(sim.setState(JointPositions(q0), JointVelocities(qd0)));
  FrictionModel fm = testutil::holdingFriction(model, q0, 1.2, 0.05);
  SolveInput in(model), ref(model);
  in.friction = ref.friction = &fm;
  in.ff_torques = ref.ff_torques = g.torques(6).data;
  in.q.setConstant(7.0);  // ignored
  in.time_step = 0.5;     // ignored
  ref.q = q0;
  ref.q_dot = qd0;
  ref.time_step = 2e-3;
  in.q_dot.setConstant(-3.0);  // ignored
  const SolveInput& const_in = in;
  Simulator copying(model, 2e-3);  // the const overload: steps a copy of the input
  REQUIRE(copying.setState(JointPositions(q0), JointVelocities(qd0)));
  Data data(model);
  Eigen::VectorXd q(6), qd(6);
  for (int k = 0; k < 200; ++k) {
    REQUIRE(sim.step(in));  // the non-const overload: the state lent to `in` for the step
    REQUIRE(copying.step(const_in));
    REQUIRE(step(model, data, ref, q, qd));
    ref.q = q;
    ref.q_dot = qd;
  }
  CHECK(same(sim.q(), q));
  CHECK(same(sim.qDot(), qd));
  CHECK(same(sim.data().frictionTorques(), data.frictionTorques()));
  CHECK(same(copying.q(), q));
  CHECK(same(copying.qDot(), qd));
  CHECK(std::abs(sim.time() - 0.4) < 1e-15);
  // The caller's q, q_dot and time_step are back in the input, also after a failing step.
  CHECK((in.q.array() == 7.0).all());
  CHECK((in.q_dot.array() == -3.0).all());
  CHECK(in.time_step == 0.5);
  in.ff_torques(0) = std::numeric_limits<double>::quiet_NaN();
  CHECK(sim.step(in).code() == Error::NonfiniteInput);
  CHECK(same(sim.q(), q));
  CHECK((in.q.array() == 7.0).all());
  CHECK((in.q_dot.array() == -3.0).all());
  CHECK(in.time_step == 0.5);
}

TEST_CASE("rollout equals repeated step() bitwise and records what it is asked") {
  RandomGen g(83);
  const Model model(g.chain(7));
  const Eigen::VectorXd q0 = g.q(7).data, qd0 = 0.2 * g.qdot(7).data;
  const FrictionModel fm = testutil::holdingFriction(model, q0, 1.2, 0.05);
  const int n_steps = 300;
  // The controller: a PD pull towards q0 plus a sine on joint 2, written into the input.
  const Controller pd = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t, SolveInput& in) {
    in.ff_torques = 5.0 * (q0 - q) - 0.5 * qd;
    in.ff_torques(2) += std::sin(10.0 * t);
  };
  PointContact pc;  // a support under the last segment's tip, friction 0.5
  pc.segment = static_cast<int>(model.nrOfSegments()) - 1;
  pc.mu = 0.5;
  Simulator a(model, 1e-3), b(model, 1e-3);
  REQUIRE(a.setState(JointPositions(q0), JointVelocities(qd0)));
  REQUIRE(b.setState(JointPositions(q0), JointVelocities(qd0)));
  SolveInput in_a(model), in_b(model);
  in_a.friction = in_b.friction = &fm;
  in_a.contacts = in_b.contacts = {pc};
  RolloutRecord rec;
  rec.resize(7, n_steps, true, true, 1);
  int done = -1;
  REQUIRE(a.rollout(n_steps, pd, in_a, rec, &done));
  CHECK(done == n_steps);
  CHECK(same(rec.q.col(0), q0));
  for (int k = 0; k < n_steps; ++k) {
    pd(b.q(), b.qDot(), b.time(), in_b);
    REQUIRE(b.step(in_b));
    CHECK(rec.t(k + 1) == b.time());
    if (!same(rec.q.col(k + 1), b.q()) || !same(rec.q_dot.col(k + 1), b.qDot())) FAIL("state differs at step " << k);
    CHECK(same(rec.tau_command.col(k), b.data().commandTorques()));
    CHECK(same(rec.friction_torque.col(k), b.data().frictionTorques()));
    CHECK(same(rec.contact_force.col(k), Eigen::Map<const Eigen::VectorXd>(b.data().contactForces().data(), 3)));
  }
  CHECK(same(a.q(), b.q()));
  // Only the states recorded: the optional buffers stay empty.
  RolloutRecord states;
  states.resize(7, 10);
  REQUIRE(a.rollout(10, Controller(), in_a, states));
  CHECK(states.tau_command.size() == 0);
  CHECK(same(states.q.col(10), a.q()));
}

TEST_CASE("the Simulator refuses bad input with a status, never a crash") {
  RandomGen g(84);
  const Model model(g.chain(3));
  for (const double dt : {0.0, -1e-3, std::numeric_limits<double>::quiet_NaN(), HUGE_VAL}) {
    Simulator bad(model, dt);
    CHECK(bad.status().code() == Error::OutOfRange);
    CHECK(bad.step(SolveInput(model)).code() == Error::OutOfRange);
  }
  KDL::Chain invalid;  // a negative mass: the model's own status, passed on
  invalid.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ), KDL::Frame(), KDL::RigidBodyInertia(-1.0)));
  CHECK(Simulator(Model(invalid), 1e-3).status().code() == Error::InvalidModel);
  Simulator sim(model, 1e-3);
  const Eigen::VectorXd ok = Eigen::VectorXd::Zero(3), wrong = Eigen::VectorXd::Zero(2);
  Eigen::VectorXd nan = ok;
  nan(1) = std::numeric_limits<double>::quiet_NaN();
  CHECK(sim.setState(JointPositions(wrong), JointVelocities(ok)).code() == Error::SizeMismatch);
  CHECK(sim.setState(JointPositions(ok), JointVelocities(nan)).code() == Error::NonfiniteInput);
  CHECK(sim.setState(JointPositions(ok), JointVelocities(ok), HUGE_VAL).code() == Error::NonfiniteInput);
  SolveInput in(model);
  in.ff_torques = wrong;  // the solve's message, the state unchanged
  const Status s = sim.step(in);
  CHECK(s.code() == Error::SizeMismatch);
  CHECK(std::string(s.message()).size() > 0);
  CHECK(sim.time() == 0.0);
  in.ff_torques = ok;
  RolloutRecord rec;
  rec.resize(3, 5);
  CHECK(sim.rollout(6, Controller(), in, rec).code() == Error::SizeMismatch);
  CHECK(sim.rollout(-1, Controller(), in, rec).code() == Error::OutOfRange);
  rec.resize(3, 5, true);
  rec.tau_command.resize(3, 4);
  CHECK(sim.rollout(5, Controller(), in, rec).code() == Error::SizeMismatch);
  // A controller that makes a step fail: the rollout stops there, the state the last good one.
  rec.resize(3, 5);
  int done = -1;
  const Controller breaks = [](const Eigen::VectorXd&, const Eigen::VectorXd&, double t, SolveInput& input) {
    input.ff_torques(0) = t > 2.5e-3 ? std::numeric_limits<double>::quiet_NaN() : 0.0;
  };
  CHECK(sim.rollout(5, breaks, in, rec, &done).code() == Error::NonfiniteInput);
  CHECK(done == 3);
  CHECK(sim.time() == 3e-3);
  CHECK(sim.q().allFinite());
}

TEST_CASE("the symplectic Simulator: held bitwise, equal to stepSymplectic(), momentum H(q) q_dot at the start") {
  RandomGen g(84);
  const Model model(g.chain(7));
  const Eigen::VectorXd q0 = g.q(7).data, v0 = g.qdot(7).data;
  const FrictionModel fm = testutil::holdingFriction(model, q0, 1.2, 0.05);
  SolveInput in(model);
  Simulator held(model, 1e-3, Integrator::Symplectic);
  REQUIRE(held.status());
  REQUIRE(held.setState(JointPositions(q0), JointVelocities(Eigen::VectorXd::Zero(7))));
  in.friction = &fm;
  bool ok = true;
  for (int k = 0, steps = testutil::longRunSteps(100000); k < steps && ok; ++k)
    ok = held.step(in).code() == Error::None;
  REQUIRE(ok);
  CHECK(same(held.q(), q0));
  CHECK((held.qDot().array() == 0.0).all());
  CHECK((held.momentum().array() == 0.0).all());

  Simulator sim(model, 1e-3, Integrator::Symplectic);
  REQUIRE(sim.setState(JointPositions(q0), JointVelocities(v0)));
  DynamicsData dd(model);
  Eigen::MatrixXd H(7, 7);
  REQUIRE(massMatrix(model, dd, JointPositions(q0), H));
  CHECK((sim.momentum() - H * v0).norm() <= 1e-12 * (1.0 + (H * v0).norm()));
  Data data(model);
  Eigen::VectorXd q = q0, u = v0, p = sim.momentum(), q1(7), u1(7), p1(7);
  in.time_step = 1e-3;
  for (int k = 0; k < 300; ++k) {
    in.ff_torques = Eigen::VectorXd::Constant(7, 0.01 * k);
    REQUIRE(sim.step(in));
    in.q = q, in.q_dot = u;
    REQUIRE(stepSymplectic(model, data, in, p, q1, u1, p1));
    q = q1, u = u1, p = p1;
  }
  CHECK(same(sim.q(), q));
  CHECK(same(sim.qDot(), u));
  CHECK(same(sim.momentum(), p));
  CHECK(same(sim.data().frictionTorques(), data.frictionTorques()));
}
