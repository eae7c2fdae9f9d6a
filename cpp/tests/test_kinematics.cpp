// Forward kinematics (kinematics.hpp) against KDL on random chains and trees with fixed joints,
// prismatic joints and frames offset from the segment tips (merged links): poses
// (ChainFkSolverPos_recursive, TreeFkSolverPos_recursive), twists (ChainFkSolverVel_recursive),
// Jacobians (ChainJntToJacSolver, TreeJntToJacSolver, reference point moved to the frame origin)
// and bias accelerations (ChainJntToJacDotSolver, HYBRID: base axes, tip origin; on trees along
// the chain of each segment's path). Tolerance 1e-9 relative. Then every error code.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainfksolvervel_recursive.hpp>
#include <kdl/chainjnttojacdotsolver.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treejnttojacsolver.hpp>

#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/kinematics.hpp"

namespace {

using testutil::relErr;
using vereshchagin::FrameRef;
using vereshchagin::JointPositions;
using vereshchagin::JointVelocities;
using vereshchagin::KinematicsData;
using vereshchagin::Model;
using vereshchagin::Vector6;
constexpr double kTol = 1e-9;

Eigen::Matrix4d hom(const KDL::Frame& f) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T(r, c) = f.M(r, c);
    T(r, 3) = f.p(r);
  }
  return T;
}

Vector6 vec(const KDL::Twist& t) {
  Vector6 v;
  for (int r = 0; r < 6; ++r) v(r) = t(r);
  return v;
}

// KDL's tip-origin twist or Jdot qd of a segment, moved to the frame origin offset by r (base axes)
// from the tip: v_P = v + w x r; classical a_P = a + dw x r + w x (w x r).
Vector6 twistAt(const KDL::Twist& t, const KDL::Vector& r) {
  return vec(KDL::Twist(t.vel + t.rot * r, t.rot));
}
Vector6 biasAt(const KDL::Twist& a_tip, const KDL::Vector& w, const KDL::Vector& r) {
  return vec(KDL::Twist(a_tip.vel + a_tip.rot * r + w * (w * r), a_tip.rot));
}

// Checks every segment of a chain model (frames offset by `offset` from each tip) against KDL.
void checkChain(const KDL::Chain& chain, testutil::RandomGen& g) {
  const Model model(chain);
  KinematicsData kd(model);
  const unsigned int n = chain.getNrOfJoints();
  const KDL::JntArray q = g.q(n), qd = g.qdot(n);
  REQUIRE(forwardKinematics(model, kd, JointPositions(q.data), JointVelocities(qd.data)).ok());
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainFkSolverVel_recursive fkv(chain);
  KDL::ChainJntToJacSolver jac(chain);
  KDL::ChainJntToJacDotSolver jdot(chain);
  for (int i = 0; i < static_cast<int>(chain.getNrOfSegments()); ++i) {
    const FrameRef frame{i, g.frame(0.3)};
    KDL::Frame tip, pose;
    REQUIRE(fk.JntToCart(q, tip, i + 1) >= 0);
    REQUIRE(framePose(model, kd, frame, pose).ok());
    CHECK(relErr(hom(pose), hom(tip * frame.in_tip)) < kTol);
    const KDL::Vector r = tip.M * frame.in_tip.p;
    KDL::FrameVel fv;
    REQUIRE(fkv.JntToCart(KDL::JntArrayVel(q, qd), fv, i + 1) >= 0);
    Vector6 twist, bias;
    REQUIRE(frameTwist(model, kd, frame, twist).ok());
    CHECK(relErr(twist, twistAt(fv.GetTwist(), r)) < kTol);
    KDL::Jacobian J(n);
    REQUIRE(jac.JntToJac(q, J, i + 1) >= 0);
    J.changeRefPoint(r);
    Eigen::MatrixXd ours(6, n);
    REQUIRE(frameJacobian(model, kd, frame, ours).ok());
    CHECK(relErr(ours, J.data) < kTol);
    KDL::Twist a_tip;
    REQUIRE(jdot.JntToJacDot(KDL::JntArrayVel(q, qd), a_tip, i + 1) >= 0);
    REQUIRE(frameBiasAcceleration(model, kd, frame, bias).ok());
    CHECK(relErr(bias, biasAt(a_tip, fv.GetTwist().rot, r)) < kTol);
  }
}

TEST_CASE("chain kinematics match KDL (poses, twists, Jacobians, Jdot qd)") {
  for (unsigned long long seed = 1; seed <= 40; ++seed) {
    CAPTURE(seed);
    testutil::RandomGen g(seed);
    testutil::ChainSpec spec;
    spec.n_joints = g.integer(1, 12);
    spec.fixed_before = {0, g.integer(0, spec.n_joints), spec.n_joints};
    checkChain(g.chain(spec), g);
  }
}

// The segments on the path from the base to `segment` as a chain, and its joints' model indices.
KDL::Chain pathChain(const Model& model, int segment, std::vector<int>& joints) {
  std::vector<int> path;
  for (int i = segment; i >= 0; i = model.parents()[static_cast<std::size_t>(i)]) path.insert(path.begin(), i);
  KDL::Chain chain;
  joints.clear();
  for (int i : path) {
    chain.addSegment(model.segment(i));
    if (model.jointOfSegment()[static_cast<std::size_t>(i)] >= 0)
      joints.push_back(model.jointOfSegment()[static_cast<std::size_t>(i)]);
  }
  return chain;
}

void checkTreeSegment(const Model& model, KinematicsData& kd, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                      int i, testutil::RandomGen& g) {
  std::vector<int> joints;
  const KDL::Chain chain = pathChain(model, i, joints);
  KDL::JntArray qc(chain.getNrOfJoints()), qdc(chain.getNrOfJoints());
  for (std::size_t k = 0; k < joints.size(); ++k) qc(k) = q(joints[k]), qdc(k) = qd(joints[k]);
  const FrameRef frame{i, g.frame(0.3)};
  KDL::FrameVel fv;
  KDL::ChainFkSolverVel_recursive(chain).JntToCart(KDL::JntArrayVel(qc, qdc), fv);
  KDL::Twist a_tip;
  KDL::ChainJntToJacDotSolver(chain).JntToJacDot(KDL::JntArrayVel(qc, qdc), a_tip);
  const KDL::Vector r = fv.M.R * frame.in_tip.p;
  Vector6 twist, bias;
  REQUIRE(frameTwist(model, kd, frame, twist).ok());
  REQUIRE(frameBiasAcceleration(model, kd, frame, bias).ok());
  CHECK(relErr(twist, twistAt(fv.GetTwist(), r)) < kTol);
  CHECK(relErr(bias, biasAt(a_tip, fv.GetTwist().rot, r)) < kTol);
}

TEST_CASE("tree kinematics match KDL's tree solvers and path chains") {
  for (unsigned long long seed = 1; seed <= 25; ++seed) {
    CAPTURE(seed);
    testutil::RandomGen g(seed);
    testutil::TreeSpec spec;
    spec.n_joints = g.integer(1, 14);
    const KDL::Tree tree = testutil::randomTree(g, spec);
    const Model model(tree);
    REQUIRE(model.status().ok());
    KinematicsData kd(model);
    const unsigned int n = model.nrOfJoints();
    const Eigen::VectorXd q = g.q(n).data, qd = g.qdot(n).data;
    REQUIRE(forwardKinematics(model, kd, JointPositions(q), JointVelocities(qd)).ok());
    const KDL::Tree copy = tree;  // KDL's tree solvers keep a copy: its q_nr order is theirs
    KDL::JntArray qk(n);
    std::vector<int> qnr(n);
    for (unsigned int j = 0; j < n; ++j) {
      const std::string& name = model.segment(model.segmentOfJoint()[j]).getName();
      qnr[j] = static_cast<int>(GetTreeElementQNr(copy.getSegment(name)->second));
      qk(qnr[j]) = q(j);
    }
    KDL::TreeFkSolverPos_recursive fk(copy);
    KDL::TreeJntToJacSolver jac(copy);
    for (int i = 0; i < static_cast<int>(model.nrOfSegments()); ++i) {
      const std::string& name = model.segment(i).getName();
      KDL::Frame tip, pose;
      REQUIRE(fk.JntToCart(qk, tip, name) >= 0);
      REQUIRE(framePose(model, kd, FrameRef{i, KDL::Frame::Identity()}, pose).ok());
      CHECK(relErr(hom(pose), hom(tip)) < kTol);
      KDL::Jacobian J(n);
      REQUIRE(jac.JntToJac(qk, J, name) >= 0);
      Eigen::MatrixXd ours(6, n), theirs(6, n);
      for (unsigned int j = 0; j < n; ++j) theirs.col(j) = J.data.col(qnr[j]);
      REQUIRE(frameJacobian(model, kd, FrameRef{i, KDL::Frame::Identity()}, ours).ok());
      CHECK(relErr(ours, theirs) < kTol);
      checkTreeSegment(model, kd, q, qd, i, g);
    }
  }
}

TEST_CASE("the base frame: identity, zero twist, zero Jacobian") {
  testutil::RandomGen g(7);
  const Model model(g.chain(4));
  KinematicsData kd(model);
  const Eigen::VectorXd q = g.q(4).data, qd = g.qdot(4).data;
  REQUIRE(forwardKinematics(model, kd, JointPositions(q), JointVelocities(qd)).ok());
  const FrameRef base{-1, KDL::Frame(KDL::Vector(1, 2, 3))};
  KDL::Frame pose;
  Vector6 t;
  Eigen::MatrixXd J = Eigen::MatrixXd::Ones(6, 4);
  CHECK(framePose(model, kd, base, pose).ok());
  CHECK(pose.p == KDL::Vector(1, 2, 3));
  CHECK(frameTwist(model, kd, base, t).ok());
  CHECK(t.isZero());
  CHECK(frameJacobian(model, kd, base, J).ok());
  CHECK(J.isZero());
}

TEST_CASE("errors: codes and messages") {
  testutil::RandomGen g(3);
  const Model model(g.chain(3)), other(g.chain(3));
  KinematicsData kd(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(3), q4 = Eigen::VectorXd::Zero(4);
  KDL::Frame pose;
  Vector6 t;
  CHECK(framePose(model, kd, FrameRef{0, {}}, pose).code() == vereshchagin::Error::NoSolution);
  vereshchagin::Status s = forwardKinematics(model, kd, JointPositions(q4));
  CHECK(s.code() == vereshchagin::Error::SizeMismatch);
  CHECK(std::string(s.message()) == "q has 4 entries, the model has 3 joints");
  Eigen::VectorXd bad = q;
  bad(1) = NAN;
  s = forwardKinematics(model, kd, JointPositions(q), JointVelocities(bad));
  CHECK(s.code() == vereshchagin::Error::NonfiniteInput);
  CHECK(std::string(s.message()) == "q_dot[1] is not finite");
  CHECK(forwardKinematics(other, kd, JointPositions(q)).code() == vereshchagin::Error::NotUpToDate);
  REQUIRE(forwardKinematics(model, kd, JointPositions(q)).ok());
  CHECK(frameTwist(model, kd, FrameRef{0, {}}, t).code() == vereshchagin::Error::NoSolution);
  CHECK(framePose(model, kd, FrameRef{3, {}}, pose).code() == vereshchagin::Error::OutOfRange);
  CHECK(framePose(model, kd, FrameRef{-2, {}}, pose).code() == vereshchagin::Error::OutOfRange);
  Eigen::MatrixXd J(6, 2);
  CHECK(frameJacobian(model, kd, FrameRef{0, {}}, J).code() == vereshchagin::Error::SizeMismatch);
}

}  // namespace

// ---- task.hpp ----
#include "vereshchagin/task.hpp"

namespace {

TEST_CASE("beta from a classical acceleration and pose errors") {
  testutil::RandomGen g(11);
  const KDL::Chain chain = g.chain(5);
  const Model model(chain);
  KinematicsData kd(model);
  const Eigen::VectorXd q = g.q(5).data, qd = g.qdot(5).data;
  REQUIRE(forwardKinematics(model, kd, JointPositions(q), JointVelocities(qd)).ok());
  const FrameRef frame{4, g.frame(0.3)};
  Vector6 twist, a;
  REQUIRE(frameTwist(model, kd, frame, twist).ok());
  for (int r = 0; r < 6; ++r) a(r) = g.uniform(-3.0, 3.0);
  const Eigen::MatrixXd alfa = g.alfa(4).data;
  const KDL::Vector gravity(0.1, -0.2, -9.81);
  Eigen::VectorXd beta(4);
  REQUIRE(vereshchagin::betaForFrame(model, kd, frame, alfa, a, gravity, beta).ok());
  Vector6 spatial;  // [a_lin - w x v - g; a_ang]
  spatial.head<3>() = a.head<3>() - twist.tail<3>().cross(twist.head<3>()) - vereshchagin::Vector3(0.1, -0.2, -9.81);
  spatial.tail<3>() = a.tail<3>();
  CHECK(relErr(beta, alfa.transpose() * spatial) < 1e-14);
  Eigen::VectorXd wrong(3);
  CHECK(vereshchagin::betaForFrame(model, kd, frame, alfa, a, gravity, wrong).code() ==
        vereshchagin::Error::SizeMismatch);
  for (int k = 0; k < 50; ++k) {
    const KDL::Frame c = g.frame(), d = g.frame();
    CHECK(relErr(vereshchagin::poseError(c, d), vec(KDL::diff(c, d))) < 1e-9);
  }
  const KDL::Frame c = g.frame();  // angles near 0 and pi
  CHECK(vereshchagin::poseError(c, c).norm() < 1e-15);
  const KDL::Frame flipped(c.M * KDL::Rotation::Rot(KDL::Vector(1, 2, 3), M_PI - 1e-9), c.p);
  CHECK(std::abs(vereshchagin::poseError(c, flipped).tail<3>().norm() - (M_PI - 1e-9)) < 1e-9);
}

}  // namespace
