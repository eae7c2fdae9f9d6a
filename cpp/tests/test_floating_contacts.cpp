// Contacts and joint friction on a floating base (contact_stage.hpp, floating_contact_points.cpp):
// a free-flyer standing on three points with its joints held by friction ends every step exactly
// at rest (the base too), the solves with contacts and friction at the instant and over a step do
// not allocate, and a second solve repeats the first bit for bit (no state between calls). The
// comparisons with Pinocchio are in Python (tests/oracles/test_floating_contacts.py).
#include <doctest/doctest.h>
#include <Eigen/Dense>

#include <cmath>

#include "alloc_counter.hpp"
#include "floating_fixture.hpp"
#include "random_tree.hpp"
#include "vereshchagin/data.hpp"

namespace {

using namespace vereshchagin;

Model floatingModel(BaseKind kind, unsigned seed) {
  testutil::RandomGen g(seed);
  testutil::TreeSpec spec;
  spec.n_joints = 7;
  return testutil::floatingTreeModel(kind, g, spec, 3.0);
}

// A state with the base turned, three contacts (on the last segments, the ground's normal up),
// joint friction large enough to hold every joint.
struct Standing {
  explicit Standing(const Model& model) : in(model, 2, 4) {
    in.q = Eigen::VectorXd::LinSpaced(model.nq(), -0.3, 0.4);
    if (model.baseKind() == BaseKind::FreeFlyer) {
      in.q.segment<4>(3) << 0.1, -0.2, 0.05, 0.97;
      in.q.segment<4>(3).normalize();
    } else {
      in.q.segment<2>(2) << std::cos(0.4), std::sin(0.4);
    }
    in.q_dot.setZero();
    in.gravity = KDL::Vector(0.0, 0.0, -9.81);
    const int ns = static_cast<int>(model.nrOfSegments());
    for (int k = 0; k < 3; ++k) {
      PointContact pc;
      pc.segment = ns - 1 - k;
      pc.point = Vector3(0.02 * k, -0.01, 0.03);
      pc.mu = 0.8;
      in.contacts.push_back(pc);
    }
    friction.static_friction = Eigen::VectorXd::Constant(model.nrOfJoints(), 1e4);
    friction.kinetic_friction = friction.static_friction;
    in.friction = &friction;
  }
  FrictionModel friction;
  SolveInput in;
};

}  // namespace

TEST_CASE("floating-base solves with contacts and joint friction do not allocate and repeat") {
  for (BaseKind kind : {BaseKind::FreeFlyer, BaseKind::Planar}) {
    const Model model = floatingModel(kind, 11);
    REQUIRE(model.status());
    Data data(model);
    Standing s(model);
    Eigen::VectorXd q_next(model.nq()), qd_next(model.nv());
    for (double dt : {0.0, 1e-3}) {
      s.in.time_step = dt;  // (at the instant from rest: no contact point approaches its surface)
      if (dt > 0.0) s.in.q_dot = Eigen::VectorXd::LinSpaced(model.nv(), 0.2, -0.1);
      REQUIRE(solve(model, data, s.in));
      const Eigen::VectorXd first = data.qdd();
      if (dt > 0.0) REQUIRE(step(model, data, s.in, q_next, qd_next));
      const long before = g_new_calls.load() + g_malloc_calls.load();
      for (int it = 0; it < 10; ++it) {
        CHECK(solve(model, data, s.in));
        if (dt > 0.0) CHECK(step(model, data, s.in, q_next, qd_next));
      }
      CHECK(g_new_calls.load() + g_malloc_calls.load() == before);
      REQUIRE(solve(model, data, s.in));
      CHECK((data.qdd() - first).norm() == 0.0);
    }
    s.in.contacts.clear();  // friction alone takes the contact stage too
    s.in.time_step = 0.0;
    REQUIRE(solve(model, data, s.in));
    const long before = g_new_calls.load() + g_malloc_calls.load();
    CHECK(solve(model, data, s.in));
    CHECK(g_new_calls.load() + g_malloc_calls.load() == before);
  }
}

TEST_CASE("a free-flyer held by its joints' friction on three sticking points ends a step at rest") {
  // No gravity: the robot at rest, its joints held by friction, pushed by a force F on its base
  // whose line passes through the centroid of three points on surfaces facing -F, with much
  // friction: the supports hold it (each -F / 3), and the step ends exactly at rest.
  const Model model = floatingModel(BaseKind::FreeFlyer, 11);
  Data data(model);
  Standing s(model);
  s.in.gravity = KDL::Vector::Zero();
  s.in.time_step = 1e-3;
  const auto contacts = s.in.contacts;
  s.in.contacts.clear();
  REQUIRE(solve(model, data, s.in));  // the points' positions (world)
  Vector3 centroid = Vector3::Zero();
  for (const PointContact& pc : contacts) {
    const KDL::Frame f =
        data.framePose(FrameRef{pc.segment, KDL::Frame(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)))});
    centroid += Vector3(f.p.x(), f.p.y(), f.p.z()) / 3.0;
  }
  const Eigen::Quaterniond quat(s.in.q(6), s.in.q(3), s.in.q(4), s.in.q(5));
  const Matrix3 R = quat.normalized().toRotationMatrix();
  const Vector3 F(0.3, -0.2, -5.0);  // world axes
  s.in.ff_torques.setZero(model.nv());
  s.in.ff_torques.head<3>() = R.transpose() * F;  // (base axes, moment about the base origin)
  s.in.ff_torques.segment<3>(3) = R.transpose() * (centroid - s.in.q.head<3>()).cross(F);
  s.in.contacts = contacts;
  for (PointContact& pc : s.in.contacts) {
    pc.normal = -F.normalized();
    pc.mu = 10.0;
  }
  Eigen::VectorXd q_next(model.nq()), qd_next(model.nv());
  REQUIRE(step(model, data, s.in, q_next, qd_next));
  for (const JointStatus st : data.jointStatus()) CHECK(st == JointStatus::Stick);
  for (const ContactStatus st : data.contactStatus()) CHECK(st == ContactStatus::Sticking);
  CHECK((data.contactForces().rowwise().sum() + F).norm() < 1e-9 * F.norm());
  CHECK(qd_next.norm() == 0.0);  // exactly: every joint held, the base fixed by the points
  CHECK((q_next - s.in.q).norm() == 0.0);
}
