// A random chain held by friction, for the time-step tests (test_time_step*.cpp): the model, its
// solve data and an input at the chain's random q with holdingFriction, and the check that many
// steps keep such a chain exactly where it is.
#pragma once

#include <doctest/doctest.h>

#include <Eigen/Core>

#include "holding_friction.hpp"
#include "random_chain.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"

namespace testutil {

// g.chain(n) at q = g.q(n), q_dot zero, in.friction = &fm with fm = holdingFriction(model, q,
// factor, extra). Neither copied nor moved (in points at fm). Name its members by references, not
// by a structured binding: doctest's CHECK with DOCTEST_CONFIG_ASSERTS_RETURN_VALUES is a lambda,
// and capturing a structured binding is C++20 (clang 14 refuses it in C++17).
struct HeldChain {
  HeldChain(RandomGen& g, int n, double factor, double extra) : model(g.chain(n)), data(model), in(model) {
    in.q = g.q(n).data;
    in.q_dot.setZero();
    fm = holdingFriction(model, in.q, factor, extra);
    in.friction = &fm;
  }
  HeldChain(const HeldChain&) = delete;
  HeldChain& operator=(const HeldChain&) = delete;

  const vereshchagin::Model model;
  vereshchagin::Data data;
  vereshchagin::SolveInput in;
  vereshchagin::FrictionModel fm;
};

// Runs step() `steps` times from (in.q, in.q_dot), each step's end its next start, and checks that
// every step succeeded and the chain stayed held: q bitwise where it started, q_dot exactly zero
// and every joint sticking.
inline void checkHeldOverSteps(const vereshchagin::Model& model, vereshchagin::Data& data, vereshchagin::SolveInput& in,
                               int steps) {
  using namespace vereshchagin;
  const Eigen::VectorXd q0 = in.q;
  Eigen::VectorXd q_next(in.q.size()), qd_next(in.q_dot.size());
  bool ok = true;
  for (int k = 0; k < steps && ok; ++k) {
    ok = static_cast<bool>(step(model, data, in, q_next, qd_next));
    in.q = q_next;
    in.q_dot = qd_next;
  }
  REQUIRE(ok);
  CHECK((in.q.array() == q0.array()).all());
  CHECK((in.q_dot.array() == 0.0).all());
  for (const JointStatus s : data.jointStatus()) CHECK(s == JointStatus::Stick);
}

}  // namespace testutil
