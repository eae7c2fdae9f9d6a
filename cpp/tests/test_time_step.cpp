// The solve over a time step (SolveInput::time_step) and step() (data.hpp): a chain held by
// friction under gravity keeps q bitwise over 10^6 steps; a moving chain friction can stop comes
// to exact rest; the step's joint outputs obey their bounds and oppose the end velocities; and
// the argument checks of step().
#include <doctest/doctest.h>

#include <cmath>

#include "held_chain.hpp"
#include "random_chain.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

TEST_CASE("a chain held by friction keeps q bitwise over a million steps") {
  RandomGen g(71);
  testutil::HeldChain held(g, 4, 1.1, 0.01);
  const Model& model = held.model;
  auto& data = held.data;
  auto& in = held.in;
  in.time_step = 1e-3;
  testutil::checkHeldOverSteps(model, data, in, testutil::longRunSteps(1000000));
}

TEST_CASE("a moving chain friction can stop comes to exact rest and stays") {
  RandomGen g(72);
  testutil::HeldChain held(g, 5, 1.5, 1.0);  // friction that would hold it at rest at q
  const Model& model = held.model;
  auto& data = held.data;
  auto& in = held.in;
  auto& fm = held.fm;
  in.q_dot = Eigen::VectorXd::Constant(5, 0.05);
  in.time_step = 1e-3;
  Eigen::VectorXd q_next(5), qd_next(5), q_rest(5);
  int stopped = -1;
  for (int k = 0; k < 3000; ++k) {
    REQUIRE(step(model, data, in, q_next, qd_next));
    // Friction never pushes along the end velocity, and stays within its bound.
    for (int j = 0; j < 5; ++j) {
      CHECK(data.frictionTorques()(j) * qd_next(j) <= 0.0);
      CHECK(std::abs(data.frictionTorques()(j)) <= fm.static_friction(j) * (1 + 1e-12));
    }
    if (stopped < 0 && (qd_next.array() == 0.0).all()) stopped = k, q_rest = q_next;
    in.q = q_next;
    in.q_dot = qd_next;
  }
  REQUIRE(stopped >= 0);
  CHECK(stopped < 2000);
  CHECK((in.q.array() == q_rest.array()).all());
}

TEST_CASE("step() checks its arguments") {
  RandomGen g(73);
  const Model model(g.chain(3));
  Data data(model);
  SolveInput in(model);
  Eigen::VectorXd q_next(3), qd_next(3), wrong(2);
  CHECK(step(model, data, in, q_next, qd_next).code() == Error::OutOfRange);  // time_step 0
  in.time_step = 1e-3;
  CHECK(step(model, data, in, wrong, qd_next).code() == Error::SizeMismatch);
  CHECK(step(model, data, in, q_next, qd_next));  // no friction: explicit Euler on the solve's qdd
  CHECK(q_next.isApprox(in.q + 1e-3 * qd_next));
  in.time_step = -1.0;
  CHECK(solve(model, data, in).code() == Error::OutOfRange);
}
