// The least-effort rule over a time step (contact_effort.cpp, docs/time-step.md): where the
// step's impulses are not unique (supports, a force set-point and friction-held joints sharing a
// load), the step picks them as the instant does, so a chain at rest gets the instant's forces and
// command torques; and a chain held that way keeps q bitwise over many steps.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "held_chain.hpp"
#include "random_chain.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

// Two supports with friction on the last two segments and a force set-point (its normal held by
// the motors: one motor column) on the one before, all on horizontal surfaces.
std::vector<PointContact> sharedLoad(int ns) {
  std::vector<PointContact> out;
  for (int k = 0; k < 3; ++k) {
    PointContact pc;
    pc.segment = ns - 1 - k;
    pc.point = Vector3(0.02 * k, -0.03, 0.05);
    pc.normal = Vector3::UnitZ();
    pc.mu = 0.8;
    if (k == 2) pc.force = 3.0;  // N, pushing up
    out.push_back(pc);
  }
  return out;
}

}  // namespace

TEST_CASE("at rest the step's least-effort split is the instant's") {
  // At rest the step's conditions are the instant's (rows a + v / dt with v = 0): the same
  // problem, whose forces and torques the least-effort rule makes unique. Without the rule the
  // step returned the complementarity problem's split instead.
  for (const unsigned seed : {81u, 82u, 83u, 84u}) {
    CAPTURE(seed);
    RandomGen g(seed);
    testutil::HeldChain held(g, 7, 0.7, 0.3);
    const Model& model = held.model;
    auto& data = held.data;
    auto& in = held.in;
    in.contacts = sharedLoad(static_cast<int>(model.nrOfSegments()));
    REQUIRE(solve(model, data, in));
    const Eigen::MatrixXd f_inst = data.contactForces();
    const Eigen::VectorXd cmd_inst = data.commandTorques(), fric_inst = data.frictionTorques();
    in.time_step = 1e-3;
    REQUIRE(solve(model, data, in));
    const double scale = std::max(1.0, f_inst.norm() + cmd_inst.norm() + fric_inst.norm());
    CHECK((data.contactForces() - f_inst).norm() <= 1e-9 * scale);
    CHECK((data.commandTorques() - cmd_inst).norm() <= 1e-9 * scale);
    CHECK((data.frictionTorques() - fric_inst).norm() <= 1e-9 * scale);
  }
}

TEST_CASE("a chain held by supports, a set-point and friction keeps q bitwise over many steps") {
  RandomGen g(85);
  testutil::HeldChain held(g, 7, 1.2, 0.5);
  const Model& model = held.model;
  auto& data = held.data;
  auto& in = held.in;
  in.contacts = sharedLoad(static_cast<int>(model.nrOfSegments()));
  in.time_step = 1e-3;
  testutil::checkHeldOverSteps(model, data, in, testutil::longRunSteps(20000));
  // The set-point's normal force is the input's, its reaction the motors' least effort.
  CHECK(data.contactForces()(2, 2) == doctest::Approx(3.0).epsilon(1e-12));
}
