// Floating bases (base_kind.hpp): sizes, free fall, constraints through the base, the checks of
// q, and no allocation in the solve. The comparison with Pinocchio's aba is in Python
// (tests/oracles/test_floating_base.py).
#include <doctest/doctest.h>
#include <Eigen/Dense>

#include "alloc_counter.hpp"
#include "floating_fixture.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/model.hpp"

namespace {

using vereshchagin::BaseKind;

vereshchagin::Model floatingModel(BaseKind kind, unsigned seed) {
  return testutil::floatingTreeModel(kind, seed, 9);
}

Eigen::VectorXd floatingState(const vereshchagin::Model& model, double scale) {
  return testutil::floatingConfiguration(model, -0.8 * scale, 0.9 * scale);
}

}  // namespace

TEST_CASE("base kinds set nq and nv, a fixed base keeps n") {
  const vereshchagin::Model ff = floatingModel(BaseKind::FreeFlyer, 3), pl = floatingModel(BaseKind::Planar, 3),
                            fx = floatingModel(BaseKind::Fixed, 3);
  REQUIRE(ff.status());
  REQUIRE(pl.status());
  CHECK(ff.nq() == ff.nrOfJoints() + 7);
  CHECK(ff.nv() == ff.nrOfJoints() + 6);
  CHECK(pl.nq() == pl.nrOfJoints() + 4);
  CHECK(pl.nv() == pl.nrOfJoints() + 3);
  CHECK(fx.nq() == fx.nrOfJoints());
  CHECK(fx.nv() == fx.nrOfJoints());
  vereshchagin::Data d(ff);
  CHECK(d.qdd().size() == ff.nv());
}

TEST_CASE("a free-flyer at rest falls with gravity, its joints still") {
  // No velocity, no torque: every body accelerates with gravity, so the joints do not move and
  // the base's acceleration in base axes is R^T g.
  const vereshchagin::Model model = floatingModel(BaseKind::FreeFlyer, 11);
  vereshchagin::Data data(model);
  vereshchagin::SolveInput in(model);
  in.q = floatingState(model, 1.0);
  in.q_dot.setZero();
  REQUIRE(vereshchagin::solve(model, data, in));
  const Eigen::Quaterniond quat(in.q(6), in.q(3), in.q(4), in.q(5));
  const Eigen::Vector3d g(in.gravity.x(), in.gravity.y(), in.gravity.z());
  const Eigen::Vector3d expected = quat.toRotationMatrix().transpose() * g;
  CHECK((data.qdd().head<3>() - expected).norm() < 1e-12);
  CHECK(data.qdd().segment<3>(3).norm() < 1e-12);
  CHECK(data.qdd().tail(model.nrOfJoints()).norm() < 1e-11);
}

TEST_CASE("a constraint couples through the base and tau_command reproduces it") {
  // A 6-D constraint on a leaf; tau_command (nv) applied as generalized force without the
  // constraint gives the constrained motion.
  for (BaseKind kind : {BaseKind::FreeFlyer, BaseKind::Planar}) {
    const vereshchagin::Model model = floatingModel(kind, 5);
    vereshchagin::Data held(model), free(model);
    vereshchagin::SolveInput in(model);
    in.q = floatingState(model, 1.0);
    in.q_dot = Eigen::VectorXd::LinSpaced(model.nv(), 0.4, -0.3);
    in.ff_torques = Eigen::VectorXd::LinSpaced(model.nv(), -1.0, 2.0);
    in.ff_torques.head(model.nv() - model.nrOfJoints()).setZero();
    const int seg = static_cast<int>(model.nrOfSegments()) - 1;
    Eigen::VectorXd beta(6);
    beta << 0.1, -0.2, 9.81, 0.3, 0.0, -0.1;
    REQUIRE(in.addConstraint(seg, Eigen::MatrixXd::Identity(6, 6), beta));
    const vereshchagin::Status s = vereshchagin::solve(model, held, in);
    REQUIRE_MESSAGE(s, s.message());
    vereshchagin::SolveInput plain(model);
    plain.q = in.q;
    plain.q_dot = in.q_dot;
    plain.ff_torques = in.ff_torques + held.commandTorques();
    REQUIRE(vereshchagin::solve(model, free, plain));
    CHECK((free.qdd() - held.qdd()).norm() < 1e-9 * (1.0 + held.qdd().norm()));
  }
}

TEST_CASE("floating-base inputs are checked with messages") {
  const vereshchagin::Model model = floatingModel(BaseKind::FreeFlyer, 7);
  vereshchagin::Data data(model);
  vereshchagin::SolveInput in(model);
  in.q = floatingState(model, 1.0);
  in.q.segment<4>(3) *= 1.01;
  vereshchagin::Status s = vereshchagin::solve(model, data, in);
  CHECK(!s);
  CHECK(std::string(s.message()).find("unit quaternion") != std::string::npos);
  in.q = Eigen::VectorXd::Zero(model.nrOfJoints());
  s = vereshchagin::solve(model, data, in);
  CHECK(std::string(s.message()).find("q has") != std::string::npos);
}

TEST_CASE("floating-base solves do not allocate") {
  for (BaseKind kind : {BaseKind::FreeFlyer, BaseKind::Planar}) {
    const vereshchagin::Model model = floatingModel(kind, 9);
    vereshchagin::Data data(model);
    vereshchagin::SolveInput in(model, 2, 0);
    in.q = floatingState(model, 0.5);
    in.q_dot = Eigen::VectorXd::LinSpaced(model.nv(), 0.4, -0.3);
    Eigen::VectorXd beta = Eigen::VectorXd::LinSpaced(6, -1.0, 1.0);
    REQUIRE(in.addConstraint(static_cast<int>(model.nrOfSegments()) - 1, Eigen::MatrixXd::Identity(6, 6), beta));
    REQUIRE(in.addConstraint(2, Eigen::MatrixXd::Identity(6, 3), beta.head(3)));
    REQUIRE(vereshchagin::solve(model, data, in));
    const long before = g_new_calls.load() + g_malloc_calls.load();
    int failed = 0;
    for (int it = 0; it < 50; ++it) {
      in.q_dot(0) = 0.01 * it;
      if (!vereshchagin::solve(model, data, in)) ++failed;
    }
    CHECK(failed == 0);
    CHECK(g_new_calls.load() + g_malloc_calls.load() == before);
  }
}
