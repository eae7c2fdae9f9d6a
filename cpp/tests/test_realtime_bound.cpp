// The real-time iteration bound of the friction stage (FrictionModel::max_iterations, issue 27):
// a bound forced below what random resting chains need gives Error::Degraded with the documented
// fallback (friction within its bounds, no positive work in sum, the motion the exact response to
// that friction), at the instant and over a time step; the default bound is not hit on them and
// gives results bitwise equal to the exhaustive bound's; nothing of a degraded call leaks into the
// next; invalid bounds are refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "random_chain.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/friction_solver.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

// A random n-joint chain at a random q, every joint resting (or slowly moving with `moving`), with
// breakaway friction 0.2-1.6 times each joint's gravity torque: near breakaway, the hard case.
struct Case {
  Model model;
  SolveInput in;
  FrictionModel fm;
  Case(RandomGen& g, int n, double speed) : model(g.chain(n, false)), in(model) {
    in.q = g.q(n).data;
    in.q_dot.setZero();
    for (int j = 0; j < n; ++j) in.q_dot(j) = speed * g.uniform(-1.0, 1.0);
    DynamicsData dyn(model);
    Eigen::VectorXd grav(n);
    REQUIRE(gravityTorques(model, dyn, JointPositions(in.q), KDL::Vector(0, 0, -9.81), grav));
    fm.static_friction.resize(n);
    for (int j = 0; j < n; ++j) fm.static_friction(j) = g.uniform(0.2, 1.6) * std::abs(grav(j)) + 0.01;
    fm.kinetic_friction = 0.8 * fm.static_friction;
    in.friction = &fm;
  }
};

bool bitwiseEqual(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

// The fallback's properties: friction within its bounds (no limit reaction without limits), no
// positive work in sum on the rows (accelerations, or end velocities over dt), and the motion the
// exact response to the friction: inverse dynamics of qdd is ff + tau_cmd + friction.
void checkFallback(const Case& c, const Data& data, double dt) {
  const Eigen::VectorXd& fr = data.frictionTorques();
  const Eigen::VectorXd& qdd = data.qdd();
  const long n = fr.size();
  double power = 0.0, scale = 0.0;
  for (long j = 0; j < n; ++j) {
    const bool moving = std::abs(c.in.q_dot(j)) > c.fm.velocity_tolerance;
    const double f = moving ? c.fm.kinetic_friction(j) : c.fm.static_friction(j);
    CHECK(std::abs(fr(j)) <= f);
    CHECK(std::abs(data.limitTorques()(j)) <= 1e-12 * f);
    const double row = qdd(j) + (dt > 0.0 ? c.in.q_dot(j) / dt : 0.0);
    power += fr(j) * row;
    scale += std::abs(fr(j) * row);
  }
  CHECK(power <= 1e-9 * std::max(1.0, scale));
  DynamicsData dyn(c.model);
  Eigen::VectorXd tau(n);
  REQUIRE(inverseDynamics(c.model, dyn, JointPositions(c.in.q), JointVelocities(c.in.q_dot), JointAccelerations(qdd),
                          Matrix6X::Zero(6, c.model.nrOfSegments()), KDL::Vector(0, 0, -9.81), tau));
  const Eigen::VectorXd applied = c.in.ff_torques + data.commandTorques() + fr + data.limitTorques();
  CHECK((tau - applied).cwiseAbs().maxCoeff() <= 1e-8 * std::max(1.0, tau.cwiseAbs().maxCoeff()));
}

// Solves `c` with the default bound, the exhaustive one and forced bounds 1 and 2 (on cases that
// need more); returns how many cases the forced bounds degraded.
int forcedBounds(Case& c, double dt) {
  Data data(c.model);
  c.in.time_step = dt;
  c.fm.max_iterations = 0;
  REQUIRE(solve(c.model, data, c.in).code() == Error::None);
  const int needed = data.iterations();
  const Eigen::VectorXd qdd = data.qdd(), fr = data.frictionTorques(), cmd = data.commandTorques();
  c.fm.max_iterations = -1;  // the default: not hit, bitwise the exhaustive bound's results
  REQUIRE(solve(c.model, data, c.in).code() == Error::None);
  CHECK(data.iterations() == needed);
  CHECK((bitwiseEqual(qdd, data.qdd()) && bitwiseEqual(fr, data.frictionTorques()) &&
         bitwiseEqual(cmd, data.commandTorques())));
  int degraded = 0;
  for (int bound = 1; bound <= 2; ++bound) {
    c.fm.max_iterations = bound;
    const Status s = solve(c.model, data, c.in);
    if (needed <= bound) {
      CHECK(s.code() == Error::None);
      continue;
    }
    ++degraded;
    CHECK(s.code() == Error::Degraded);
    CHECK(s.ok());
    CHECK(std::strstr(s.message(), "real-time bound") != nullptr);
    CHECK(data.iterations() == bound);
    checkFallback(c, data, dt);
  }
  // Nothing of the degraded calls leaks: the default bound again, bitwise as before.
  c.fm.max_iterations = -1;
  REQUIRE(solve(c.model, data, c.in).code() == Error::None);
  CHECK((bitwiseEqual(qdd, data.qdd()) && bitwiseEqual(fr, data.frictionTorques()) &&
         bitwiseEqual(cmd, data.commandTorques())));
  return degraded;
}

}  // namespace

TEST_CASE("a forced bound at the instant gives the documented fallback") {
  RandomGen g(2701);
  int degraded = 0;
  for (int t = 0; t < 200; ++t) {
    Case c(g, g.integer(3, 12), 0.0);
    degraded += forcedBounds(c, 0.0);
  }
  CHECK(degraded > 50);  // the forced bounds were hit on a good share of the cases
}

TEST_CASE("a forced bound over a time step gives the documented fallback") {
  RandomGen g(2702);
  int degraded = 0;
  for (int t = 0; t < 200; ++t) {
    Case c(g, g.integer(3, 12), t % 2 ? 0.0 : 0.01);
    degraded += forcedBounds(c, 1e-3);
  }
  CHECK(degraded > 50);
}

static_assert(static_cast<int>(Error::Degraded) == FrictionSolver::E_DEGRADED);

TEST_CASE("a degraded FrictionSolver call returns E_DEGRADED with its message") {
  RandomGen g(2703);
  const KDL::Chain chain = g.chain(7, false);
  FrictionSolver fs(chain, KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()));
  const Eigen::VectorXd q = g.q(7).data, zero = Eigen::VectorXd::Zero(7);
  FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::Constant(7, 1.0);
  const Eigen::MatrixXd none(6, 0);
  const Eigen::VectorXd nobeta(0);
  REQUIRE(fs.solve(q, zero, none, nobeta, none, zero, fm) == 0);
  REQUIRE(fs.iterations() > 1);
  fm.max_iterations = 1;
  CHECK(fs.solve(q, zero, none, nobeta, none, zero, fm) == FrictionSolver::E_DEGRADED);
  CHECK(std::strstr(fs.errorMessage(), "real-time bound") != nullptr);
  CHECK(fs.iterations() == 1);
  CHECK(std::isfinite(fs.gaussValue()));
  fm.max_iterations = -2;
  CHECK(fs.solve(q, zero, none, nobeta, none, zero, fm) == FrictionSolver::E_INVALID_FRICTION);
  CHECK(std::strstr(fs.errorMessage(), "max_iterations") != nullptr);
}
