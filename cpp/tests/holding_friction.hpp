// A friction model that holds a robot at rest at q (the time-step and Simulator tests): breakaway
// friction `factor` times the gravity torques at q plus `extra` at every joint, kinetic 0.8 of it.
#pragma once

#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cstdlib>

#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/friction_model.hpp"

namespace testutil {

// The number of steps of a long hold: `steps` in a plain build, a tenth of it where the tests run
// under the sanitizers (cpp/tests/CMakeLists.txt sets VERESHCHAGIN_TEST_SANITIZED=1 there). The
// sanitized library runs such a loop about 20 times slower; what the sanitizers look for (a bad
// access, a leak, undefined behaviour) shows in the first steps as well, and the plain build keeps
// the full count of the property.
inline int longRunSteps(int steps) {
  const char* sanitized = std::getenv("VERESHCHAGIN_TEST_SANITIZED");
  return sanitized != nullptr && sanitized[0] == '1' ? steps / 10 : steps;
}

inline vereshchagin::FrictionModel holdingFriction(const vereshchagin::Model& model, const Eigen::VectorXd& q,
                                                   double factor, double extra) {
  using namespace vereshchagin;
  const int n = static_cast<int>(model.nrOfJoints());
  DynamicsData dyn(model);
  Eigen::VectorXd g(n);
  REQUIRE(gravityTorques(model, dyn, JointPositions(q), KDL::Vector(0, 0, -9.81), g));
  FrictionModel fm;
  fm.static_friction = factor * g.cwiseAbs() + Eigen::VectorXd::Constant(n, extra);
  fm.kinetic_friction = 0.8 * fm.static_friction;
  return fm;
}

}  // namespace testutil
