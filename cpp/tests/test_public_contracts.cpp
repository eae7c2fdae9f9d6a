// Public contracts not covered elsewhere, each against an oracle the library did not compute:
//  * maxConstraints() = 6 x n_segments (capped by SolverOptions::max_constraints): that many
//    columns solve, one more is E_TOO_MANY_CONSTRAINTS.
//  * articulatedInertia(j) = 1 / (H_jj^-1 of the joints j moves), i.e. the Schur complement of the
//    block of joint j's subtree joints in H(q), with every other joint held. H from KDL's
//    ChainDynParam (chains) and from KDL's TreeIdSolver_RNE columns (trees).
//  * setJointAccelerations(): E_NO_SOLUTION before a successful solve (and after a failed one),
//    E_SIZE_MISMATCH for a wrong size; then the link accelerations of arbitrary qdd (base and tip
//    axes) equal the time derivative of KDL's link velocities (ChainFkSolverVel_recursive on the
//    path to each segment) along q(t) = q + qd t + qdd t^2 / 2, by central differences, converted
//    to spatial accelerations (a = d/dt v_tip - w x v_tip, plus root_acc).
//  * On trees: linkLocalPose() against KDL's TreeFkSolverPos_recursive (pose in the parent's tip
//    frame), linkLocalVelocity() against ChainFkSolverVel_recursive, linkLocalAcceleration() as
//    above, in each segment's tip axes.
#include <map>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <Eigen/LU>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolvervel_recursive.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>

#include "random_chain.hpp"
#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/tree_hd_solver.hpp"

using testutil::relErr;
using testutil::relErrCols;
using testutil::str;
using Matrix6X = vereshchagin::HdSolver::Matrix6X;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using vereshchagin::HdSolver;

namespace {

const KDL::Twist kGrav(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());

Eigen::Vector3d vec(const KDL::Vector& v) {
  return Eigen::Vector3d(v.x(), v.y(), v.z());
}

Eigen::Matrix3d mat3(const KDL::Rotation& R) {
  Eigen::Matrix3d M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = R(r, c);
  return M;
}

Vector6 twist6(const KDL::Twist& t) {
  Vector6 v;
  v << vec(t.vel), vec(t.rot);
  return v;
}

// The path from the base to every solver segment as a KDL chain, with the solver's joint index of
// each of its moving joints (KDL builds the chain; the indices come from the joint names).
struct PathChain {
  KDL::Chain chain;
  std::vector<int> joints;
};

std::vector<PathChain> pathChains(const KDL::Tree& tree, const vereshchagin::TreeHdSolver& s) {
  std::map<std::string, int> index;
  for (std::size_t j = 0; j < s.jointNames().size(); ++j) index[s.jointNames()[j]] = static_cast<int>(j);
  std::vector<PathChain> out(s.nrOfSegments());
  for (unsigned int i = 0; i < s.nrOfSegments(); ++i) {
    tree.getChain(s.rootName(), s.segmentNames()[i], out[i].chain);
    for (unsigned int k = 0; k < out[i].chain.getNrOfSegments(); ++k) {
      const KDL::Joint& j = out[i].chain.getSegment(k).getJoint();
      if (j.getType() != KDL::Joint::Fixed) out[i].joints.push_back(index.at(j.getName()));
    }
  }
  return out;
}

PathChain chainPrefix(const KDL::Chain& chain, unsigned int segments) {
  PathChain p;
  int joint = 0;
  for (unsigned int k = 0; k < segments; ++k) {
    p.chain.addSegment(chain.getSegment(k));
    if (chain.getSegment(k).getJoint().getType() != KDL::Joint::Fixed) p.joints.push_back(joint++);
  }
  return p;
}

// KDL's velocity of the tip of a path chain at (q, qd) of the whole robot: base axes, [v_tip; w].
KDL::FrameVel tipVelocity(const PathChain& p, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  const unsigned int n = p.chain.getNrOfJoints();
  KDL::JntArrayVel jv(n);
  for (unsigned int k = 0; k < n; ++k) {
    jv.q(k) = q(p.joints[k]);
    jv.qdot(k) = qd(p.joints[k]);
  }
  KDL::ChainFkSolverVel_recursive fk(p.chain);
  KDL::FrameVel out;
  fk.JntToCart(jv, out);
  return out;
}

// Spatial acceleration of every segment's tip (base axes, tip origin, with root_acc) along
// q(t) = q + qd t + qdd t^2 / 2, by central differences of KDL's velocities (error O(h^2)).
Matrix6X accelerationsByDifferences(const std::vector<PathChain>& paths, const Eigen::VectorXd& q,
                                    const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd, const Vector6& root_acc) {
  const double h = 1e-5;
  Matrix6X acc(6, paths.size());
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const KDL::FrameVel now = tipVelocity(paths[i], q, qd);
    const KDL::FrameVel plus = tipVelocity(paths[i], q + qd * h + 0.5 * qdd * h * h, qd + qdd * h);
    const KDL::FrameVel minus = tipVelocity(paths[i], q - qd * h + 0.5 * qdd * h * h, qd - qdd * h);
    const Eigen::Vector3d v = vec(now.p.v), w = vec(now.M.w);
    const Eigen::Vector3d dv = (vec(plus.p.v) - vec(minus.p.v)) / (2 * h);
    const Eigen::Vector3d dw = (vec(plus.M.w) - vec(minus.M.w)) / (2 * h);
    acc.col(i) << dv - w.cross(v) + root_acc.head<3>(), dw + root_acc.tail<3>();
  }
  return acc;
}

void maxConstraintChecks(HdSolver& s, testutil::RandomGen& g, const std::string& tag) {
  const unsigned int n = s.nrOfJoints(), ns = s.nrOfSegments();
  const int expected = std::min(static_cast<int>(6 * ns), vereshchagin::SolverOptions::kDefaultConstraintCapacity);
  CHECK_MESSAGE(s.maxConstraints() == expected, tag << ": maxConstraints " << str(s.maxConstraints()));
  const int m = s.maxConstraints();
  Matrix6X alfa = g.alfa(m + 1).data;
  Eigen::VectorXd beta = g.beta(m + 1).data;
  Eigen::VectorXi seg(m + 1);
  for (int c = 0; c <= m; ++c) seg(c) = c % static_cast<int>(ns);
  const Eigen::VectorXd q = g.q(n).data, qd = g.qdot(n).data;
  int rc = s.solve(q, qd, alfa.leftCols(m), beta.head(m), seg.head(m), Matrix6X(6, 0), Eigen::VectorXd());
  CHECK_MESSAGE((rc == 0 && s.constraintCount() == m),
                tag << ": " << str(m) << " columns: rc " << str(rc) << " " << s.errorMessage());
  rc = s.solve(q, qd, alfa, beta, seg, Matrix6X(6, 0), Eigen::VectorXd());
  CHECK_MESSAGE(rc == HdSolver::E_TOO_MANY_CONSTRAINTS, tag << ": " << str(m + 1) << " columns: rc " << str(rc));
}

// SolverOptions::max_constraints: the capacity it sets (capped at 6 per segment), a solve within
// it equal to the default solver's bit for bit, one column more refused naming the option,
// negative values refused; and a 2,000-segment chain (12,000 columns by the old rule: its
// coupling workspace alone was 4 x 12,000^2 doubles, 4.6 GB) builds and solves.
TEST_CASE("SolverOptions::max_constraints sets the capacity and a 2000-segment chain solves") {
  testutil::RandomGen g(37);
  testutil::ChainSpec spec;
  spec.n_joints = 9;
  const KDL::Chain chain = g.chain(spec);
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
  vereshchagin::SolverOptions small;
  small.max_constraints = 8;
  vereshchagin::ChainHdSolver capped(chain, kGrav, small), full(chain, kGrav);
  CHECK_MESSAGE((capped.maxConstraints() == 8 && full.maxConstraints() == static_cast<int>(6 * ns)),
                "capacity: maxConstraints " << str(capped.maxConstraints()) << " / " << str(full.maxConstraints()));
  const Eigen::VectorXd q = g.q(n).data, qd = g.qdot(n).data;
  const Matrix6X alfa = g.alfa(9).data;
  const Eigen::VectorXd beta = g.beta(9).data;
  Eigen::VectorXi seg(9);
  for (int c = 0; c < 9; ++c) seg(c) = (c * 5) % static_cast<int>(ns);
  int rc = capped.solve(q, qd, alfa.leftCols(8), beta.head(8), seg.head(8), Matrix6X(6, 0), Eigen::VectorXd());
  const int rc_full = full.solve(q, qd, alfa.leftCols(8), beta.head(8), seg.head(8), Matrix6X(6, 0), Eigen::VectorXd());
  CHECK_MESSAGE((rc == 0 && rc_full == 0 && capped.qdd() == full.qdd() && capped.nu() == full.nu()),
                "capacity: 8 columns within the capacity equal the default solver's");
  rc = capped.solve(q, qd, alfa, beta, seg, Matrix6X(6, 0), Eigen::VectorXd());
  CHECK_MESSAGE((rc == HdSolver::E_TOO_MANY_CONSTRAINTS &&
                 std::string(capped.errorMessage()).find("max_constraints") != std::string::npos),
                "capacity: 9 columns refused naming max_constraints: " << std::string(capped.errorMessage()));
  vereshchagin::SolverOptions bad;
  bad.max_constraints = -1;
  CHECK_MESSAGE(full.setOptions(bad) == HdSolver::E_INVALID_OPTIONS, "capacity: max_constraints = -1 refused");
  small.max_constraints = 1000;  // beyond 6 per segment: capped there
  CHECK_MESSAGE((full.setOptions(small) == 0 && full.maxConstraints() == static_cast<int>(6 * ns)),
                "capacity: 1000 capped at 6 per segment");
  KDL::Chain long_chain;
  for (int i = 0; i < 2000; ++i)
    long_chain.addSegment(KDL::Segment(
        KDL::Joint(i % 2 ? KDL::Joint::RotY : KDL::Joint::RotX), KDL::Frame(KDL::Vector(0.0, 0.0, 0.01)),
        KDL::RigidBodyInertia(0.1, KDL::Vector(0.0, 0.0, -0.005), KDL::RotationalInertia(1e-5, 1e-5, 1e-6))));
  vereshchagin::ChainHdSolver big(long_chain, kGrav);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2000);
  rc = big.solve(zero, zero, Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), Eigen::VectorXd());
  CHECK_MESSAGE(
      (big.modelError() == 0 && rc == 0 &&
       big.maxConstraints() == vereshchagin::SolverOptions::kDefaultConstraintCapacity && big.qdd().allFinite()),
      "capacity: a 2,000-segment chain builds and solves: rc " << str(rc) << " " << big.errorMessage());
}

// D_j against the Schur complement of H on the joints j moves (sub: their indices, j first).
void articulatedChecks(const HdSolver& s, const Eigen::MatrixXd& H, const std::vector<std::vector<int>>& moved,
                       const std::string& tag) {
  double worst = 0.0;
  for (std::size_t j = 0; j < moved.size(); ++j) {
    const std::vector<int>& sub = moved[j];
    Eigen::MatrixXd Hs(sub.size(), sub.size());
    for (std::size_t a = 0; a < sub.size(); ++a)
      for (std::size_t b = 0; b < sub.size(); ++b) Hs(a, b) = H(sub[a], sub[b]);
    const double expected = 1.0 / Hs.inverse()(0, 0);
    const double got = s.articulatedInertia(static_cast<unsigned int>(j));
    worst = std::max(worst, std::abs(got - expected) / std::abs(expected));
  }
  CHECK_MESSAGE(worst <= 1e-9, tag << ": articulatedInertia vs Schur complement of H rel err " << str(worst));
}

TEST_CASE("chain: maxConstraints, setJointAccelerations and articulatedInertia") {
  testutil::RandomGen g(31);
  testutil::ChainSpec spec;
  spec.n_joints = 7;
  spec.rotor_inertia = false;  // KDL's ChainDynParam H without rotors, as the solver's
  spec.fixed_before = {3};
  const KDL::Chain chain = g.chain(spec);
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
  vereshchagin::ChainHdSolver s(chain, kGrav);
  maxConstraintChecks(s, g, "chain");
  vereshchagin::ChainHdSolver fresh(chain, kGrav);
  const Eigen::VectorXd q = g.q(n).data, qd = g.qdot(n).data, qdd = g.torques(n).data;
  int rc = fresh.setJointAccelerations(qdd);
  CHECK_MESSAGE(rc == HdSolver::E_NO_SOLUTION, "chain: setJointAccelerations before a solve: rc " << str(rc));
  rc = fresh.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), Eigen::VectorXd());
  CHECK_MESSAGE(rc == 0, "chain: solve");
  rc = fresh.setJointAccelerations(qdd.head(n - 1));
  CHECK_MESSAGE(rc == HdSolver::E_SIZE_MISMATCH, "chain: setJointAccelerations wrong size: rc " << str(rc));
  CHECK_MESSAGE(fresh.setJointAccelerations(qdd) == 0, "chain: setJointAccelerations");
  std::vector<PathChain> paths;
  for (unsigned int i = 1; i <= ns; ++i) paths.push_back(chainPrefix(chain, i));
  const Matrix6X expected = accelerationsByDifferences(paths, q, qd, qdd, testutil::toVector(kGrav));
  const double e = relErrCols(fresh.linkAccelerations().rightCols(ns), expected);
  CHECK_MESSAGE(e <= 1e-7, "chain: setJointAccelerations link accelerations vs KDL differences rel err " << str(e));
  CHECK_MESSAGE(fresh.linkAccelerations().col(0) == testutil::toVector(kGrav), "chain: column 0 is root_acc");
  // A failed solve withdraws the state.
  rc = fresh.solve(q.head(1), qd, Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), Eigen::VectorXd());
  CHECK_MESSAGE((rc != 0 && fresh.setJointAccelerations(qdd) == HdSolver::E_NO_SOLUTION),
                "chain: setJointAccelerations after a failed solve");

  KDL::ChainDynParam dyn(chain, KDL::Vector::Zero());
  KDL::JntArray jq(n);
  jq.data = q;
  KDL::JntSpaceInertiaMatrix H(n);
  dyn.JntToMass(jq, H);
  CHECK_MESSAGE(fresh.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), Eigen::VectorXd()) == 0, "solve");
  std::vector<std::vector<int>> moved(n);
  for (unsigned int j = 0; j < n; ++j)
    for (unsigned int k = j; k < n; ++k) moved[j].push_back(static_cast<int>(k));
  articulatedChecks(fresh, H.data, moved, "chain");
}

Eigen::Matrix3d relative(const KDL::Frame& parent, const KDL::Frame& child, Eigen::Vector3d& p) {
  const KDL::Frame X = parent.Inverse() * child;
  p = vec(X.p);
  return mat3(X.M);
}

void treeGetterChecks(const KDL::Tree& tree, vereshchagin::TreeHdSolver& s, const Eigen::VectorXd& q,
                      const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  const unsigned int ns = s.nrOfSegments(), n = s.nrOfJoints();
  KDL::TreeFkSolverPos_recursive fk(tree);
  KDL::JntArray jq(n);
  jq.data = q;
  const std::vector<PathChain> paths = pathChains(tree, s);
  const Matrix6X acc = accelerationsByDifferences(paths, q, qd, qdd, testutil::toVector(kGrav));
  double pose_err = 0.0, vel_err = 0.0, acc_err = 0.0, base_err = 0.0;
  for (unsigned int i = 0; i < ns; ++i) {
    KDL::Frame Fi, Fp = KDL::Frame::Identity();
    fk.JntToCart(jq, Fi, s.segmentNames()[i]);
    if (s.parent()[i] >= 0) fk.JntToCart(jq, Fp, s.segmentNames()[s.parent()[i]]);
    Eigen::Vector3d p_exp, p_got;
    const Eigen::Matrix3d R_exp = relative(Fp, Fi, p_exp);
    const Eigen::Matrix3d R_got = relative(KDL::Frame::Identity(), s.linkLocalPose(i), p_got);
    pose_err = std::max({pose_err, (R_got - R_exp).cwiseAbs().maxCoeff(), relErr(p_got, p_exp)});
    const Eigen::Matrix3d R = mat3(Fi.M);  // tip axes in base axes
    const KDL::FrameVel fv = tipVelocity(paths[i], q, qd);
    Vector6 v_exp;
    v_exp << R.transpose() * vec(fv.p.v), R.transpose() * vec(fv.M.w);
    vel_err = std::max(vel_err, relErr(twist6(s.linkLocalVelocity(i)), v_exp));
    Vector6 a_exp;
    a_exp << R.transpose() * acc.col(i).head<3>(), R.transpose() * acc.col(i).tail<3>();
    acc_err = std::max(acc_err, relErr(twist6(s.linkLocalAcceleration(i)), a_exp));
    base_err = std::max(base_err, relErr(s.linkAccelerations().col(i + 1), acc.col(i)));
  }
  CHECK_MESSAGE(pose_err <= 1e-12, "tree: linkLocalPose vs KDL TreeFkSolverPos_recursive err " << str(pose_err));
  CHECK_MESSAGE(vel_err <= 1e-12, "tree: linkLocalVelocity vs KDL ChainFkSolverVel_recursive rel err " << str(vel_err));
  CHECK_MESSAGE(acc_err <= 1e-7, "tree: linkLocalAcceleration vs KDL velocity differences rel err " << str(acc_err));
  CHECK_MESSAGE(base_err <= 1e-7, "tree: linkAccelerations vs KDL velocity differences rel err " << str(base_err));
}

TEST_CASE("tree: maxConstraints, link getters, setJointAccelerations and articulatedInertia") {
  testutil::RandomGen g(47);
  testutil::TreeSpec spec;
  spec.n_joints = 9;
  spec.rotor_inertia = false;  // KDL's TreeIdSolver_RNE has no rotors
  const KDL::Tree tree = testutil::randomTree(g, spec);
  vereshchagin::TreeHdSolver s(tree, kGrav);
  CHECK_MESSAGE(s.modelError() == 0, "tree: model " << std::string(s.errorMessage()));
  const unsigned int n = s.nrOfJoints(), ns = s.nrOfSegments();
  maxConstraintChecks(s, g, "tree");
  const Eigen::VectorXd q = g.q(n).data, qd = g.qdot(n).data, ff = g.torques(n).data;
  // The solve's own accelerations, then those of arbitrary qdd by setJointAccelerations().
  int rc = s.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), ff);
  CHECK_MESSAGE(rc == 0, "tree: solve " << std::string(s.errorMessage()));
  treeGetterChecks(tree, s, q, qd, s.qdd());
  const Eigen::VectorXd qdd = g.torques(n).data;
  CHECK_MESSAGE(s.setJointAccelerations(qdd.head(n - 1)) == HdSolver::E_SIZE_MISMATCH, "tree: wrong size accepted");
  CHECK_MESSAGE(s.setJointAccelerations(qdd) == 0, "tree: setJointAccelerations");
  treeGetterChecks(tree, s, q, qd, qdd);

  // H by columns of KDL's tree RNE (no gravity, no velocity): H e_k. TreeIdSolver_RNE keeps a
  // reference to its tree and uses its q_nr: a copy's are depth-first, the solver's joint order.
  const KDL::Tree copy = tree;
  KDL::TreeIdSolver_RNE rne(copy, KDL::Vector::Zero());
  KDL::JntArray jq(n), zero(n), unit(n), tau(n);
  jq.data = q;
  Eigen::MatrixXd H(n, n);
  for (unsigned int k = 0; k < n; ++k) {
    unit.data.setZero();
    unit(k) = 1.0;
    rne.CartToJnt(jq, zero, unit, KDL::WrenchMap(), tau);
    H.col(k) = tau.data;
  }
  CHECK_MESSAGE(s.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), ff) == 0, "tree: solve again");
  std::vector<int> joint_of(ns, -1);
  for (unsigned int i = 0, j = 0; i < ns; ++i) {
    const std::string& jn = tree.getSegment(s.segmentNames()[i])->second.segment.getJoint().getName();
    if (j < n && s.jointNames()[j] == jn) joint_of[i] = static_cast<int>(j++);
  }
  std::vector<std::vector<int>> moved(n);
  for (unsigned int i = 0; i < ns; ++i) {
    if (joint_of[i] < 0) continue;
    // Subtree of i: [i, end) in preorder, where end is the first later segment not below i.
    unsigned int end = i + 1;
    for (; end < ns; ++end) {
      int p = s.parent()[end];
      while (p > static_cast<int>(i)) p = s.parent()[p];
      if (p != static_cast<int>(i)) break;
    }
    for (unsigned int k = i; k < end; ++k)
      if (joint_of[k] >= 0) moved[joint_of[i]].push_back(joint_of[k]);
  }
  articulatedChecks(s, H, moved, "tree");
}

}  // namespace
