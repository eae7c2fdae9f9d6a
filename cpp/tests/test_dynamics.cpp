// Dynamics companions (dynamics.hpp) against KDL on random chains and trees with fixed joints,
// prismatic joints and rotor inertias: ChainIdSolver_RNE and TreeIdSolver_RNE (external wrenches
// converted to KDL's tip axes; KDL takes physical gravity too), ChainDynParam (mass matrix,
// gravity, Coriolis), and on trees H from RNE columns. Tolerance 1e-9 relative. Then errors.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>

#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/dynamics.hpp"

namespace {

using testutil::relErr;
using vereshchagin::DynamicsData;
using vereshchagin::JointAccelerations;
using vereshchagin::JointPositions;
using vereshchagin::JointVelocities;
using vereshchagin::Matrix6X;
using vereshchagin::Model;
constexpr double kTol = 1e-9;

// Random wrenches per segment, base axes, moment about the tip origin (6 x ns).
Matrix6X randomWrenches(testutil::RandomGen& g, int ns) {
  Matrix6X f(6, ns);
  for (int i = 0; i < ns; ++i)
    for (int r = 0; r < 6; ++r) f(r, i) = g.uniform(-2.0, 2.0);
  return f;
}

// The same wrench in the tip's axes (KDL's solvers), R the tip orientation in the base.
KDL::Wrench inTipAxes(const KDL::Rotation& R, const Matrix6X& f, int i) {
  return R.Inverse(KDL::Wrench(KDL::Vector(f(0, i), f(1, i), f(2, i)), KDL::Vector(f(3, i), f(4, i), f(5, i))));
}

TEST_CASE("chain dynamics match KDL (RNE with f_ext, ChainDynParam)") {
  for (unsigned long long seed = 1; seed <= 40; ++seed) {
    CAPTURE(seed);
    testutil::RandomGen g(seed);
    testutil::ChainSpec spec;
    spec.n_joints = g.integer(1, 12);
    spec.fixed_before = {0, g.integer(0, spec.n_joints), spec.n_joints};
    const KDL::Chain chain = g.chain(spec);
    const Model model(chain);
    REQUIRE(model.status().ok());
    DynamicsData dd(model);
    const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
    const KDL::JntArray q = g.q(n), qd = g.qdot(n), qdd = g.torques(n);
    const KDL::Vector gravity = g.vector(-10.0, 10.0);
    const Matrix6X f = randomWrenches(g, static_cast<int>(ns));
    KDL::ChainFkSolverPos_recursive fk(chain);
    KDL::Wrenches wk(ns);
    for (unsigned int i = 0; i < ns; ++i) {
      KDL::Frame tip;
      fk.JntToCart(q, tip, static_cast<int>(i) + 1);
      wk[i] = inTipAxes(tip.M, f, static_cast<int>(i));
    }
    KDL::JntArray tau_k(n);
    KDL::ChainIdSolver_RNE rne(chain, gravity);
    REQUIRE(rne.CartToJnt(q, qd, qdd, wk, tau_k) >= 0);
    Eigen::VectorXd tau(n);
    REQUIRE(inverseDynamics(model, dd, JointPositions(q.data), JointVelocities(qd.data), JointAccelerations(qdd.data),
                            f, gravity, tau)
                .ok());
    CHECK(relErr(tau, tau_k.data) < kTol);
    KDL::ChainDynParam dyn(chain, gravity);
    KDL::JntSpaceInertiaMatrix Hk(n);
    KDL::JntArray gk(n), ck(n);
    REQUIRE(dyn.JntToMass(q, Hk) >= 0);
    REQUIRE(dyn.JntToGravity(q, gk) >= 0);
    REQUIRE(dyn.JntToCoriolis(q, qd, ck) >= 0);
    Eigen::MatrixXd H(n, n);
    REQUIRE(massMatrix(model, dd, JointPositions(q.data), H).ok());
    CHECK(relErr(H, Hk.data) < kTol);
    REQUIRE(gravityTorques(model, dd, JointPositions(q.data), gravity, tau).ok());
    CHECK(relErr(tau, gk.data) < kTol);
    REQUIRE(coriolisTorques(model, dd, JointPositions(q.data), JointVelocities(qd.data), tau).ok());
    CHECK(relErr(tau, ck.data) < kTol);
  }
}

// KDL's tree solvers on a copy of the tree, joint vectors mapped to its q_nr order.
struct TreeOracle {
  TreeOracle(const KDL::Tree& t, const Model& m) : tree(t), model(m), fk(tree), nj(m.nrOfJoints()), qnr(nj) {
    for (unsigned int j = 0; j < nj; ++j)
      qnr[j] = GetTreeElementQNr(tree.getSegment(model.segment(model.segmentOfJoint()[j]).getName())->second);
  }
  KDL::JntArray toKdl(const Eigen::VectorXd& v) const {
    KDL::JntArray a(nj);
    for (unsigned int j = 0; j < nj; ++j) a(qnr[j]) = v(j);
    return a;
  }
  Eigen::VectorXd fromKdl(const KDL::JntArray& a) const {
    Eigen::VectorXd v(nj);
    for (unsigned int j = 0; j < nj; ++j) v(j) = a(qnr[j]);
    return v;
  }
  Eigen::VectorXd rne(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                      const Matrix6X& f, const KDL::Vector& gravity) {
    KDL::WrenchMap wm;
    for (int i = 0; i < f.cols(); ++i) {
      const std::string& name = model.segment(i).getName();
      KDL::Frame tip;
      fk.JntToCart(toKdl(q), tip, name);
      wm[name] = inTipAxes(tip.M, f, i);
    }
    KDL::TreeIdSolver_RNE solver(tree, gravity);
    KDL::JntArray tau(nj);
    REQUIRE(solver.CartToJnt(toKdl(q), toKdl(qd), toKdl(qdd), wm, tau) >= 0);
    return fromKdl(tau);
  }
  const KDL::Tree tree;  // a copy: KDL's tree solvers number the joints of their copy
  const Model& model;
  KDL::TreeFkSolverPos_recursive fk;
  unsigned int nj;
  std::vector<unsigned int> qnr;
};

TEST_CASE("tree dynamics match KDL's TreeIdSolver_RNE") {
  for (unsigned long long seed = 1; seed <= 25; ++seed) {
    CAPTURE(seed);
    testutil::RandomGen g(seed);
    testutil::TreeSpec spec;
    spec.n_joints = g.integer(1, 14);
    const KDL::Tree tree = testutil::randomTree(g, spec);
    const Model model(tree);
    REQUIRE(model.status().ok());
    DynamicsData dd(model);
    TreeOracle oracle(tree, model);
    const unsigned int n = model.nrOfJoints();
    const int ns = static_cast<int>(model.nrOfSegments());
    const Eigen::VectorXd q = g.q(n).data, qd = g.qdot(n).data, qdd = g.torques(n).data, z = Eigen::VectorXd::Zero(n);
    const KDL::Vector gravity = g.vector(-10.0, 10.0);
    const Matrix6X f = randomWrenches(g, ns), none(6, 0);
    Eigen::VectorXd tau(n);
    REQUIRE(inverseDynamics(model, dd, JointPositions(q), JointVelocities(qd), JointAccelerations(qdd), f, gravity, tau)
                .ok());
    CHECK(relErr(tau, oracle.rne(q, qd, qdd, f, gravity)) < kTol);
    REQUIRE(gravityTorques(model, dd, JointPositions(q), gravity, tau).ok());
    CHECK(relErr(tau, oracle.rne(q, z, z, none, gravity)) < kTol);
    REQUIRE(coriolisTorques(model, dd, JointPositions(q), JointVelocities(qd), tau).ok());
    CHECK(relErr(tau, oracle.rne(q, qd, z, none, KDL::Vector::Zero())) < kTol);
    Eigen::MatrixXd H(n, n), Hk(n, n);
    for (unsigned int k = 0; k < n; ++k)
      Hk.col(k) = oracle.rne(q, z, Eigen::VectorXd::Unit(n, k), none, KDL::Vector::Zero());
    REQUIRE(massMatrix(model, dd, JointPositions(q), H).ok());
    CHECK(relErr(H, Hk) < kTol);
    CHECK((H - H.transpose()).cwiseAbs().maxCoeff() == 0.0);
  }
}

TEST_CASE("errors: codes and messages") {
  testutil::RandomGen g(5);
  const Model model(g.chain(3)), other(g.chain(3));
  DynamicsData dd(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
  Eigen::VectorXd tau(3), tau2(2);
  Eigen::MatrixXd H(3, 2);
  const KDL::Vector gravity(0, 0, -9.81);
  vereshchagin::Status s = gravityTorques(model, dd, JointPositions(q), gravity, tau2);
  CHECK(s.code() == vereshchagin::Error::SizeMismatch);
  CHECK(std::string(s.message()) == "tau is 2x1, expected 3x1");
  CHECK(massMatrix(model, dd, JointPositions(q), H).code() == vereshchagin::Error::SizeMismatch);
  CHECK(gravityTorques(other, dd, JointPositions(q), gravity, tau).code() == vereshchagin::Error::NotUpToDate);
  CHECK(gravityTorques(model, dd, JointPositions(q), KDL::Vector(0, NAN, 0), tau).code() ==
        vereshchagin::Error::NonfiniteInput);
  const Matrix6X f(6, 2);
  s = inverseDynamics(model, dd, JointPositions(q), JointVelocities(q), JointAccelerations(q), f, gravity, tau);
  CHECK(s.code() == vereshchagin::Error::SizeMismatch);
  CHECK(std::string(s.message()) == "f_ext has 2 columns, expected 3 (one per segment) or 0");
}

}  // namespace
