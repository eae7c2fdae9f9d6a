// A friction model that holds a robot at rest at q (the time-step and Simulator tests): breakaway
// friction `factor` times the gravity torques at q plus `extra` at every joint, kinetic 0.8 of it.
#pragma once

#include <doctest/doctest.h>

#include <Eigen/Core>

#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/friction_model.hpp"

namespace testutil {

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
