// Every call stands alone (issue 23): what one call leaves must not change what another returns.
//  * Argument shapes: alfa and f_ext of every solve() overload (HdSolver on a chain and on a tree,
//    FrictionSolver on both) are checked for 6 rows: a 3-row MatrixXd gives E_SIZE_MISMATCH naming
//    the argument and its size (it used to be read past its end). 6-row MatrixXd arguments, blocks
//    with an outer stride and empty (0 x 0) matrices give bit for bit the results of Matrix6X ones.
//  * errorMessage() is emptied by a successful solve after a failed one.
//  * One solver used from two threads: every call returns the single-thread result bit for bit or
//    E_CONCURRENT_CALL, never another error or a wrong result; with the entry flag held (as by a
//    call in progress) every mutating method returns E_CONCURRENT_CALL and changes nothing.
//  * A diverged state (prismatic joints at |q| ~ 1e92) fails with E_STATE_OUT_OF_RANGE and a
//    message saying so, not "zero articulated inertia" blaming the model.
//  * A link inertia of 1e300 does not make the other joints' inertias look like zero: the solve
//    succeeds and KDL's recursive Newton-Euler (ChainIdSolver_RNE) reproduces the torques.
#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include <doctest/doctest.h>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>

#include "../src/hd_core.hpp"
#include "random_chain.hpp"
#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"
#include "vereshchagin/tree_hd_solver.hpp"

using testutil::relErr;
using testutil::str;
using Matrix6X = vereshchagin::HdSolver::Matrix6X;
using vereshchagin::HdSolver;

namespace {

const KDL::Twist kGrav(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());

bool contains(const char* text, const std::string& part) {
  return std::string(text).find(part) != std::string::npos;
}

// The entry flag of any HdSolver (a protected member reached through a member pointer).
struct Access : HdSolver {
  static std::atomic<bool>& busy(HdSolver& s) {
    using Core = vereshchagin::detail::HdCore& (HdSolver::*)();
    return (s.*static_cast<Core>(&Access::core))().busy;
  }
};

using Inputs = testutil::SolveInputs;

// testutil::randomInputs with the columns on random segments.
Inputs randomSegmentInputs(testutil::RandomGen& g, unsigned int n, unsigned int ns, int nc) {
  Inputs in = testutil::randomInputs(g, n, ns, nc);
  in.segments.resize(nc);
  for (int c = 0; c < nc; ++c) in.segments(c) = g.integer(0, static_cast<int>(ns) - 1);
  return in;
}

// Row checks and layouts of one HdSolver, both overloads.
void shapeChecksHd(HdSolver& s, const Inputs& in, const std::string& tag) {
  const unsigned int ns = s.nrOfSegments();
  const Eigen::MatrixXd alfa3 = in.alfa.topRows(3), fext3 = in.fext.topRows(3);
  for (int overload = 0; overload < 2; ++overload) {
    const std::string t = tag + (overload ? " (segments)" : " (last)");
    auto run = [&](const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& f) {
      return overload ? s.solve(in.q, in.qd, a, in.beta, in.segments, f, in.ff)
                      : s.solve(in.q, in.qd, a, in.beta, f, in.ff);
    };
    int rc = run(in.alfa, in.fext);
    CHECK_MESSAGE(rc == 0, t << ": reference solve failed: " << s.errorMessage());
    const Eigen::VectorXd qdd = s.qdd(), tau = s.commandTorques();
    rc = run(alfa3, in.fext);
    CHECK_MESSAGE((rc == HdSolver::E_SIZE_MISMATCH && contains(s.errorMessage(), "alfa is 3x" + str(in.alfa.cols()))),
                  t << ": 3-row alfa: rc " << str(rc) << " '" << s.errorMessage() << "'");
    rc = run(in.alfa, fext3);
    CHECK_MESSAGE((rc == HdSolver::E_SIZE_MISMATCH && contains(s.errorMessage(), "f_ext is 3x" + str(ns))),
                  t << ": 3-row f_ext: rc " << str(rc) << " '" << s.errorMessage() << "'");
    // The same data as MatrixXd, as 6-row blocks of taller matrices (outer stride 9), and empty.
    Eigen::MatrixXd tall_a = Eigen::MatrixXd::Constant(9, in.alfa.cols(), 7.0);
    Eigen::MatrixXd tall_f = Eigen::MatrixXd::Constant(9, ns, -7.0);
    tall_a.topRows(6) = in.alfa;
    tall_f.bottomRows(6) = in.fext;
    rc = run(Eigen::MatrixXd(in.alfa), Eigen::MatrixXd(in.fext));
    CHECK_MESSAGE((rc == 0 && s.qdd() == qdd && s.commandTorques() == tau), t << ": MatrixXd arguments differ");
    rc = run(tall_a.topRows(6), tall_f.bottomRows(6));
    CHECK_MESSAGE((rc == 0 && s.qdd() == qdd && s.commandTorques() == tau),
                  t << ": strided blocks differ (rc " << str(rc) << ")");
    rc = run(in.alfa, Matrix6X(6, 0));
    const Eigen::VectorXd qdd_nof = s.qdd();
    CHECK_MESSAGE((rc == 0 && run(in.alfa, Eigen::MatrixXd()) == 0 && s.qdd() == qdd_nof),
                  t << ": empty f_ext 0x0 vs 6x0");
  }
}

void shapeChecksFriction(vereshchagin::FrictionSolver& s, const Inputs& in, const std::string& tag) {
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::Constant(in.q.size(), 0.5);
  Eigen::VectorXd qd = in.qd;
  qd(0) = 0.0;  // one joint at rest: the max-min runs
  const Eigen::MatrixXd alfa3 = in.alfa.topRows(3), fext3 = in.fext.topRows(3);
  for (int overload = 0; overload < 2; ++overload) {
    const std::string t = tag + (overload ? " (segments)" : " (last)");
    auto run = [&](const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& f) {
      return overload ? s.solve(in.q, qd, a, in.beta, in.segments, f, in.ff, fm)
                      : s.solve(in.q, qd, a, in.beta, f, in.ff, fm);
    };
    int rc = run(in.alfa, in.fext);
    CHECK_MESSAGE(rc == 0, t << ": reference solve failed: " << s.errorMessage());
    const Eigen::VectorXd qdd = s.qdd();
    rc = run(alfa3, in.fext);
    CHECK_MESSAGE((rc == HdSolver::E_SIZE_MISMATCH && contains(s.errorMessage(), "alfa is 3x")),
                  t << ": 3-row alfa: rc " << str(rc) << " '" << s.errorMessage() << "'");
    rc = run(in.alfa, fext3);
    CHECK_MESSAGE((rc == HdSolver::E_SIZE_MISMATCH && contains(s.errorMessage(), "f_ext is 3x")),
                  t << ": 3-row f_ext: rc " << str(rc) << " '" << s.errorMessage() << "'");
    Eigen::MatrixXd tall_a = Eigen::MatrixXd::Zero(8, in.alfa.cols());
    tall_a.bottomRows(6) = in.alfa;
    rc = run(tall_a.bottomRows(6), Eigen::MatrixXd(in.fext));
    CHECK_MESSAGE((rc == 0 && s.qdd() == qdd), t << ": strided alfa / MatrixXd f_ext differ (rc " << str(rc) << ")");
    // A failed solve, then a good one: the message is emptied.
    rc = s.solve(in.q.head(1), qd, in.alfa, in.beta, in.fext, in.ff, fm);
    CHECK_MESSAGE((rc != 0 && std::string(s.errorMessage()).size() > 0), t << ": bad q accepted");
    CHECK_MESSAGE((run(in.alfa, in.fext) == 0 && std::string(s.errorMessage()).empty()),
                  t << ": message kept after a successful solve: '" << s.errorMessage() << "'");
  }
}

TEST_CASE("argument shapes, strided and empty matrices, and errorMessage() after a good solve") {
  testutil::RandomGen g(2323);
  testutil::ChainSpec spec;
  spec.n_joints = 6;
  spec.fixed_before = {2};
  const KDL::Chain chain = g.chain(spec);
  testutil::TreeSpec tspec;
  tspec.n_joints = 9;
  const KDL::Tree tree = testutil::randomTree(g, tspec);
  vereshchagin::ChainHdSolver chain_solver(chain, kGrav);
  vereshchagin::TreeHdSolver tree_solver(tree, kGrav);
  vereshchagin::FrictionSolver chain_friction(chain, kGrav), tree_friction(tree, kGrav);
  const Inputs cin = randomSegmentInputs(g, chain_solver.nrOfJoints(), chain_solver.nrOfSegments(), 3);
  const Inputs tin = randomSegmentInputs(g, tree_solver.nrOfJoints(), tree_solver.nrOfSegments(), 3);
  shapeChecksHd(chain_solver, cin, "chain");
  shapeChecksHd(tree_solver, tin, "tree");
  shapeChecksFriction(chain_friction, cin, "friction chain");
  shapeChecksFriction(tree_friction, tin, "friction tree");
  for (HdSolver* s : {static_cast<HdSolver*>(&chain_solver), static_cast<HdSolver*>(&tree_solver)}) {
    const Inputs& in = s == &chain_solver ? cin : tin;
    int rc = s->solve(in.q, in.qd.head(1), in.alfa, in.beta, in.fext, in.ff);
    CHECK_MESSAGE((rc == HdSolver::E_SIZE_MISMATCH && contains(s->errorMessage(), "q_dot")), "bad q_dot accepted");
    rc = s->solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff);
    CHECK_MESSAGE((rc == 0 && std::string(s->errorMessage()).empty()),
                  "HdSolver: message kept after a successful solve: '" << std::string(s->errorMessage()) << "'");
    Eigen::VectorXd wrong(1);
    CHECK_MESSAGE((s->setJointAccelerations(wrong) == HdSolver::E_SIZE_MISMATCH && *s->errorMessage() != '\0' &&
                   s->setJointAccelerations(s->qdd()) == 0 && *s->errorMessage() == '\0'),
                  "setJointAccelerations: message not emptied by a successful call");
  }
}

// The flag held as by a call in progress: every mutating method refuses and changes nothing.
TEST_CASE("entry flag held: every mutating method refuses and changes nothing") {
  testutil::RandomGen g(99);
  const KDL::Chain chain = g.chain(5);
  vereshchagin::ChainHdSolver s(chain, kGrav);
  const Inputs in = randomSegmentInputs(g, 5, 5, 2);
  CHECK_MESSAGE(s.solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff) == 0, "held flag: reference solve");
  const Eigen::VectorXd qdd = s.qdd(), nu = s.nu();
  std::atomic<bool>& busy = Access::busy(s);
  busy.store(true);
  constexpr int C = HdSolver::E_CONCURRENT_CALL;
  const int n = 5;
  Eigen::VectorXd out(n), tau(n);
  Eigen::MatrixXd a(n, 1), b(n, 1), d(2, 1);
  Eigen::VectorXi j(1);
  j << 0;
  KDL::JntArray qa(n), qda(n), qdda(n), ffa(n), tca(n), beta(2);
  KDL::Jacobian alfa(2);
  const KDL::Wrenches w(5, KDL::Wrench::Zero());
  std::vector<int> rcs = {s.solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff),
                          s.solve(in.q, in.qd, in.alfa, in.beta, in.segments, in.fext, in.ff),
                          s.CartToJnt(qa, qda, qdda, alfa, beta, w, ffa, tca),
                          s.setJointAccelerations(Eigen::VectorXd::Zero(n)),
                          s.inverseInertiaTimes(Eigen::VectorXd::Ones(n), out),
                          s.responseColumns(j, a, b),
                          s.responseColumns(j, a, b, d),
                          s.commandTorquesOf(nu, tau),
                          s.setPassThrough(Eigen::VectorXd::Ones(2), Eigen::VectorXd()),
                          s.clearPassThrough(),
                          s.setRootAcceleration(KDL::Twist::Zero()),
                          s.setOptions(vereshchagin::SolverOptions())};
  for (std::size_t k = 0; k < rcs.size(); ++k)
    CHECK_MESSAGE(rcs[k] == C, "held flag: call " << str(k) << " returned " << str(rcs[k]));
  s.updateInternalDataStructures();  // refused: the model is marked stale
  busy.store(false);
  CHECK_MESSAGE((s.qdd() == qdd && s.nu() == nu && s.passThroughColumns() == -1), "held flag: results changed");
  int rc = s.solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff);
  CHECK_MESSAGE((rc == C && contains(s.errorMessage(), "updateInternalDataStructures")),
                "refused rebuild not reported: rc " << str(rc));
  s.updateInternalDataStructures();
  rc = s.solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff);
  CHECK_MESSAGE((rc == 0 && s.qdd() == qdd), "after the rebuild: rc " << str(rc) << " (root_acc kept, same results)");
  CHECK_MESSAGE(contains(s.strError(C), "one solver per thread"), "strError(E_CONCURRENT_CALL)");

  // FrictionSolver whose underlying solver is busy (used through hdSolver() by another thread).
  vereshchagin::FrictionSolver f(chain, kGrav);
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::Constant(n, 0.3);
  Access::busy(f.hdSolver()).store(true);
  rc = f.solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff, fm);
  Access::busy(f.hdSolver()).store(false);
  CHECK_MESSAGE((rc == C && contains(f.errorMessage(), "two threads")),
                "friction with busy hdSolver(): rc " << str(rc));
}

// Two threads on one solver: every call returns the single-thread result bit for bit or
// E_CONCURRENT_CALL (CartToJnt and responseColumns copy their results out inside the call).
TEST_CASE("two threads on one solver: exact results or E_CONCURRENT_CALL") {
  testutil::RandomGen g(7);
  const KDL::Chain chain = g.chain(12);
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
  constexpr int kInputs = 16;
  struct Case {
    KDL::JntArray q, qd, beta, ff, qdd, tau;
    KDL::Jacobian alfa;
    KDL::Wrenches fext;
  };
  std::vector<Case> cases(kInputs);
  vereshchagin::ChainHdSolver single(chain, kGrav), shared(chain, kGrav);
  for (Case& c : cases) {
    c.q = g.q(n);
    c.qd = g.qdot(n);
    c.ff = g.torques(n);
    c.alfa = g.alfa(3);
    c.beta = g.beta(3);
    c.fext = g.fext(ns);
    c.qdd = c.tau = KDL::JntArray(n);
    CHECK_MESSAGE(single.CartToJnt(c.q, c.qd, c.qdd, c.alfa, c.beta, c.fext, c.ff, c.tau) == 0, "thread reference");
  }
  std::atomic<long> ok{0}, refused{0}, wrong{0};
  // A refused call returns at once: each thread keeps calling until 20000 of its calls got in
  // (bounded, in case one never does), so that the two overlap at almost every call.
  auto hammer = [&](int offset) {
    KDL::JntArray qdd(n), tau(n);
    long entered = 0;
    for (long it = 0; entered < 20000 && it < 200000000; ++it) {
      const Case& c = cases[(it * 5 + offset) % kInputs];
      const int rc = shared.CartToJnt(c.q, c.qd, qdd, c.alfa, c.beta, c.fext, c.ff, tau);
      if (rc == HdSolver::E_CONCURRENT_CALL) {
        ++refused;
      } else if (rc == 0 && qdd.data == c.qdd.data && tau.data == c.tau.data) {
        ++ok;
        ++entered;
      } else {
        ++wrong;
        ++entered;
      }
    }
  };
  std::thread a(hammer, 0), b(hammer, 3);
  a.join();
  b.join();
  CHECK_MESSAGE(wrong == 0, "two threads: " << str(wrong.load()) << " wrong results or other errors (" << str(ok.load())
                                            << " exact, " << str(refused.load()) << " refused)");
  CHECK_MESSAGE(ok > 0, "two threads: no call succeeded");
  KDL::JntArray qdd(n), tau(n);
  const Case& c = cases[0];
  CHECK_MESSAGE((shared.CartToJnt(c.q, c.qd, qdd, c.alfa, c.beta, c.fext, c.ff, tau) == 0 && qdd.data == c.qdd.data),
                "two threads: the solver is not usable afterwards");
  MESSAGE("threads: " << ok.load() << " exact, " << refused.load() << " refused, " << wrong.load() << " wrong");
}

// Random 7-joint chains (revolute and prismatic joints) at |q| ~ 1e92 (a diverged simulation):
// in some of them round-off makes an articulated inertia negative (-1.4e168 in one), which joint
// is decided by round-off alone. Every such failure must be E_STATE_OUT_OF_RANGE saying so, never
// a model error, and it must occur in some chain (about 1 in 10 when written); every chain
// solves at a normal state.
TEST_CASE("a diverged state fails with E_STATE_OUT_OF_RANGE, not a model error") {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  int failed = 0;
  for (int seed = 0; seed < 40; ++seed) {
    testutil::RandomGen g(seed);
    const KDL::Chain chain = g.chain(7);
    vereshchagin::ChainHdSolver s(chain, kGrav);
    const Eigen::VectorXd q = g.q(7).data * (1e92 / 3);
    const int rc = s.solve(q, zero, Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), zero);
    if (rc != 0) {
      ++failed;
      CHECK_MESSAGE((rc == HdSolver::E_STATE_OUT_OF_RANGE && contains(s.errorMessage(), "state is out of range") &&
                     !contains(s.errorMessage(), "zero articulated inertia")),
                    "seed " << str(seed) << ", diverged state: rc " << str(rc) << " '" << s.errorMessage() << "'");
    }
    CHECK_MESSAGE(s.solve(q * 1e-92, zero, Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), zero) == 0,
                  "seed " << str(seed) << ", the same robot at a normal state: " << std::string(s.errorMessage()));
  }
  CHECK_MESSAGE(failed > 0, "no chain of 40 failed at |q| ~ 1e92: the diagnosis is not exercised");
  MESSAGE(str(failed) << " of 40 chains fail at |q| ~ 1e92");
}

// One link of rotational inertia 1e300 between light ones (axes X, Z, Y so that no joint's axis
// lies along a direction a child projected out).
TEST_CASE("a 1e300 link inertia between light links: KDL RNE reproduces the torques") {
  KDL::Chain chain;
  const KDL::Joint::JointType types[] = {KDL::Joint::RotX, KDL::Joint::RotZ, KDL::Joint::RotY};
  const double big = 1e300;
  for (int k = 0; k < 3; ++k) {
    const KDL::RotationalInertia I =
        k == 1 ? KDL::RotationalInertia(big, big, big) : KDL::RotationalInertia(0.02, 0.02, 0.01);
    chain.addSegment(KDL::Segment("s" + str(k), KDL::Joint("j" + str(k), types[k]),
                                  KDL::Frame(KDL::Vector(0, 0.1, 0.3)),
                                  KDL::RigidBodyInertia(1.0, KDL::Vector(0.05, 0.0, 0.1), I)));
  }
  vereshchagin::ChainHdSolver s(chain, kGrav);
  CHECK_MESSAGE(s.modelError() == 0, "1e300 inertia: model refused: " << std::string(s.errorMessage()));
  Eigen::VectorXd q(3), ff(3);
  q << 0.4, -0.7, 1.2;
  ff << 3.0, -2.0, 0.5;
  const int rc = s.solve(q, Eigen::VectorXd::Zero(3), Matrix6X(6, 0), Eigen::VectorXd(), Matrix6X(6, 0), ff);
  CHECK_MESSAGE(rc == 0, "1e300 inertia: rc " << str(rc) << " '" << s.errorMessage() << "'");
  if (rc != 0) return;
  // KDL's RNE (gravity with its physical sign) at the solved qdd gives back the applied torques.
  KDL::ChainIdSolver_RNE rne(chain, KDL::Vector(0, 0, -9.81));
  KDL::JntArray jq(3), jqd(3), jqdd(3), tau(3);
  jq.data = q;
  jqdd.data = s.qdd();
  const KDL::Wrenches none(3, KDL::Wrench::Zero());
  CHECK_MESSAGE(rne.CartToJnt(jq, jqd, jqdd, none, tau) == 0, "1e300 inertia: KDL RNE failed");
  const double e = relErr(tau.data, ff);
  CHECK_MESSAGE(e <= 1e-9, "1e300 inertia: RNE(qdd) vs applied torques rel err " << str(e));
}

}  // namespace
