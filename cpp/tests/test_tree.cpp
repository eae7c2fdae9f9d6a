// TreeHdSolver on random KDL trees against KDL's tree solvers (TreeIdSolver_RNE,
// TreeJntToJacSolver, TreeFkSolverPos_recursive), and a chain given as a tree against
// ChainHdSolver. Tolerances 1e-9 relative for exact results; finite differences of twists 1e-6.
//
// Oracles: H(q) from RNE columns (unit accelerations, gravity 0, q_dot 0), the bias from RNE with
// zero accelerations; constrained accelerations from the KKT system of Gauss' principle with the
// stacked constraint Jacobians alfa^T J; command torques replayed through RNE; link accelerations
// against a finite difference of the segment twists J(q) q_dot along q(t) = q + t qd + t^2/2 qdd.
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl/treejnttojacsolver.hpp>

#include <doctest/doctest.h>
#include <Eigen/Dense>

#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"
#include "vereshchagin/tree_hd_solver.hpp"

namespace {

using testutil::relErr;
using testutil::str;
using vereshchagin::TreeHdSolver;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
const KDL::Twist kGravityUp(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());
constexpr double kTol = 1e-9;

// KDL's tree solvers on the same tree; joint vectors in the q_nr order of a copy of the tree, which
// KDL's tree solvers use (they keep a copy) and TreeHdSolver documents as its joint order.
struct Oracle {
  explicit Oracle(const KDL::Tree& t, const std::vector<std::string>& segment_names)
      : tree(t),
        names(segment_names),
        fk(tree),
        jac(tree),
        rne0(tree, KDL::Vector::Zero()),
        rneg(tree, KDL::Vector(0, 0, -9.81)),
        nj(tree.getNrOfJoints()) {}

  KDL::JntArray arr(const Eigen::VectorXd& v) const {
    KDL::JntArray a(nj);
    a.data = v;
    return a;
  }
  KDL::Frame pose(const Eigen::VectorXd& q, int segment) {
    KDL::Frame F;
    fk.JntToCart(arr(q), F, names[segment]);
    return F;
  }
  // f_ext (base axes, moment about the tip origin) -> KDL's per-segment wrenches in tip axes.
  KDL::WrenchMap wrenches(const Eigen::VectorXd& q, const Matrix6X& f_ext) {
    KDL::WrenchMap wm;
    for (int i = 0; i < f_ext.cols(); ++i) {
      const KDL::Rotation Rt = pose(q, i).M.Inverse();
      wm[names[i]] = KDL::Wrench(Rt * KDL::Vector(f_ext(0, i), f_ext(1, i), f_ext(2, i)),
                                 Rt * KDL::Vector(f_ext(3, i), f_ext(4, i), f_ext(5, i)));
    }
    return wm;
  }
  Eigen::VectorXd rne(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                      const Matrix6X& f_ext, bool gravity) {
    KDL::JntArray tau(nj);
    const KDL::WrenchMap wm = f_ext.cols() ? wrenches(q, f_ext) : KDL::WrenchMap();
    (gravity ? rneg : rne0).CartToJnt(arr(q), arr(qd), arr(qdd), wm, tau);
    return tau.data;
  }
  Eigen::MatrixXd massMatrix(const Eigen::VectorXd& q) {
    Eigen::MatrixXd H(nj, nj);
    const Eigen::VectorXd z = Eigen::VectorXd::Zero(nj);
    for (unsigned int k = 0; k < nj; ++k) H.col(k) = rne(q, z, Eigen::VectorXd::Unit(nj, k), Matrix6X(6, 0), false);
    return H;
  }
  // Jacobian of segment i's tip: base axes, reference point the tip origin (6 x nj).
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& q, int segment) {
    KDL::Jacobian J(nj);
    jac.JntToJac(arr(q), J, names[segment]);
    return J.data;
  }

  const KDL::Tree tree;  // a copy, as KDL's solvers keep: its q_nr are depth-first (the solver's order)
  std::vector<std::string> names;
  KDL::TreeFkSolverPos_recursive fk;
  KDL::TreeJntToJacSolver jac;
  KDL::TreeIdSolver_RNE rne0, rneg;
  unsigned int nj;
};

// A constraint layout: columns of alfa (unit norm) on segments.
struct Task {
  Matrix6X alfa;
  Eigen::VectorXd beta;
  Eigen::VectorXi segments;
};

// Moving joints on the path from segment i to the base.
int ancestorJoints(const TreeHdSolver& s, const KDL::Tree& tree, int i) {
  int n = 0;
  for (int k = i; k >= 0; k = s.parent()[k])
    n += tree.getSegment(s.segmentNames()[k])->second.segment.getJoint().getType() != KDL::Joint::Fixed;
  return n;
}

// kind 0: one leaf; 1: two leaves; 2: a leaf and an inner segment of another branch; 3: random
// segments, several per branch. Columns per segment at most its ancestor joints.
Task randomTask(testutil::RandomGen& g, const TreeHdSolver& s, const KDL::Tree& tree, int kind) {
  const int ns = static_cast<int>(s.nrOfSegments());
  std::vector<int> leaves, inner;
  for (int i = 0; i < ns; ++i) {
    if (ancestorJoints(s, tree, i) == 0) continue;
    bool leaf = true;
    for (int k = i + 1; k < ns; ++k) leaf = leaf && s.parent()[k] != i;
    (leaf ? leaves : inner).push_back(i);
  }
  std::vector<int> pick;
  const auto any = [&](const std::vector<int>& v) { return v[g.integer(0, static_cast<int>(v.size()) - 1)]; };
  if (!leaves.empty()) pick.push_back(any(leaves));
  if (kind == 1 && leaves.size() > 1) pick.push_back(any(leaves));
  if (kind == 2 && !inner.empty()) pick.push_back(any(inner));
  if (kind == 3)
    for (int k = 0; k < 3; ++k) pick.push_back(g.integer(0, ns - 1));
  std::sort(pick.begin(), pick.end());
  pick.erase(std::unique(pick.begin(), pick.end()), pick.end());  // at most 6 columns per segment
  std::vector<int> segs;
  for (int i : pick) {
    const int cols = std::min(g.integer(1, 6), ancestorJoints(s, tree, i));
    for (int c = 0; c < cols; ++c) segs.push_back(i);
  }
  Task t;
  const int m = static_cast<int>(segs.size());
  t.alfa = g.alfa(m).data;
  t.beta = g.beta(m).data;
  t.segments = Eigen::Map<const Eigen::VectorXi>(segs.data(), m);
  return t;
}

// Stacked A = alfa^T J (m x nj) and b = beta - alfa^T (root acceleration) at q_dot = 0.
void constraintRows(Oracle& o, const Eigen::VectorXd& q, const Task& t, Eigen::MatrixXd& A, Eigen::VectorXd& b) {
  const int m = static_cast<int>(t.segments.size());
  A.resize(m, o.nj);
  b.resize(m);
  Eigen::Matrix<double, 6, 1> up;
  up << 0, 0, 9.81, 0, 0, 0;
  for (int c = 0; c < m; ++c) {
    A.row(c) = t.alfa.col(c).transpose() * o.jacobian(q, t.segments(c));
    b(c) = t.beta(c) - t.alfa.col(c).dot(up);
  }
}

bool fullRowRank(const Eigen::MatrixXd& A) {
  if (A.rows() == 0) return true;
  if (A.rows() > A.cols()) return false;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  const auto& s = svd.singularValues();
  return s(s.size() - 1) > 1e-2 * s(0);  // well conditioned: the KKT oracle keeps 1e-9
}

// KKT of Gauss' principle: [H A^T; A 0] [qdd; l] = [tau - C; b] (extra rows: joint accelerations
// held at zero).
Eigen::VectorXd kkt(const Eigen::MatrixXd& H, const Eigen::VectorXd& rhs, const Eigen::MatrixXd& A,
                    const Eigen::VectorXd& b) {
  const long n = H.rows(), m = A.rows();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
  K.topLeftCorner(n, n) = H;
  K.topRightCorner(n, m) = A.transpose();
  K.bottomLeftCorner(m, n) = A;
  Eigen::VectorXd r(n + m);
  r << rhs, b;
  return K.fullPivLu().solve(r).head(n);
}

Eigen::VectorXd up6() {
  Eigen::VectorXd u(6);
  u << 0, 0, 9.81, 0, 0, 0;
  return u;
}

// One random tree (2..max_joints moving joints, drawn from `seed`), its solver and the oracle.
struct TreeCase {
  TreeCase(unsigned long long seed, int max_joints)
      : g(seed),
        tree(draw(g, max_joints)),
        s(tree, kGravityUp),
        o(tree, s.segmentNames()),
        nj(static_cast<int>(s.nrOfJoints())),
        ns(static_cast<int>(s.nrOfSegments())) {}
  static KDL::Tree draw(testutil::RandomGen& g, int max_joints) {
    testutil::TreeSpec spec;
    spec.n_joints = g.integer(2, max_joints);
    return testutil::randomTree(g, spec);
  }
  testutil::RandomGen g;
  KDL::Tree tree;
  TreeHdSolver s;
  Oracle o;
  int nj, ns;
};

TEST_CASE("forward dynamics (no constraint) replayed through TreeIdSolver_RNE") {
  double worst = 0.0;
  for (int seed = 0; seed < 60; ++seed) {
    TreeCase c(500 + seed, 40);
    auto& g = c.g;
    auto& s = c.s;
    auto& o = c.o;
    const int nj = c.nj;
    const int ns = c.ns;
    const Eigen::VectorXd q = g.q(nj).data, qd = g.qdot(nj).data, ff = g.torques(nj).data;
    const Matrix6X f_ext = testutil::toMatrix(g.fext(ns));
    const int rc = s.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(0), f_ext, ff);
    if (!CHECK_MESSAGE(rc == 0, "seed " << str(seed) << ": solve failed: " << s.errorMessage())) continue;
    const double e = relErr(o.rne(q, qd, s.qdd(), f_ext, true), ff);
    worst = std::max(worst, e);
    CHECK_MESSAGE(e < kTol,
                  "seed " << str(seed) << ": m = 0 qdd replayed through TreeIdSolver_RNE misses ff by " << str(e));
  }
  MESSAGE(testutil::format("m = 0 forward dynamics vs TreeIdSolver_RNE: worst %.2e", worst));
}

// inverseInertiaTimes after a solve (with and without constraints) against H from RNE columns:
// H out = tau; and its error codes.
TEST_CASE("inverseInertiaTimes against H from TreeIdSolver_RNE") {
  double worst = 0.0;
  for (int seed = 0; seed < 30; ++seed) {
    TreeCase c(900 + seed, 30);
    auto& g = c.g;
    auto& tree = c.tree;
    auto& s = c.s;
    auto& o = c.o;
    const int nj = c.nj;
    const Eigen::VectorXd q = g.q(nj).data, qd = g.qdot(nj).data, tau = g.torques(nj).data;
    Eigen::VectorXd out(nj);
    if (seed == 0) {
      CHECK_MESSAGE(s.inverseInertiaTimes(tau, out) == vereshchagin::HdSolver::E_NO_SOLUTION,
                    "inverseInertiaTimes before a solve");
      CHECK_MESSAGE(std::string(s.errorMessage()).find("needs a successful solve") != std::string::npos,
                    std::string("its message: ") << s.errorMessage());
    }
    const Task t = randomTask(g, s, tree, seed % 4);
    const Matrix6X none(6, 0);
    const int rc = seed % 2 ? s.solve(q, qd, t.alfa, t.beta, t.segments, none, Eigen::VectorXd(0))
                            : s.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(0), none, Eigen::VectorXd(0));
    if (!CHECK_MESSAGE(rc == 0, "seed " << str(seed) << ": solve failed: " << s.errorMessage())) continue;
    if (!CHECK_MESSAGE(s.inverseInertiaTimes(tau, out) == 0, "inverseInertiaTimes failed")) continue;
    const double e = relErr(o.massMatrix(q) * out, tau);
    worst = std::max(worst, e);
    CHECK_MESSAGE(e < kTol, "seed " << str(seed) << ": H (H^-1 tau) misses tau by " << str(e));
    Eigen::VectorXd short_out(std::max(nj - 1, 0));
    CHECK_MESSAGE(s.inverseInertiaTimes(tau, short_out) == vereshchagin::HdSolver::E_SIZE_MISMATCH,
                  "wrong out size is refused");
  }
  MESSAGE(testutil::format("inverseInertiaTimes vs H from TreeIdSolver_RNE: worst %.2e", worst));
}

// Constrained solves at q_dot = 0 against the KKT solution; command torques replayed through
// RNE and beta checked from the link accelerations (q_dot = 0 and q_dot != 0).
TEST_CASE("constraints on several branches against the KKT system") {
  double worst_kkt = 0.0, worst_tau = 0.0, worst_beta = 0.0, worst_sigma = 0.0;
  int tested = 0;
  for (int seed = 0; seed < 120; ++seed) {
    TreeCase c(2000 + seed, 40);
    auto& g = c.g;
    auto& tree = c.tree;
    auto& s = c.s;
    auto& o = c.o;
    const int nj = c.nj;
    const int ns = c.ns;
    const Task t = randomTask(g, s, tree, seed % 4);
    const Eigen::VectorXd q = g.q(nj).data, ff = g.torques(nj).data, zero = Eigen::VectorXd::Zero(nj);
    const Matrix6X f_ext = testutil::toMatrix(g.fext(ns));
    Eigen::MatrixXd A;
    Eigen::VectorXd b;
    constraintRows(o, q, t, A, b);
    if (!fullRowRank(A)) continue;
    ++tested;
    const std::string tag = "seed " + str(seed) + " (m = " + str(t.segments.size()) + ")";
    int rc = s.solve(q, zero, t.alfa, t.beta, t.segments, f_ext, ff);
    if (!CHECK_MESSAGE(rc == 0, tag << ": solve failed: " << s.errorMessage())) continue;
    const Eigen::VectorXd C = o.rne(q, zero, zero, f_ext, true);
    const Eigen::VectorXd qdd_kkt = kkt(o.massMatrix(q), ff - C, A, b);
    const double e_kkt = relErr(s.qdd(), qdd_kkt);
    CHECK_MESSAGE(e_kkt < kTol, tag << ": qdd differs from the KKT solution by " << str(e_kkt));
    worst_kkt = std::max(worst_kkt, e_kkt);
    // K = A H^-1 A^T: its smallest eigenvalue against Eigen's dense eigen-solver.
    const Eigen::MatrixXd K = A * o.massMatrix(q).ldlt().solve(A.transpose());
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(K, Eigen::EigenvaluesOnly).eigenvalues();
    const double e_sigma = std::abs(s.smallestSingularValue() - ev(0)) / ev(ev.size() - 1);
    CHECK_MESSAGE(e_sigma < kTol,
                  tag << ": smallestSingularValue " << str(s.smallestSingularValue()) << " vs " << str(ev(0)));
    worst_sigma = std::max(worst_sigma, e_sigma);
    for (int pass = 0; pass < 2; ++pass) {  // q_dot = 0, then q_dot != 0
      const Eigen::VectorXd qd = pass ? g.qdot(nj).data : zero;
      rc = s.solve(q, qd, t.alfa, t.beta, t.segments, f_ext, ff);
      if (!CHECK_MESSAGE(rc == 0, tag << ": solve failed: " << s.errorMessage())) continue;
      const double e_tau = relErr(o.rne(q, qd, s.qdd(), f_ext, true), ff + s.commandTorques());
      CHECK_MESSAGE(e_tau < kTol, tag << ": command torques replayed through RNE miss by " << str(e_tau));
      Eigen::VectorXd achieved(t.segments.size());
      for (int c = 0; c < t.segments.size(); ++c)
        achieved(c) = t.alfa.col(c).dot(s.linkAccelerations().col(t.segments(c) + 1));
      const double e_beta = relErr(achieved, t.beta);
      CHECK_MESSAGE(e_beta < kTol, tag << ": beta not met, by " << str(e_beta));
      worst_tau = std::max(worst_tau, e_tau);
      worst_beta = std::max(worst_beta, e_beta);
    }
  }
  CHECK_MESSAGE(tested >= 50, "only " << str(tested) << " constraint layouts of full rank");
  MESSAGE(testutil::format("constraints on branches (%d layouts): KKT %.2e, tau replay %.2e, beta %.2e, sigma_min %.2e",
                           tested, worst_kkt, worst_tau, worst_beta, worst_sigma));
}

// Link accelerations against d/dt of the segment twists J(q) q_dot: the spatial acceleration
// (base axes, tip origin) is [d/dt v - w x v; d/dt w] plus the base's.
TEST_CASE("link accelerations against finite differences of J(q) q_dot") {
  double worst = 0.0;
  for (int seed = 0; seed < 30; ++seed) {
    TreeCase c(7000 + seed, 25);
    auto& g = c.g;
    auto& tree = c.tree;
    auto& s = c.s;
    auto& o = c.o;
    const int nj = c.nj;
    const int ns = c.ns;
    const Task t = randomTask(g, s, tree, seed % 4);
    const Eigen::VectorXd q = g.q(nj).data, qd = g.qdot(nj).data, ff = g.torques(nj).data;
    if (s.solve(q, qd, t.alfa, t.beta, t.segments, Matrix6X(6, 0), ff) != 0) continue;
    const Eigen::VectorXd qdd = s.qdd();
    const double h = 1e-3;
    const auto twist = [&](double tt, int i) -> Eigen::VectorXd {
      const Eigen::VectorXd qt = q + tt * qd + 0.5 * tt * tt * qdd, qdt = qd + tt * qdd;
      return o.jacobian(qt, i) * qdt;
    };
    for (int i = 0; i < ns; ++i) {
      const Eigen::VectorXd V = twist(0.0, i);
      const Eigen::VectorXd dV =
          (8.0 * (twist(h, i) - twist(-h, i)) - (twist(2 * h, i) - twist(-2 * h, i))) / (12.0 * h);
      Eigen::VectorXd expect = dV + up6();
      expect.head(3) -= Eigen::Vector3d(V.tail(3)).cross(Eigen::Vector3d(V.head(3)));
      const double e = relErr(s.linkAccelerations().col(i + 1), expect);
      worst = std::max(worst, e);
      CHECK_MESSAGE(e < 1e-6,
                    "seed " << str(seed) << " segment " << str(i) << ": link acceleration vs d/dt twist " << str(e));
    }
  }
  MESSAGE(testutil::format("link accelerations vs finite differences of J(q) q_dot: worst %.2e", worst));
}

// Response columns against central differences in ff (exact: qdd, tau_cmd and nu are affine).
TEST_CASE("response columns against differences in ff_torques") {
  double worst = 0.0;
  for (int seed = 0; seed < 40; ++seed) {
    TreeCase c(9000 + seed, 30);
    auto& g = c.g;
    auto& tree = c.tree;
    auto& s = c.s;
    const int nj = c.nj;
    const Task t = randomTask(g, s, tree, seed % 4);
    const int m = static_cast<int>(t.segments.size());
    const Eigen::VectorXd q = g.q(nj).data, qd = g.qdot(nj).data, ff = g.torques(nj).data;
    Eigen::VectorXi joints(nj);  // all joints, shuffled half of the time
    for (int j = 0; j < nj; ++j) joints(j) = j;
    if (seed % 2) std::shuffle(joints.data(), joints.data() + nj, g.engine());
    Eigen::MatrixXd dqdd(nj, nj), dtau(nj, nj), dnu(m, nj);
    int rc = s.solve(q, qd, t.alfa, t.beta, t.segments, Matrix6X(6, 0), ff);
    if (rc == 0) rc = s.responseColumns(joints, dqdd, dtau, dnu);
    if (!CHECK_MESSAGE(rc == 0, "seed " << str(seed) << ": response columns rc " << str(rc) << " " << s.errorMessage()))
      continue;
    Eigen::MatrixXd fq(nj, nj), ft(nj, nj), fn(m, nj);
    for (int c = 0; c < nj; ++c) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(nj, joints(c));
      s.solve(q, qd, t.alfa, t.beta, t.segments, Matrix6X(6, 0), ff + e);
      const Eigen::VectorXd qp = s.qdd(), tp = s.commandTorques(), np = s.nu();
      s.solve(q, qd, t.alfa, t.beta, t.segments, Matrix6X(6, 0), ff - e);
      fq.col(c) = 0.5 * (qp - s.qdd());
      ft.col(c) = 0.5 * (tp - s.commandTorques());
      fn.col(c) = 0.5 * (np - s.nu());
    }
    const double e = std::max({relErr(dqdd, fq), relErr(dtau, ft), m ? relErr(dnu, fn) : 0.0});
    worst = std::max(worst, e);
    CHECK_MESSAGE(e < kTol, "seed " << str(seed) << ": response columns vs differences " << str(e));
    // More columns than joints (processed in chunks of n_joints): every joint twice.
    Eigen::VectorXi twice(2 * nj);
    twice << joints, joints;
    Eigen::MatrixXd dq2(nj, 2 * nj), dt2(nj, 2 * nj);
    s.solve(q, qd, t.alfa, t.beta, t.segments, Matrix6X(6, 0), ff);
    rc = s.responseColumns(twice, dq2, dt2);
    CHECK_MESSAGE((rc == 0 && relErr(dq2.leftCols(nj), dqdd) < kTol && relErr(dq2.rightCols(nj), dqdd) < kTol &&
                   relErr(dt2.rightCols(nj), dtau) < kTol),
                  "seed " << str(seed) << ": response columns in two chunks differ");
  }
  MESSAGE(testutil::format("response columns vs differences in ff: worst %.2e", worst));
}

// A chain given as a KDL::Tree gives ChainHdSolver's outputs (both solve() overloads, friction).
TEST_CASE("a chain given as a tree equals ChainHdSolver") {
  double worst = 0.0;
  for (int seed = 0; seed < 40; ++seed) {
    testutil::RandomGen g(300 + seed);
    testutil::ChainSpec spec;
    spec.n_joints = g.integer(1, 12);
    if (seed % 3 == 0) spec.fixed_before = {g.integer(0, spec.n_joints)};
    const KDL::Chain raw = g.chain(spec);
    KDL::Chain chain;  // unique segment names, as a tree needs
    for (unsigned int i = 0; i < raw.getNrOfSegments(); ++i) {
      const KDL::Segment& sg = raw.getSegment(i);
      chain.addSegment(KDL::Segment("c" + str(i), sg.getJoint(), sg.getFrameToTip(), sg.getInertia()));
    }
    KDL::Tree tree("base");
    tree.addChain(chain, "base");
    vereshchagin::ChainHdSolver cs(chain, kGravityUp);
    TreeHdSolver ts(tree, kGravityUp);
    const int nj = static_cast<int>(cs.nrOfJoints()), ns = static_cast<int>(cs.nrOfSegments());
    const Eigen::VectorXd q = g.q(nj).data, qd = g.qdot(nj).data, ff = g.torques(nj).data;
    const Matrix6X f_ext = testutil::toMatrix(g.fext(ns));
    const int m = seed % 7;
    const Matrix6X alfa = g.alfa(m).data;
    const Eigen::VectorXd beta = g.beta(m).data;
    Eigen::VectorXi segs(m);
    for (int c = 0; c < m; ++c) segs(c) = seed % 2 ? ns - 1 : g.integer(0, ns - 1);
    Eigen::VectorXi joints(nj);
    for (int j = 0; j < nj; ++j) joints(j) = j;
    Eigen::MatrixXd dq1(nj, nj), dt1(nj, nj), dq2(nj, nj), dt2(nj, nj);
    for (int overload = 0; overload < 2; ++overload) {
      const int rc1 = overload ? cs.solve(q, qd, alfa, beta, segs, f_ext, ff) : cs.solve(q, qd, alfa, beta, f_ext, ff);
      const int rc2 = overload ? ts.solve(q, qd, alfa, beta, segs, f_ext, ff) : ts.solve(q, qd, alfa, beta, f_ext, ff);
      if (!CHECK_MESSAGE((rc1 == 0 && rc2 == 0),
                         "seed " << str(seed) << ": " << cs.errorMessage() << ts.errorMessage()))
        continue;
      cs.responseColumns(joints, dq1, dt1);
      ts.responseColumns(joints, dq2, dt2);
      const double e =
          std::max({relErr(ts.qdd(), cs.qdd()), relErr(ts.commandTorques(), cs.commandTorques()),
                    m ? relErr(ts.nu(), cs.nu()) : 0.0, relErr(ts.linkAccelerations(), cs.linkAccelerations()),
                    relErr(dq2, dq1), relErr(dt2, dt1)});
      CHECK_MESSAGE(ts.constraintRank() == cs.constraintRank(), "seed " << str(seed) << ": ranks differ");
      CHECK_MESSAGE(e < kTol, "seed " << str(seed) << ": chain as tree differs from the chain by " << str(e));
      worst = std::max(worst, e);
    }
    vereshchagin::FrictionSolver fc(chain, kGravityUp), ft(tree, kGravityUp);
    vereshchagin::FrictionModel fm;
    fm.static_friction = Eigen::VectorXd::Constant(nj, g.uniform(0.5, 4.0));
    const Eigen::VectorXd rest = Eigen::VectorXd::Zero(nj);
    const int mf = std::min(m, nj);
    const int rc1 = fc.solve(q, rest, alfa.leftCols(mf), beta.head(mf), f_ext, ff, fm);
    const int rc2 = ft.solve(q, rest, alfa.leftCols(mf), beta.head(mf), f_ext, ff, fm);
    if (!CHECK_MESSAGE((rc1 == 0 && rc2 == 0),
                       "seed " << str(seed) << ": friction " << fc.errorMessage() << ft.errorMessage()))
      continue;
    const double e = std::max(relErr(ft.qdd(), fc.qdd()), relErr(ft.frictionTorques(), fc.frictionTorques()));
    CHECK_MESSAGE(e < kTol, "seed " << str(seed) << ": friction on the chain as tree differs by " << str(e));
    worst = std::max(worst, e);
  }
  MESSAGE(testutil::format("chain as tree vs ChainHdSolver: worst %.2e", worst));
}

// Static friction on trees: stick joints do not move and hold at most f; slipping joints get
// -f sign(qdd); the sticking set solved as a constrained problem (KKT with qdd_stick = 0 and the
// slipping joints' friction as torques) gives the same qdd; the solution replays through RNE.
TEST_CASE("friction on trees against stick/slip enumeration") {
  double worst = 0.0;
  int sticks = 0, slips = 0;
  for (int seed = 0; seed < 60; ++seed) {
    testutil::RandomGen g(11000 + seed);
    testutil::TreeSpec spec;
    spec.n_joints = g.integer(2, 20);
    const KDL::Tree tree = testutil::randomTree(g, spec);
    vereshchagin::FrictionSolver fs(tree, kGravityUp);
    const TreeHdSolver& s = static_cast<TreeHdSolver&>(fs.hdSolver());
    Oracle o(tree, s.segmentNames());
    const int nj = static_cast<int>(s.nrOfJoints());
    const Task t = randomTask(g, s, tree, seed % 4);
    const Eigen::VectorXd q = g.q(nj).data, ff = g.torques(nj).data, zero = Eigen::VectorXd::Zero(nj);
    Eigen::MatrixXd A;
    Eigen::VectorXd b;
    constraintRows(o, q, t, A, b);
    if (!fullRowRank(A) || A.rows() >= nj) continue;
    vereshchagin::FrictionModel fm;
    fm.static_friction = Eigen::VectorXd::Constant(nj, g.uniform(0.2, 6.0));
    const std::string tag = "seed " + str(seed);
    if (!CHECK_MESSAGE(fs.solve(q, zero, t.alfa, t.beta, t.segments, Matrix6X(6, 0), ff, fm) == 0,
                       tag << ": " << fs.errorMessage()))
      continue;
    const Eigen::VectorXd qdd = fs.qdd(), fr = fs.frictionTorques();
    const double qscale = std::max(1.0, qdd.cwiseAbs().maxCoeff());
    std::vector<int> stick;
    Eigen::VectorXd tau = ff;  // the slipping joints' friction as torques
    for (int j = 0; j < nj; ++j) {
      const double f = fm.static_friction(j);
      if (fs.status()[j] == vereshchagin::FrictionSolver::Stick) {
        stick.push_back(j);
        ++sticks;
        CHECK_MESSAGE(std::abs(qdd(j)) < kTol * qscale, tag << ": a sticking joint moves, qdd " << str(qdd(j)));
        CHECK_MESSAGE(std::abs(fr(j)) <= f * (1 + kTol), tag << ": stick friction beyond f");
      } else {
        ++slips;
        CHECK_MESSAGE(std::abs(fr(j) + f * (qdd(j) > 0 ? 1.0 : -1.0)) < kTol * f,
                      tag << ": slip friction is not -f sgn(qdd)");
        tau(j) += fr(j);
      }
    }
    Eigen::MatrixXd Aall(A.rows() + stick.size(), nj);
    Eigen::VectorXd ball(A.rows() + stick.size());
    Aall.topRows(A.rows()) = A;
    ball.head(A.rows()) = b;
    for (std::size_t k = 0; k < stick.size(); ++k) {
      Aall.row(A.rows() + k) = Eigen::RowVectorXd::Unit(nj, stick[k]);
      ball(A.rows() + k) = 0.0;
    }
    if (!fullRowRank(Aall)) continue;
    const Eigen::VectorXd C = o.rne(q, zero, zero, Matrix6X(6, 0), true);
    const double e_kkt = relErr(qdd, kkt(o.massMatrix(q), tau - C, Aall, ball));
    const double e_rne = relErr(o.rne(q, zero, qdd, Matrix6X(6, 0), true), ff + fs.commandTorques() + fr);
    CHECK_MESSAGE(e_kkt < kTol, tag << ": stick/slip enumeration differs by " << str(e_kkt));
    CHECK_MESSAGE(e_rne < kTol, tag << ": friction solution replayed through RNE misses by " << str(e_rne));
    worst = std::max({worst, e_kkt, e_rne});
  }
  CHECK_MESSAGE((sticks > 20 && slips > 20),
                "too few stick (" << str(sticks) << ") or slip (" << str(slips) << ") joints");
  MESSAGE(testutil::format("friction on trees (%d stick, %d slip joints): worst %.2e", sticks, slips, worst));
}

// Pass-through on trees: with f_ext weights 1, alfa_c^T Xdd = beta_c + a_fext,c, where a_fext is
// what f_ext alone gives the unconstrained tree at rest without gravity.
TEST_CASE("pass-through set-points on trees") {
  double worst = 0.0;
  for (int seed = 0; seed < 30; ++seed) {
    testutil::RandomGen g(13000 + seed);
    testutil::TreeSpec spec;
    spec.n_joints = g.integer(2, 25);
    const KDL::Tree tree = testutil::randomTree(g, spec);
    TreeHdSolver s(tree, kGravityUp), alone(tree, KDL::Twist::Zero());
    const int nj = static_cast<int>(s.nrOfJoints()), ns = static_cast<int>(s.nrOfSegments());
    const Task t = randomTask(g, s, tree, seed % 4);
    const int m = static_cast<int>(t.segments.size());
    const Eigen::VectorXd q = g.q(nj).data, qd = g.qdot(nj).data, ff = g.torques(nj).data;
    const Matrix6X f_ext = testutil::toMatrix(g.fext(ns));
    if (alone.solve(q, Eigen::VectorXd::Zero(nj), Matrix6X(6, 0), Eigen::VectorXd(0), f_ext, Eigen::VectorXd(0)) != 0)
      continue;
    Eigen::VectorXd a_fext(m), achieved(m);
    for (int c = 0; c < m; ++c) a_fext(c) = t.alfa.col(c).dot(alone.linkAccelerations().col(t.segments(c) + 1));
    s.setPassThrough(Eigen::VectorXd::Ones(m), Eigen::VectorXd(0));
    if (!CHECK_MESSAGE(s.solve(q, qd, t.alfa, t.beta, t.segments, f_ext, ff) == 0, s.errorMessage())) continue;
    if (s.constraintRank() < m) continue;  // a redundant layout cannot meet every set-point
    for (int c = 0; c < m; ++c) achieved(c) = t.alfa.col(c).dot(s.linkAccelerations().col(t.segments(c) + 1));
    const double e = relErr(achieved, t.beta + a_fext);
    worst = std::max(worst, e);
    CHECK_MESSAGE(e < kTol, "seed " << str(seed) << ": pass-through set-points missed by " << str(e));
  }
  MESSAGE(testutil::format("pass-through on trees: worst %.2e", worst));
}

// Names, order and error paths.
TEST_CASE("segment order, names, sub-trees and errors") {
  testutil::RandomGen g(42);
  testutil::TreeSpec spec;
  spec.n_joints = 12;
  const KDL::Tree tree = testutil::randomTree(g, spec);
  TreeHdSolver s(tree, kGravityUp);
  const KDL::Tree copy(tree);
  const int ns = static_cast<int>(s.nrOfSegments());
  CHECK_MESSAGE((s.modelError() == 0 && s.nrOfJoints() == tree.getNrOfJoints() && ns == (int)tree.getNrOfSegments()),
                "tree sizes");
  for (int i = 0; i < ns; ++i) {
    CHECK_MESSAGE(s.parent()[i] < i, "parent after child in the segment order");
    CHECK_MESSAGE(s.segmentIndex(s.segmentNames()[i]) == i, "segmentIndex");
    const auto& el = tree.getSegment(s.segmentNames()[i])->second;
    const std::string pname = el.parent->first;
    CHECK_MESSAGE(s.parent()[i] == s.segmentIndex(pname), "parent index does not name the KDL parent");
    const auto& el_copy = copy.getSegment(s.segmentNames()[i])->second;
    if (el.segment.getJoint().getType() != KDL::Joint::Fixed)
      CHECK_MESSAGE(s.jointNames()[el_copy.q_nr] == el.segment.getJoint().getName(),
                    "joint order is not q_nr of a copy");
  }
  CHECK_MESSAGE(s.segmentIndex("no such segment") == -1, "segmentIndex of an unknown name");
  const int nj = static_cast<int>(s.nrOfJoints());
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(nj);
  Eigen::VectorXi segs(1);
  segs << ns;
  Matrix6X alfa = g.alfa(7).data;
  int rc = s.solve(q, q, alfa.leftCols(1), Eigen::VectorXd::Zero(1), segs, Matrix6X(6, 0), Eigen::VectorXd(0));
  CHECK_MESSAGE(
      (rc == KDL::SolverI::E_OUT_OF_RANGE && std::string(s.errorMessage()).find("segments(0)") != std::string::npos),
      "segment index out of range: " << str(rc) << " " << s.errorMessage());
  Eigen::VectorXi seven = Eigen::VectorXi::Constant(7, ns - 1);
  rc = s.solve(q, q, alfa, Eigen::VectorXd::Zero(7), seven, Matrix6X(6, 0), Eigen::VectorXd(0));
  CHECK_MESSAGE(rc == TreeHdSolver::E_TOO_MANY_CONSTRAINTS, "7 columns on one segment: " << str(rc));
  rc = s.solve(q, q, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X::Zero(6, ns + 1), Eigen::VectorXd(0));
  CHECK_MESSAGE(rc == KDL::SolverI::E_SIZE_MISMATCH, "f_ext with a column too many: " << str(rc));

  TreeHdSolver unknown(tree, kGravityUp, vereshchagin::SolverOptions(), "nowhere");
  rc = unknown.solve(Eigen::VectorXd(0), Eigen::VectorXd(0), Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X(6, 0),
                     Eigen::VectorXd(0));
  CHECK_MESSAGE((unknown.modelError() == TreeHdSolver::E_INVALID_MODEL && rc == TreeHdSolver::E_INVALID_MODEL &&
                 std::string(unknown.errorMessage()).find("nowhere") != std::string::npos),
                std::string("unknown root: ") << unknown.errorMessage());
  TreeHdSolver empty(KDL::Tree("root"), kGravityUp);
  CHECK_MESSAGE((empty.modelError() == TreeHdSolver::E_INVALID_MODEL &&
                 std::string(empty.errorMessage()).find("no segments") != std::string::npos),
                std::string("empty tree: ") << empty.errorMessage());
  KDL::Tree bad = tree;
  bad.addSegment(KDL::Segment("heavy", KDL::Joint("jb", KDL::Joint::RotZ), KDL::Frame(),
                              KDL::RigidBodyInertia(-1.0, KDL::Vector::Zero(), KDL::RotationalInertia(1, 1, 1))),
                 "root");
  TreeHdSolver negative(bad, kGravityUp);
  CHECK_MESSAGE((negative.modelError() == TreeHdSolver::E_INVALID_MODEL &&
                 std::string(negative.errorMessage()).find("heavy") != std::string::npos),
                std::string("negative mass: ") << negative.errorMessage());

  // A sub-tree root: the segments below it only, in the same order, its joints renumbered from 0.
  const std::string sub = s.segmentNames()[0];
  TreeHdSolver part(tree, kGravityUp, vereshchagin::SolverOptions(), sub);
  int end = 1;  // segment 0's subtree is [0, end) in s
  while (end < ns && s.parent()[end] >= 0) ++end;
  CHECK_MESSAGE((part.modelError() == 0 && part.rootName() == sub), std::string("sub-tree root: ")
                                                                        << part.errorMessage());
  CHECK_MESSAGE(static_cast<int>(part.nrOfSegments()) == end - 1, "sub-tree segment count");
  for (int k = 0; k + 1 < end && k < static_cast<int>(part.nrOfSegments()); ++k)
    CHECK_MESSAGE(part.segmentNames()[k] == s.segmentNames()[k + 1], "sub-tree segment order");
}

}  // namespace
