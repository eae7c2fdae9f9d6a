// The position update on a floating base (base_kind.hpp's integrateConfiguration, step() and
// stepSymplectic() of data.hpp, the Simulator): a free fall from rest follows the semi-implicit
// parabola p_k = p_0 + g dt^2 k (k + 1) / 2 exactly under both integrators, the quaternion stays
// unit, the Simulator starts at the neutral base, and no step allocates. The comparison with
// pin.integrate and pin.aba is in Python (tests/oracles/test_floating_base_step.py).
#include <doctest/doctest.h>
#include <Eigen/Dense>

#include <cmath>
#include <string>

#include "alloc_counter.hpp"
#include "floating_fixture.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/simulator.hpp"

namespace {

using namespace vereshchagin;

Model floatingModel(BaseKind kind, unsigned seed) {
  return testutil::floatingTreeModel(kind, seed, 7);
}

Eigen::VectorXd startQ(const Model& model) {
  return testutil::floatingConfiguration(model, -0.7, 0.8);
}

}  // namespace

TEST_CASE("a floating robot at rest falls on the parabola under both integrators") {
  const double dt = 1e-3;
  const KDL::Vector g(0.0, 0.0, -9.81);
  const Model model = floatingModel(BaseKind::FreeFlyer, 5);
  REQUIRE(model.status());
  for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::Symplectic}) {
    Simulator sim(model, dt, integrator);
    REQUIRE(sim.status());
    CHECK(sim.q()(6) == 1.0);  // the neutral base: the identity quaternion
    const Eigen::VectorXd q0 = startQ(model);
    REQUIRE(sim.setState(JointPositions(q0), JointVelocities(Eigen::VectorXd::Zero(model.nv()))));
    SolveInput in(model);
    in.gravity = g;
    const int steps = 200;
    for (int k = 0; k < steps; ++k) REQUIRE(sim.step(in));
    const double fall = -9.81 * dt * dt * steps * (steps + 1) / 2.0;
    CHECK(std::abs(sim.q()(2) - (q0(2) + fall)) < 1e-12);
    CHECK((sim.q().head<2>() - q0.head<2>()).norm() < 1e-12);
    CHECK((sim.q().tail(model.nq() - 3) - q0.tail(model.nq() - 3)).norm() < 1e-12);  // nothing turns
    CHECK(std::abs(sim.q().segment<4>(3).norm() - 1.0) < 1e-15);
  }
}

TEST_CASE("the SE(2) and SE(3) updates of a constant twist stay on its circle and helix") {
  // A constant LOCAL twist (forward speed v, turning rate w) moves the base on a circle of
  // radius v / w (a helix with a speed along the axis): the exact exponential puts every step on it.
  const double dt = 0.1, v = 0.5, w = 0.25, climb = 0.3;
  Eigen::VectorXd planar(4), twist2(3), next(4);
  planar << 0.0, 0.0, 1.0, 0.0;
  twist2 << v, 0.0, w;
  Eigen::VectorXd ff(7), twist3(6), next3(7);
  ff << 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  twist3 << v, 0.0, climb, 0.0, 0.0, w;
  for (int k = 1; k <= 100; ++k) {
    integrateConfiguration(BaseKind::Planar, planar, twist2, dt, next);
    planar = next;
    integrateConfiguration(BaseKind::FreeFlyer, ff, twist3, dt, next3);
    ff = next3;
    const double yaw = w * dt * k;
    CHECK(std::abs(std::hypot(planar(0), planar(1) - v / w) - v / w) < 1e-13);
    CHECK(std::abs(std::atan2(planar(3), planar(2)) - std::remainder(yaw, 2.0 * M_PI)) < 1e-13);
    CHECK(std::abs(std::hypot(ff(0), ff(1) - v / w) - v / w) < 1e-13);
    CHECK(std::abs(ff(2) - climb * dt * k) < 1e-13);
    CHECK(std::abs(ff.segment<4>(3).norm() - 1.0) < 1e-15);
  }
}

TEST_CASE("floating-base steps do not allocate") {
  for (BaseKind kind : {BaseKind::FreeFlyer, BaseKind::Planar}) {
    const Model model = floatingModel(kind, 7);
    Data data(model);
    SolveInput in(model, 1, 0);
    in.q = startQ(model);
    in.q_dot = Eigen::VectorXd::LinSpaced(model.nv(), 0.4, -0.3);
    in.time_step = 1e-3;
    REQUIRE(in.addConstraint(static_cast<int>(model.nrOfSegments()) - 1, Eigen::MatrixXd::Identity(6, 3),
                             Eigen::VectorXd::Zero(3)));
    Eigen::VectorXd q_next(model.nq()), qd_next(model.nv()), p(model.nv()), p_next(model.nv());
    p.setZero();
    REQUIRE(step(model, data, in, q_next, qd_next));
    REQUIRE(stepSymplectic(model, data, in, p, q_next, qd_next, p_next));
    Simulator sim(model, 1e-3, Integrator::Symplectic);
    REQUIRE(sim.setState(JointPositions(in.q), JointVelocities(in.q_dot)));
    REQUIRE(sim.step(in));
    const long before = g_new_calls.load() + g_malloc_calls.load();
    for (int it = 0; it < 20; ++it) {
      CHECK(step(model, data, in, q_next, qd_next));
      CHECK(stepSymplectic(model, data, in, p, q_next, qd_next, p_next));
      CHECK(sim.step(in));
    }
    CHECK(g_new_calls.load() + g_malloc_calls.load() == before);
    CHECK(step(model, data, in, qd_next, qd_next).code() == Error::SizeMismatch);  // q_next needs nq
  }
}

TEST_CASE("a step whose position update overflows is refused with NonfiniteResult, never NaN") {
  // Finite but enormous base wrenches (the fuzz target's finding): the solve's accelerations stay
  // below its overflow check, the SE(3) update of dt qd_next does not.
  const Model model = floatingModel(BaseKind::FreeFlyer, 5);
  REQUIRE(model.status());
  Data data(model);
  SolveInput in(model);
  in.q = startQ(model);
  in.q_dot = Eigen::VectorXd::Zero(model.nv());
  in.time_step = 1e-3;
  in.ff_torques = Eigen::VectorXd::Zero(model.nv());
  in.ff_torques.head<6>().setConstant(5.4e137);
  Eigen::VectorXd q_next(model.nq()), qd_next(model.nv()), p_next(model.nv());
  const Status s = step(model, data, in, q_next, qd_next);
  CHECK(s.code() == Error::NonfiniteResult);
  CHECK(std::string(s.message()).find("overflows") != std::string::npos);
  const Eigen::VectorXd p = Eigen::VectorXd::Zero(model.nv());
  const Status t = stepSymplectic(model, data, in, p, q_next, qd_next, p_next);
  CHECK(t.code() == Error::NonfiniteResult);
}
