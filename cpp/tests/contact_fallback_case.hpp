// A random chain with supports that carry and joint friction near each joint's gravity load: the
// problems whose contact stage needs its complementarity problem, shared by the tests of its
// real-time fallback (test_contact_fallback.cpp, test_no_alloc.cpp).
#pragma once

#include <doctest/doctest.h>

#include "random_chain.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/kinematics.hpp"

namespace testutil {

using namespace vereshchagin;  // (the cases' own scope)

// Static friction 0.1-0.6 times each joint's gravity torque at q plus 0.01 N m, kinetic 0.8 of it.
inline void frictionNearGravity(const Model& model, const Eigen::VectorXd& q, RandomGen& g, FrictionModel& fm) {
  const long n = q.size();
  DynamicsData dyn(model);
  Eigen::VectorXd load(n);
  REQUIRE(gravityTorques(model, dyn, JointPositions(q), KDL::Vector(0, 0, -9.81), load));
  fm.static_friction = load.cwiseAbs();
  for (long j = 0; j < n; ++j) fm.static_friction(j) = g.uniform(0.1, 0.6) * fm.static_friction(j) + 0.01;
  fm.kinetic_friction = 0.8 * fm.static_friction;
}

// A random chain at rest (or creeping) with k supports with friction (mu 0.6) whose normals oppose
// their points' free acceleration (so they carry), and joint friction near each joint's gravity load.
struct Case {
  Model model;
  SolveInput in;
  FrictionModel fm;
  Case(RandomGen& g, int n, int k, double speed) : model(g.chain(n, false)), in(model) {
    in.q = g.q(n).data;
    for (int j = 0; j < n; ++j) in.q_dot(j) = speed * g.uniform(-1.0, 1.0);
    in.ff_torques = g.torques(n).data;
    frictionNearGravity(model, in.q, g, fm);
    Data free(model);
    REQUIRE(solve(model, free, in).code() == Error::None);
    KinematicsData kin(model);
    REQUIRE(forwardKinematics(model, kin, JointPositions(in.q), JointVelocities(in.q_dot)));
    Eigen::MatrixXd J(6, n);
    Vector6 bias;
    for (int c = 0; c < k; ++c) {
      PointContact pc;
      pc.segment = g.integer(static_cast<int>(model.nrOfSegments()) / 2, static_cast<int>(model.nrOfSegments()) - 1);
      const KDL::Vector p = g.vector(-0.1, 0.1);  // (draws in their own statements: random_chain.hpp)
      pc.point = Vector3(p.x(), p.y(), p.z());
      const FrameRef at{pc.segment, KDL::Frame(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)))};
      REQUIRE(frameJacobian(model, kin, at, J));
      REQUIRE(frameBiasAcceleration(model, kin, at, bias));
      const Vector3 a = J.topRows(3) * free.qdd() + bias.head<3>();
      const KDL::Vector noise = g.vector(-0.2, 0.2);
      pc.normal = (-a.normalized() + Vector3(noise.x(), noise.y(), noise.z())).normalized();
      pc.mu = 0.6;
      in.contacts.push_back(pc);
    }
    in.friction = &fm;
  }
};

}  // namespace testutil
