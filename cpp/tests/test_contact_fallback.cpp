// The contact stage's real-time bound (SolveInput::contact_max_pivots, issue 27): a pivot bound
// forced below what random chains with several supports need gives Error::Degraded with the
// documented fallback (docs/friction.md, "Real-time bound"): no friction at the contacts or at
// the resting joints, every support's force along its normal, no support moving into its surface
// (its normal acceleration, or end velocity over a step, >= 0), no contact force doing positive
// work on that motion, and the motion the exact response to these forces (the replay identity);
// the default bound is not hit on them, and nothing of a degraded call leaks into the next.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "contact_fallback_case.hpp"

using namespace vereshchagin;
using testutil::Case;
using testutil::RandomGen;

namespace {

bool bitwiseEqual(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index j = 0; j < a.cols(); ++j)
    for (Eigen::Index i = 0; i < a.rows(); ++i) {
      const double x = a(i, j), y = b(i, j);
      if (std::memcmp(&x, &y, sizeof(double)) != 0) return false;
    }
  return true;
}

// The fallback's properties (see the top of this file).
void checkFallback(const Case& c, const Data& data, double dt) {
  const Model& model = c.model;
  const SolveInput& in = c.in;
  const long n = model.nrOfJoints();
  const Eigen::VectorXd& qdd = data.qdd();
  KinematicsData kin(model);
  REQUIRE(forwardKinematics(model, kin, JointPositions(in.q), JointVelocities(in.q_dot)));
  Eigen::MatrixXd J(6, n);
  Vector6 bias, twist;
  Eigen::VectorXd applied = in.ff_torques + data.commandTorques() + data.frictionTorques() + data.limitTorques();
  double work = 0.0, scale = 1.0;
  for (std::size_t k = 0; k < in.contacts.size(); ++k) {
    const PointContact& pc = in.contacts[k];
    const FrameRef at{pc.segment, KDL::Frame(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)))};
    REQUIRE(frameJacobian(model, kin, at, J));
    REQUIRE(frameBiasAcceleration(model, kin, at, bias));
    REQUIRE(frameTwist(model, kin, at, twist));
    const Vector3 jq = J.topRows(3) * qdd, v = dt > 0.0 ? Vector3(twist.head<3>() / dt) : Vector3::Zero();
    const Vector3 row = jq + bias.head<3>() + v;  // the acceleration, or the end velocity over dt
    const double terms = std::max({1.0, jq.norm(), bias.head<3>().norm(), v.norm()});  // its round-off scale
    const Vector3 f = data.contactForces().col(k);
    const double fn = pc.normal.dot(f);
    CHECK((f - fn * pc.normal).norm() <= 1e-12 * std::max(1.0, f.norm()));  // no contact friction
    CHECK(pc.normal.dot(row) >= -1e-8 * terms);                             // not into the surface
    work += f.dot(row);
    scale = std::max(scale, std::abs(f.dot(row)));
    applied += J.topRows(3).transpose() * f;
  }
  CHECK(work <= 1e-8 * scale);    // no positive work of the contact forces
  for (long j = 0; j < n; ++j) {  // friction only at the joints moving now, at the instant
    const bool moving = dt == 0.0 && std::abs(in.q_dot(j)) > c.fm.velocity_tolerance;
    CHECK(std::abs(data.frictionTorques()(j)) <= (moving ? c.fm.kinetic_friction(j) : 0.0));
  }
  DynamicsData dyn(model);
  Eigen::VectorXd tau(n);
  REQUIRE(inverseDynamics(model, dyn, JointPositions(in.q), JointVelocities(in.q_dot), JointAccelerations(qdd),
                          Matrix6X::Zero(6, model.nrOfSegments()), KDL::Vector(0, 0, -9.81), tau));
  CHECK((tau - applied).cwiseAbs().maxCoeff() <= 1e-8 * std::max(1.0, tau.cwiseAbs().maxCoeff()));
}

// The default bound, then forced bounds of 1 and 3 pivots, then the default again; returns how
// many of the forced solves were degraded.
int forcedBounds(Case& c, double dt) {
  Data data(c.model);
  c.in.time_step = dt;
  c.in.contact_max_pivots = -1;
  const Status s0 = solve(c.model, data, c.in);
  if (s0.code() != Error::None) return 0;  // (a problem without an answer: not this test's)
  const Eigen::VectorXd qdd = data.qdd(), cmd = data.commandTorques(), fr = data.frictionTorques();
  const Matrix3X f = data.contactForces();
  int degraded = 0;
  for (int bound : {1, 3}) {
    c.in.contact_max_pivots = bound;
    const Status s = solve(c.model, data, c.in);
    CHECK(s.ok());
    if (s.code() != Error::Degraded) continue;
    ++degraded;
    CHECK(std::strstr(s.message(), "real-time bound") != nullptr);
    checkFallback(c, data, dt);
  }
  c.in.contact_max_pivots = -1;  // nothing of the degraded calls leaks
  REQUIRE(solve(c.model, data, c.in).code() == Error::None);
  CHECK((bitwiseEqual(qdd, data.qdd()) && bitwiseEqual(cmd, data.commandTorques()) &&
         bitwiseEqual(fr, data.frictionTorques()) && bitwiseEqual(f, data.contactForces())));
  return degraded;
}

}  // namespace

TEST_CASE("a forced pivot bound at the instant gives the documented fallback") {
  RandomGen g(2711);
  int degraded = 0;
  for (int t = 0; t < 60; ++t) {
    const int contacts = g.integer(2, 5), joints = g.integer(4, 8);  // (random_chain.hpp: draw order)
    Case c(g, joints, contacts, 0.0);
    degraded += forcedBounds(c, 0.0);
  }
  CHECK(degraded > 10);
}

TEST_CASE("a forced pivot bound over a time step gives the documented fallback") {
  RandomGen g(2712);
  int degraded = 0;
  for (int t = 0; t < 60; ++t) {
    const int contacts = g.integer(2, 5), joints = g.integer(4, 8);  // (random_chain.hpp: draw order)
    Case c(g, joints, contacts, t % 2 ? 0.0 : 0.01);
    degraded += forcedBounds(c, 1e-3);
  }
  CHECK(degraded > 10);
}

TEST_CASE("an invalid pivot bound is refused") {
  RandomGen g(2713);
  Case c(g, 5, 2, 0.0);
  Data data(c.model);
  for (int bound : {0, -2}) {
    c.in.contact_max_pivots = bound;
    const Status s = solve(c.model, data, c.in);
    CHECK(s.code() == Error::InvalidContact);
    CHECK(std::strstr(s.message(), "contact_max_pivots") != nullptr);
  }
}
