// WholeBodySolver (whole_body.hpp) on random floating and fixed trees: the base rows of tau are
// zero and the base held still, unactuated joints get no torque, the answer replays through
// solve() (its torques and support forces as inputs give its qdd, and with the task as
// constraints no constraint force is needed), a task no motor can realize is reported, and a
// second call of the same size allocates nothing. The Pinocchio oracles (solo12, Talos standing)
// are in Python: tests/oracles/test_whole_body.py.
#include <doctest/doctest.h>
#include <Eigen/Dense>

#include "alloc_counter.hpp"
#include "random_tree.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/whole_body.hpp"

namespace {

using vereshchagin::BaseKind;

vereshchagin::Model model(BaseKind kind, unsigned seed) {
  testutil::RandomGen g(seed);
  testutil::TreeSpec spec;
  spec.n_joints = 9;
  vereshchagin::ModelOptions options;
  options.base = kind;
  options.base_inertia = KDL::RigidBodyInertia(3.0, KDL::Vector(0.05, -0.02, 0.01),
                                               KDL::RotationalInertia(0.2, 0.3, 0.25, 0.01, 0.0, -0.02));
  return vereshchagin::Model(testutil::randomTree(g, spec), "", options);
}

void setState(const vereshchagin::Model& m, vereshchagin::SolveInput& in) {
  in.q = Eigen::VectorXd::LinSpaced(m.nq(), -0.6, 0.7);
  if (m.baseKind() == BaseKind::FreeFlyer) in.q.segment<4>(3) = Eigen::Vector4d(0.3, -0.5, 0.2, 0.8).normalized();
  in.q_dot = Eigen::VectorXd::LinSpaced(m.nv(), 0.3, -0.4);
  in.ff_torques = Eigen::VectorXd::LinSpaced(m.nv(), 0.1, 0.2);
  in.f_ext.col(2) << 1.0, -2.0, 0.5, 0.1, 0.0, -0.2;
}

// The answer replayed: tau and the support forces as inputs of a plain solve give the same qdd,
// and with the task as constraints the constraint forces vanish.
void checkReplay(const vereshchagin::Model& m, const vereshchagin::SolveInput& in,
                 const vereshchagin::WholeBodyResult& r) {
  vereshchagin::SolveInput re(m);
  re.setState(vereshchagin::JointPositions(in.q), vereshchagin::JointVelocities(in.q_dot));
  re.f_ext = in.f_ext;
  re.ff_torques = in.ff_torques + r.tau;
  for (std::size_t c = 0; c < in.contacts.size(); ++c) {
    vereshchagin::FrameRef f{
        in.contacts[c].segment,
        KDL::Frame(KDL::Vector(in.contacts[c].point(0), in.contacts[c].point(1), in.contacts[c].point(2)))};
    vereshchagin::Vector6 w;
    w << r.forces.col(c), vereshchagin::Vector3::Zero();
    REQUIRE(re.addWrench(f, w));
  }
  for (const auto& b : in.constraints)
    if (b.segment >= 0) re.constraints.push_back(b);
  vereshchagin::Data data(m);
  REQUIRE(vereshchagin::solve(m, data, re));
  const double scale = 1.0 + r.qdd.cwiseAbs().maxCoeff();
  CHECK((data.qdd() - r.qdd).cwiseAbs().maxCoeff() <= 1e-10 * scale);
  if (data.nu().size() > 0) CHECK(data.nu().cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + r.tau.cwiseAbs().maxCoeff()));
}

}  // namespace

TEST_CASE("a free-flyer holds its base still through its joints alone") {
  const vereshchagin::Model m = model(BaseKind::FreeFlyer, 5);
  REQUIRE(m.status());
  vereshchagin::SolveInput in(m);
  setState(m, in);
  in.ff_torques.head<6>().setZero();
  // Base still: its spatial acceleration [-omega x v - gravity; 0] (world axes), alpha = I.
  vereshchagin::WholeBodySolver wb(m);
  REQUIRE(wb.status());
  Eigen::Matrix<double, 6, 6> alfa = Eigen::Matrix<double, 6, 6>::Identity();
  vereshchagin::ConstraintBlock base;
  base.segment = -1;
  base.columns = 6;
  base.alfa = alfa;
  base.classical = true;  // the classical acceleration zero (the base moves)
  in.constraints.push_back(base);
  vereshchagin::WholeBodyResult r;
  REQUIRE(wb.solve(in, Eigen::VectorXi(), r));
  CHECK(r.tau.head<6>().isZero(0.0));
  CHECK(r.residual <= 1e-12);
  // The origin's classical acceleration R (vdot + w x v) and the angular one are zero (LOCAL rows).
  const Eigen::Vector3d v = in.q_dot.head<3>(), w = in.q_dot.segment<3>(3);
  CHECK((r.qdd.head<3>() + w.cross(v)).norm() <= 1e-10 * (1.0 + r.qdd.norm()));
  CHECK(r.qdd.segment<3>(3).norm() <= 1e-10 * (1.0 + r.qdd.norm()));
  checkReplay(m, in, r);
}

TEST_CASE("unactuated joints get no torque, supports and a task on a fixed tree replay") {
  const vereshchagin::Model m = model(BaseKind::Fixed, 8);
  REQUIRE(m.status());
  vereshchagin::SolveInput in(m);
  setState(m, in);
  Eigen::VectorXi actuated = Eigen::VectorXi::Ones(m.nrOfJoints());
  actuated(1) = actuated(4) = 0;
  vereshchagin::PointContact pc;
  pc.segment = static_cast<int>(m.nrOfSegments()) - 1;
  pc.point = vereshchagin::Vector3(0.02, 0.01, 0.0);
  pc.mu = 5.0;
  in.contacts.push_back(pc);
  Eigen::MatrixXd alfa = Eigen::MatrixXd::Zero(6, 2);
  alfa(2, 0) = alfa(4, 1) = 1.0;
  REQUIRE(in.addConstraint(2, alfa, Eigen::Vector2d(0.3, -0.2)));
  vereshchagin::WholeBodySolver wb(m);
  vereshchagin::WholeBodyResult r;
  const vereshchagin::Status s = wb.solve(in, actuated, r);
  REQUIRE_MESSAGE(s, s.message());
  CHECK(r.tau(1) == 0.0);
  CHECK(r.tau(4) == 0.0);
  checkReplay(m, in, r);
  // The same size again: no allocation, the same answer (nothing kept between calls).
  vereshchagin::WholeBodyResult r2;
  r2.tau.resize(r.tau.size()), r2.qdd.resize(r.qdd.size()), r2.forces.resize(3, 1);
  REQUIRE(wb.solve(in, actuated, r2));
  const long before = testutil::allocCounts().total();
  REQUIRE(wb.solve(in, actuated, r2));
  CHECK(testutil::allocCounts().total() - before == 0);
  CHECK(r2.tau == r.tau);
  CHECK(r2.forces == r.forces);
}

TEST_CASE("a task no motor and no support can realize is reported, and bad input refused") {
  const vereshchagin::Model m = model(BaseKind::Fixed, 8);
  vereshchagin::SolveInput in(m);
  setState(m, in);
  Eigen::MatrixXd alfa = Eigen::MatrixXd::Zero(6, 1);
  alfa(2, 0) = 1.0;
  REQUIRE(in.addConstraint(2, alfa, Eigen::VectorXd::Constant(1, 0.3)));
  vereshchagin::WholeBodySolver wb(m);
  vereshchagin::WholeBodyResult r;
  const Eigen::VectorXi none = Eigen::VectorXi::Zero(m.nrOfJoints());
  const vereshchagin::Status s = wb.solve(in, none, r);
  CHECK(s.code() == vereshchagin::Error::NoSolution);
  CHECK(std::string(s.message()).find("not realizable") != std::string::npos);
  CHECK(wb.solve(in, Eigen::VectorXi::Ones(2), r).code() == vereshchagin::Error::SizeMismatch);
  vereshchagin::PointContact pc;
  pc.segment = 0;
  pc.force = 3.0;
  in.contacts.push_back(pc);
  CHECK(wb.solve(in, Eigen::VectorXi(), r).code() == vereshchagin::Error::InvalidContact);
}
