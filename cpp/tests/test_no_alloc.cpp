// Real-time property: after construction, solve(), CartToJnt(), responseColumns() and Simulator steps allocate no
// heap memory, also on the contact stage's real-time fallback (a pivot bound reached). Every allocation function is
// replaced by a counting version (alloc_counter.hpp: operator new/delete and, on glibc, the malloc family, which Eigen
// uses). The test proves the counters work by allocating on purpose in a counted region.
#include <doctest/doctest.h>

#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <limits>
#include <memory>
#include <vector>

#include "alloc_counter.hpp"
#include "contact_fallback_case.hpp"
#include "floating_fixture.hpp"
#include "random_chain.hpp"
#include "random_tree.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/friction_solver.hpp"
#include "vereshchagin/kdl_compat.hpp"
#include "vereshchagin/kinematics.hpp"
#include "vereshchagin/momentum.hpp"
#include "vereshchagin/simulator.hpp"
#include "vereshchagin/tree_hd_solver.hpp"

namespace {
void* volatile g_sink = nullptr;  // keeps the deliberate allocations observable

using Counts = testutil::AllocCounts;
using testutil::str;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// The allocations counted so far. Only differences between two calls matter, and no doctest
// macro runs between the two ends of a measured region: doctest's own allocations (its
// reporters, INFO and CHECK messages) fall outside every region.
Counts now() {
  return testutil::allocCounts();
}

vereshchagin::SolverOptions dampedLeastSquares() {
  vereshchagin::SolverOptions dls;
  dls.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
  return dls;
}

// Four supports with friction (mu 0.9) on the last two segments and on segments 3 and 2, their
// points and normals a little apart, for the redundant-contact tests.
void addFourSupports(vereshchagin::SolveInput& in, unsigned int ns) {
  const int segments[4] = {static_cast<int>(ns) - 1, static_cast<int>(ns) - 2, 3, 2};
  for (int k = 0; k < 4; ++k) {
    vereshchagin::PointContact pc;
    pc.segment = segments[k];
    pc.point = vereshchagin::Vector3(0.03 * (k % 2 ? 1 : -1), 0.02, -0.05);
    pc.normal = vereshchagin::Vector3(0.1 * k, -0.1, 1.0).normalized();
    pc.mu = 0.9;
    in.contacts.push_back(pc);
  }
}

// A random 7-joint chain, its solvers (truncated and damped policies) and every input and output
// of the measured calls, all prepared before counting.
struct Fixture {
  testutil::RandomGen g{777};
  const KDL::Chain chain = g.chain(7);
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
  const KDL::Twist grav{KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()};
  vereshchagin::ChainHdSolver solver{chain, grav};
  vereshchagin::ChainHdSolver solver_dls{chain, grav, dampedLeastSquares()};
  static constexpr int kSets = 8;
  std::vector<KDL::JntArray> q, qd, ff;
  std::vector<KDL::Wrenches> fext;
  std::vector<Matrix6X> fext_m;
  std::vector<KDL::Jacobian> alfa;
  std::vector<Matrix6X> alfa_m;
  std::vector<KDL::JntArray> beta;
  Eigen::VectorXi joints = Eigen::VectorXi(3);
  Eigen::MatrixXd dqdd = Eigen::MatrixXd(n, 3), dtau = Eigen::MatrixXd(n, 3);
  KDL::JntArray qdd = KDL::JntArray(n), tau = KDL::JntArray(n);
  const Eigen::VectorXd empty_tau = Eigen::VectorXd(0);
  const Matrix6X empty_fext = Matrix6X(6, 0);
  const Eigen::VectorXd bad_q = Eigen::VectorXd(n + 1);

  Fixture() {
    for (int i = 0; i < kSets; ++i) {
      q.push_back(g.q(n));
      qd.push_back(g.qdot(n));
      ff.push_back(g.torques(n));
      fext.push_back(g.fext(ns));
      fext_m.push_back(testutil::toMatrix(fext.back()));
    }
    for (int nc = 0; nc <= 6; ++nc) {
      alfa.push_back(g.alfa(nc));
      alfa_m.push_back(alfa.back().data);
      beta.push_back(g.beta(nc));
    }
    joints << 0, 3, 6;
  }
};

}  // namespace

TEST_CASE("the counters see operator new and (on glibc) malloc") {
  // Counting must work: a std::vector and an Eigen vector allocated on purpose are seen.
  const Counts c0 = now();
  auto* v = new std::vector<int>(100, 1);
  g_sink = v->data();
  delete v;
  const Counts c1 = now();
  CHECK_MESSAGE(c1.news - c0.news >= 2, "operator new replacement does not count (std::vector)");
  Eigen::VectorXd* e = new Eigen::VectorXd(Eigen::VectorXd::Ones(100));
  g_sink = e->data();
  delete e;
  const Counts c2 = now();
  if (VERESHCHAGIN_TEST_COUNT_MALLOC)
    CHECK_MESSAGE(c2.mallocs - c1.mallocs >= 2, "malloc interposition does not count (Eigen)");
  MESSAGE("malloc family counted too: " << (VERESHCHAGIN_TEST_COUNT_MALLOC ? "yes" : "no"));
}

TEST_CASE_FIXTURE(Fixture, "solve, CartToJnt and responseColumns do not allocate (both policies)") {
  int failures = 0;
  double checksum = 0.0;

  const Counts c0 = now();
  for (int it = 0; it < 1000; ++it) {
    const int s = it % kSets, nc = it % 7, nc2 = (it * 5 + 3) % 7;
    if (solver.solve(q[s].data, qd[s].data, alfa_m[nc], beta[nc].data, fext_m[s], ff[s].data) != 0) ++failures;
    if (solver.responseColumns(joints, dqdd, dtau) != 0) ++failures;
    checksum += solver.qdd()(0) + dqdd(1, 1) + solver.smallestSingularValue() + solver.constraintRank();
    if (solver.CartToJnt(q[s], qd[s], qdd, alfa[nc2], beta[nc2], fext[s], ff[s], tau) != 0) ++failures;
    if (solver.responseColumns(joints, dqdd, dtau) != 0) ++failures;
    checksum += qdd(0) + tau(0) + dtau(0, 0);
    if (solver.solve(q[s].data, qd[s].data, alfa_m[nc2], beta[nc2].data, empty_fext, empty_tau) != 0) ++failures;
    if (solver_dls.solve(q[s].data, qd[s].data, alfa_m[nc], beta[nc].data, fext_m[s], ff[s].data) != 0) ++failures;
    if (solver_dls.responseColumns(joints, dqdd, dtau) != 0) ++failures;
    checksum += solver_dls.qdd()(0) + solver_dls.smallestSingularValue();
  }
  const Counts c1 = now();
  CHECK_MESSAGE(failures == 0, "solver calls failed: " << str(failures));
  CHECK_MESSAGE(std::isfinite(checksum), "non-finite results");
  CHECK_MESSAGE(c1.news == c0.news, "operator new called " << str(c1.news - c0.news) << " times in 1000 iterations");
  CHECK_MESSAGE(c1.mallocs == c0.mallocs,
                "malloc family called " << str(c1.mallocs - c0.mallocs) << " times in 1000 iterations");
}

TEST_CASE_FIXTURE(Fixture, "error paths do not allocate") {
  int failures = 0;
  // Error paths (they format a message) do not allocate either.
  const Counts c2 = now();
  for (int it = 0; it < 100; ++it) {
    if (solver.solve(bad_q, qd[0].data, alfa_m[1], beta[1].data, fext_m[0], ff[0].data) == 0) ++failures;
  }
  const Counts c3 = now();
  CHECK_MESSAGE(failures == 0, "size-mismatched solve did not fail");
  CHECK_MESSAGE((c3.news == c2.news && c3.mallocs == c2.mallocs),
                "error path allocates: new " << str(c3.news - c2.news) << ", malloc " << str(c3.mallocs - c2.mallocs));
}

TEST_CASE_FIXTURE(Fixture, "allocations inside KDL (a shared library) are counted") {
  // The counters also see allocations made inside a shared library: KDL's solver allocates on
  // every CartToJnt with constraints (defect 4 of the KDL notes).
  KDL::ChainHdSolver_Vereshchagin kdl(chain, grav, 2);
  const Counts k0 = now();
  const int rc = kdl.CartToJnt(q[0], qd[0], qdd, alfa[2], beta[2], fext[0], ff[0], tau);
  const Counts k1 = now();
  CHECK_MESSAGE((rc == 0 && (k1.news - k0.news) + (k1.mallocs - k0.mallocs) > 0),
                "allocations inside KDL's CartToJnt were not counted");
}

TEST_CASE_FIXTURE(Fixture, "friction-aware solves do not allocate") {
  // Friction-aware solves: all joints at rest (k = 7 resting joints), some moving, nc 0..6, with
  // the Gauss value on request; also a singular task (the tie-break path) and DLS options.
  vereshchagin::FrictionSolver fsolver(chain, grav);
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::LinSpaced(n, 0.5, 3.0);
  fm.kinetic_friction = 0.5 * fm.static_friction;
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd mixed = Eigen::VectorXd::Zero(n);
  mixed(1) = 0.3;
  mixed(4) = -0.2;
  const Matrix6X full = Matrix6X::Identity(6, 6);
  const Eigen::VectorXd hold = (Eigen::VectorXd(6) << 0, 0, 9.81, 0, 0, 0).finished();
  double fsum = 0.0;
  int ffail = 0;
  // Warm-up outside the counted region (first use of every code path).
  fsolver.solve(q[0].data, rest, alfa_m[6], beta[6].data, fext_m[0], ff[0].data, fm);
  const Counts f0 = now();
  for (int it = 0; it < 1000; ++it) {
    const int s = it % kSets, nc = it % 7;
    if (fsolver.solve(q[s].data, rest, alfa_m[nc], beta[nc].data, fext_m[s], ff[s].data, fm) != 0) ++ffail;
    fsum += fsolver.qdd()(0) + fsolver.frictionTorques()(2) + fsolver.gaussValue() + fsolver.iterations();
    if (fsolver.solve(q[s].data, mixed, alfa_m[nc], beta[nc].data, empty_fext, empty_tau, fm) != 0) ++ffail;
    if (fsolver.solve(q[s].data, rest, full, hold, empty_fext, ff[s].data, fm) != 0) ++ffail;
    fsum += fsolver.commandTorques()(0) + fsolver.gaussValue();
    // A real-time bound of 1 iteration (the fallback when it is hit: E_DEGRADED, still a result).
    fm.max_iterations = 1;
    if (fsolver.solve(q[s].data, rest, alfa_m[nc], beta[nc].data, fext_m[s], ff[s].data, fm) < 0) ++ffail;
    fsum += fsolver.frictionTorques()(1) + fsolver.gaussValue();
    fm.max_iterations = -1;
  }
  const Counts f1 = now();
  CHECK_MESSAGE(ffail == 0, "friction solves failed: " << str(ffail) << " (" << fsolver.errorMessage() << ")");
  CHECK_MESSAGE(std::isfinite(fsum), "non-finite friction results");
  CHECK_MESSAGE((f1.news == f0.news && f1.mallocs == f0.mallocs),
                "friction-aware solves allocated: operator new " << str(f1.news - f0.news) << ", malloc "
                                                                 << str(f1.mallocs - f0.mallocs) << " in 4000 solves");
}

TEST_CASE_FIXTURE(Fixture, "constraints on several segments do not allocate") {
  // Constraints on several segments (general path: Cholesky and Jacobi factorisations, both
  // policies, response columns, friction on top), 1..18 columns on up to three segments.
  vereshchagin::FrictionSolver fsolver(chain, grav);
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::LinSpaced(n, 0.5, 3.0);
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(n);
  Matrix6X A(6, 18);
  for (int c = 0; c < 18; ++c) A.col(c) = alfa_m[6].col(c % 6);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(18, -1.0, 2.0);
  Eigen::VectorXi segs(18);
  for (int c = 0; c < 18; ++c) segs(c) = c < 6 ? 2 : (c < 12 ? static_cast<int>(ns) - 1 : 4);
  Eigen::MatrixXd dnu(18, 3);
  double gsum = 0.0;
  int gfail = 0;
  solver.solve(q[0].data, qd[0].data, A, b, segs, fext_m[0], ff[0].data);
  fsolver.solve(q[0].data, rest, A.leftCols(3), b.head(3), segs.head(3), fext_m[0], ff[0].data, fm);
  const Counts g0 = now();
  for (int it = 0; it < 500; ++it) {
    const int s = it % kSets, m = 1 + it % 18;
    if (solver.solve(q[s].data, qd[s].data, A.leftCols(m), b.head(m), segs.head(m), fext_m[s], ff[s].data) != 0)
      ++gfail;
    if (solver.responseColumns(joints, dqdd, dtau, dnu) != 0) ++gfail;
    gsum += solver.qdd()(0) + solver.nu()(0) + dnu(0, 0) + solver.smallestSingularValue();
    if (solver_dls.solve(q[s].data, qd[s].data, A.leftCols(m), b.head(m), segs.head(m), empty_fext, empty_tau) != 0)
      ++gfail;
    gsum += solver_dls.commandTorques()(1);
    const int mf = 1 + it % 7;  // at most n columns keeps the friction QP well posed
    if (fsolver.solve(q[s].data, rest, A.leftCols(mf), b.head(mf), segs.head(mf), fext_m[s], ff[s].data, fm) != 0)
      ++gfail;
    gsum += fsolver.qdd()(0) + fsolver.gaussValue();
  }
  const Counts g1 = now();
  CHECK_MESSAGE(gfail == 0, "segment-constraint solves failed: " << str(gfail) << " (" << solver.errorMessage() << " / "
                                                                 << fsolver.errorMessage() << ")");
  CHECK_MESSAGE(std::isfinite(gsum), "non-finite segment-constraint results");
  CHECK_MESSAGE((g1.news == g0.news && g1.mallocs == g0.mallocs), "segment-constraint solves allocated: operator new "
                                                                      << str(g1.news - g0.news) << ", malloc "
                                                                      << str(g1.mallocs - g0.mallocs));
}

TEST_CASE_FIXTURE(Fixture, "pass-through and the KDL drop-in class do not allocate") {
  // Driver pass-through (both paths, friction on top) and the KDL drop-in class (zero columns,
  // driver weights, every getter with outputs of the right size).
  vereshchagin::ChainHdSolver pt(chain, grav);
  vereshchagin::FrictionSolver fpt(chain, grav);
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::LinSpaced(n, 0.5, 3.0);
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd w3 = Eigen::VectorXd::LinSpaced(3, 0.0, 1.0), w6 = Eigen::VectorXd::LinSpaced(6, 1.0, 0.2);
  Eigen::VectorXi segs3(3);
  segs3 << 2, static_cast<int>(ns) - 1, 4;
  vereshchagin::kdl_compat::ChainHdSolver_Vereshchagin compat(chain, grav, 6);
  KDL::Jacobian alfa_zero = alfa[6];
  alfa_zero.data.col(2).setZero();
  alfa_zero.data.col(4).setZero();
  std::vector<KDL::Twist> tw(ns + 1), tw_n(ns);
  std::vector<KDL::Frame> fr(ns);
  Eigen::VectorXd nu6(6);
  KDL::JntArray total(n);
  CHECK_MESSAGE((pt.setPassThrough(w3, w3.reverse()) == 0 && fpt.setPassThrough(w3, w3) == 0 &&
                 compat.setDriverWeights(w6, w6.reverse()) == 0),
                "pass-through weights accepted");
  pt.solve(q[0].data, qd[0].data, alfa_m[3], beta[3].data, fext_m[0], ff[0].data);
  fpt.solve(q[0].data, rest, alfa_m[3], beta[3].data, fext_m[0], ff[0].data, fm);
  compat.CartToJnt(q[0], qd[0], qdd, alfa_zero, beta[6], fext[0], ff[0], tau);
  double psum = 0.0;
  int pfail = 0;
  const Counts p0 = now();
  for (int it = 0; it < 500; ++it) {
    const int s = it % kSets;
    if (pt.solve(q[s].data, qd[s].data, alfa_m[3], beta[3].data, fext_m[s], ff[s].data) != 0) ++pfail;
    psum += pt.qdd()(0) + pt.nu()(1);
    if (pt.solve(q[s].data, qd[s].data, alfa_m[3], beta[3].data, segs3, fext_m[s], ff[s].data) != 0) ++pfail;
    psum += pt.qdd()(1);
    if (fpt.solve(q[s].data, rest, alfa_m[3], beta[3].data, segs3, fext_m[s], ff[s].data, fm) != 0) ++pfail;
    psum += fpt.qdd()(2);
    if (compat.CartToJnt(q[s], qd[s], qdd, it % 2 ? alfa_zero : alfa[6], beta[6], fext[s], ff[s], tau) != 0) ++pfail;
    compat.getTransformedLinkAcceleration(tw);
    compat.getTotalTorque(total);
    compat.getContraintForceMagnitude(nu6);
    compat.getLinkCartesianPose(fr);
    compat.getLinkCartesianVelocity(tw_n);
    compat.getLinkAcceleration(tw_n);
    psum += qdd(0) + tw[ns].vel.z() + total(0) + nu6(5) + fr[1].p.x() + tw_n[2].rot.x();
  }
  const Counts p1 = now();
  CHECK_MESSAGE(pfail == 0, "pass-through / drop-in solves failed: " << str(pfail));
  CHECK_MESSAGE(std::isfinite(psum), "non-finite pass-through results");
  CHECK_MESSAGE((p1.news == p0.news && p1.mallocs == p0.mallocs),
                "pass-through / drop-in solves allocated: operator new " << str(p1.news - p0.news) << ", malloc "
                                                                         << str(p1.mallocs - p0.mallocs));
}

TEST_CASE_FIXTURE(Fixture, "tree solves do not allocate") {
  // Trees (random branching, fixed joints): forward dynamics, constraints on two branches with
  // the last-segment and segments overloads, pass-through, response columns (all joints and a
  // shuffled subset) and friction on top.
  testutil::RandomGen tg(77);
  testutil::TreeSpec spec;
  spec.n_joints = 12;
  const KDL::Tree tree = testutil::randomTree(tg, spec);
  vereshchagin::TreeHdSolver ts(tree, grav);
  vereshchagin::FrictionSolver tf(tree, grav);
  const int tn = static_cast<int>(ts.nrOfJoints()), tns = static_cast<int>(ts.nrOfSegments());
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::LinSpaced(tn, 0.5, 3.0);
  const Eigen::VectorXd tq = Eigen::VectorXd::LinSpaced(tn, -1.0, 1.2), tqd = Eigen::VectorXd::LinSpaced(tn, 0.3, -0.4);
  const Eigen::VectorXd tff = Eigen::VectorXd::LinSpaced(tn, -2.0, 2.0), trest = Eigen::VectorXd::Zero(tn);
  const Matrix6X tfe = Matrix6X::Constant(6, tns, 0.3);
  Eigen::VectorXi tsegs(9);  // the last segment and two others on other branches
  for (int c = 0; c < 9; ++c) tsegs(c) = c < 3 ? tns - 1 : (c < 6 ? tns / 2 : 1);
  Matrix6X tA(6, 9);
  for (int c = 0; c < 9; ++c) tA.col(c) = alfa_m[6].col(c % 6);
  const Eigen::VectorXd tb = Eigen::VectorXd::LinSpaced(9, -1.0, 1.0);
  Eigen::VectorXi tall(tn), tsome(3);
  for (int j = 0; j < tn; ++j) tall(j) = j;
  tsome << tn - 1, 0, tn / 2;
  Eigen::MatrixXd tdq(tn, tn), tdt(tn, tn), tdn(9, tn), tdq3(tn, 3), tdt3(tn, 3);
  const Eigen::VectorXd w9 = Eigen::VectorXd::LinSpaced(9, 0.0, 1.0), w9r = w9.reverse();
  ts.solve(tq, tqd, tA, tb, tsegs, tfe, tff);
  ts.responseColumns(tall, tdq, tdt, tdn);
  tf.solve(tq, trest, tA.leftCols(3), tb.head(3), tsegs.head(3), tfe, tff, fm);
  double tsum = 0.0;
  int tfail = 0;
  const Counts t0 = now();
  for (int it = 0; it < 300; ++it) {
    const int m = 1 + it % 9;
    if (ts.solve(tq, tqd, tA.leftCols(0), tb.head(0), tfe, tff) != 0) ++tfail;
    tsum += ts.qdd()(0) + ts.linkAccelerations()(2, tns);
    if (ts.solve(tq, tqd, tA.leftCols(it % 7), tb.head(it % 7), tfe, tff) != 0) ++tfail;
    if (ts.solve(tq, tqd, tA.leftCols(m), tb.head(m), tsegs.head(m), tfe, tff) != 0) ++tfail;
    if (ts.responseColumns(tall, tdq, tdt, tdn) != 0) ++tfail;
    if (ts.responseColumns(tsome, tdq3, tdt3) != 0) ++tfail;
    tsum += ts.commandTorques()(1) + tdq(0, 0) + tdq3(1, 1) + ts.smallestSingularValue();
    if (it % 3 == 0) {
      if (ts.setPassThrough(w9.head(m), w9r.head(m)) != 0) ++tfail;
      if (ts.solve(tq, tqd, tA.leftCols(m), tb.head(m), tsegs.head(m), tfe, tff) != 0) ++tfail;
      ts.clearPassThrough();
    }
    const int mf = 1 + it % 4;
    if (tf.solve(tq, trest, tA.leftCols(mf), tb.head(mf), tsegs.head(mf), tfe, tff, fm) != 0) ++tfail;
    tsum += tf.qdd()(0) + tf.gaussValue();
  }
  const Counts t1 = now();
  CHECK_MESSAGE(tfail == 0,
                "tree solves failed: " << str(tfail) << " (" << ts.errorMessage() << " / " << tf.errorMessage() << ")");
  CHECK_MESSAGE(std::isfinite(tsum), "non-finite tree results");
  CHECK_MESSAGE((t1.news == t0.news && t1.mallocs == t0.mallocs), "tree solves allocated: operator new "
                                                                      << str(t1.news - t0.news) << ", malloc "
                                                                      << str(t1.mallocs - t0.mallocs));

  // The (model, data, input) API on the same tree: blocks with points, classical set-points,
  // frame wrenches, pass-through weights, gravity, friction (workspace reserved), kinematics and the companions.
  const vereshchagin::Model model(tree);
  vereshchagin::Data data(model);
  data.reserveFriction();
  vereshchagin::SolveInput input(model, 4, 4);
  input.setState(vereshchagin::JointPositions(tq), vereshchagin::JointVelocities(tqd));
  input.f_ext = tfe;
  input.ff_torques = tff;
  const vereshchagin::FrameRef tool{tns - 1, KDL::Frame(KDL::Vector(0.1, -0.2, 0.05))};
  Eigen::MatrixXd jac(6, tn);
  Eigen::VectorXd tout(tn);
  int afail = 0;
  double asum = 0.0;
  const Counts a0 = now();
  for (int it = 0; it < 300; ++it) {
    input.clear();
    const int m = 1 + it % 6;
    if (!input.addConstraint(tool, tA.leftCols(m), tb.head(m)).ok()) ++afail;
    if (!input.addConstraint(1, tA.leftCols(2), tb.head(2), vereshchagin::Vector3(0.0, 0.1, 0.0)).ok()) ++afail;
    if (!input.addWrench(tool, vereshchagin::Vector6::Constant(0.5)).ok()) ++afail;
    input.constraints[0].ff_pass_through(0) = it % 2 ? 0.5 : 0.0;
    input.constraints[1].classical = it % 4 == 1;  // beta from a classical set-point in the sweep
    input.constraints[1].classical_acceleration(2) = 0.3;
    input.f_ext = tfe;
    input.friction = it % 3 == 0 ? &fm : nullptr;
    if (!vereshchagin::solve(model, data, input).ok()) ++afail;
    if (!data.frameJacobian(tool, jac).ok()) ++afail;
    if (!data.responseColumns(tsome, tdq3, tdt3).ok()) ++afail;
    if (!data.inverseInertiaTimes(tff, tout).ok()) ++afail;
    asum += data.qdd()(0) + data.linkAccelerations()(2, tns) + data.framePose(tool).p.x() +
            data.frameTwist(tool).rot.z() + jac(0, 0) + tdq3(0, 0) + tout(0) + data.smallestSingularValue();
    if (input.friction) asum += data.gaussValue();
  }
  const Counts a1 = now();
  CHECK_MESSAGE(afail == 0, "(model, data, input) solves failed: " << str(afail));
  CHECK_MESSAGE(std::isfinite(asum), "non-finite (model, data, input) results");
  CHECK_MESSAGE((a1.news == a0.news && a1.mallocs == a0.mallocs), "(model, data, input) solves allocated: operator new "
                                                                      << str(a1.news - a0.news) << ", malloc "
                                                                      << str(a1.mallocs - a0.mallocs));
}

TEST_CASE_FIXTURE(Fixture, "solves with contacts do not allocate once warm") {
  // Supports with and without friction, a force set-point with friction, at rest and moving (so
  // the sticking trial, the full complementarity problem and the separating and sliding paths all
  // run), with a task on the last segment, with and without joint friction. The first solve of each
  // size allocates the stage.
  const vereshchagin::Model model(chain);
  vereshchagin::Data data(model);
  vereshchagin::SolveInput in(model);
  in.constraints.reserve(4);
  const auto contact = [&](int segment, double mu, double force) {
    vereshchagin::PointContact pc;
    pc.segment = segment;
    pc.point = vereshchagin::Vector3(0.05, -0.02, 0.1);
    pc.normal = vereshchagin::Vector3(0.3, 0.2, 1.0).normalized();
    pc.mu = mu;
    pc.force = force;
    return pc;
  };
  const double support = std::numeric_limits<double>::quiet_NaN();
  in.contacts = {contact(static_cast<int>(ns) - 1, 0.8, support), contact(3, 0.0, support), contact(5, 0.5, 4.0),
                 contact(2, 0.6, support)};
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(n);
  // Moving states: each normal perpendicular to its point's velocity (touching, sliding).
  std::vector<std::vector<vereshchagin::Vector3>> sliding_normals(kSets);
  vereshchagin::KinematicsData kin(model);
  for (int s = 0; s < kSets; ++s) {
    REQUIRE(vereshchagin::forwardKinematics(model, kin, vereshchagin::JointPositions(q[s].data),
                                            vereshchagin::JointVelocities(qd[s].data)));
    for (const vereshchagin::PointContact& pc : in.contacts) {
      vereshchagin::Vector6 twist;
      const KDL::Frame at(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)));
      REQUIRE(vereshchagin::frameTwist(model, kin, vereshchagin::FrameRef{pc.segment, at}, twist));
      const vereshchagin::Vector3 v = twist.head<3>();
      sliding_normals[s].push_back(v.cross(vereshchagin::Vector3::UnitZ()).normalized());
    }
  }
  const std::vector<vereshchagin::PointContact> resting = in.contacts;
  double csum = 0.0;
  int cfail = 0;
  vereshchagin::FrictionModel fm;  // joint friction together with the contacts (every other solve)
  fm.static_friction = Eigen::VectorXd::Constant(n, 0.4);
  const auto run = [&](int s, bool moving, int columns, bool friction = false) {
    in.friction = friction ? &fm : nullptr;
    in.setState(vereshchagin::JointPositions(q[s].data), vereshchagin::JointVelocities(moving ? qd[s].data : rest));
    for (std::size_t c = 0; c < in.contacts.size(); ++c)
      in.contacts[c].normal = moving ? sliding_normals[s][c] : resting[c].normal;
    in.ff_torques = ff[s].data;
    in.constraints.clear();
    if (columns > 0 && !in.addConstraint(static_cast<int>(ns) - 2, alfa_m[columns], beta[columns].data)) ++cfail;
    const vereshchagin::Status st = vereshchagin::solve(model, data, in);
    if (!st && st.code() != vereshchagin::Error::NoContactSolution) ++cfail;
    if (st) csum += data.qdd()(0) + data.contactForces()(2, 0);
  };
  for (int s = 0; s < kSets; ++s)
    for (int columns = 0; columns <= 2; ++columns)
      for (const bool friction : {false, true}) run(s, s % 2 == 1, columns, friction);  // warm: every size once
  const Counts c0 = now();
  for (int it = 0; it < 300; ++it) run(it % kSets, it % 2 == 1, it % 3, it % 4 >= 2);
  const Counts c1 = now();
  CHECK_MESSAGE(cfail == 0, "contact solves failed: " << str(cfail));
  CHECK_MESSAGE(std::isfinite(csum), "non-finite contact results");
  CHECK_MESSAGE((c1.news == c0.news && c1.mallocs == c0.mallocs), "contact solves allocated: operator new "
                                                                      << str(c1.news - c0.news) << ", malloc "
                                                                      << str(c1.mallocs - c0.mallocs));
}

TEST_CASE_FIXTURE(Fixture, "redundant resting contacts (the least-effort guess) do not allocate once warm") {
  // Four supports with friction at rest and a task: twelve held directions on seven joints, so the
  // all-active guess factors a rank-deficient Delassus matrix and runs the least-effort programme
  // (both stages, the second through its dual) in A's null space; dropping a pulling support and
  // the general method run on the states where the guess fails.
  const vereshchagin::Model model(chain);
  vereshchagin::Data data(model);
  vereshchagin::SolveInput in(model);
  in.constraints.reserve(2);
  addFourSupports(in, ns);
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(n);
  double csum = 0.0;
  int cfail = 0;
  const auto run = [&](int s, int columns) {
    in.setState(vereshchagin::JointPositions(q[s].data), vereshchagin::JointVelocities(rest));
    in.ff_torques = ff[s].data;
    in.constraints.clear();
    if (columns > 0 && !in.addConstraint(static_cast<int>(ns) - 1, alfa_m[columns], beta[columns].data)) ++cfail;
    const vereshchagin::Status st = vereshchagin::solve(model, data, in);
    if (!st && st.code() != vereshchagin::Error::NoContactSolution) ++cfail;
    if (st) csum += data.qdd()(0) + data.contactForces()(2, 0);
  };
  for (int s = 0; s < kSets; ++s)
    for (int columns = 0; columns <= 2; ++columns) run(s, columns);  // warm: every size once
  const Counts c0 = now();
  for (int it = 0; it < 300; ++it) run(it % kSets, it % 3);
  const Counts c1 = now();
  CHECK_MESSAGE(cfail == 0, "contact solves failed: " << str(cfail));
  CHECK_MESSAGE(std::isfinite(csum), "non-finite contact results");
  CHECK_MESSAGE((c1.news == c0.news && c1.mallocs == c0.mallocs), "contact solves allocated: operator new "
                                                                      << str(c1.news - c0.news) << ", malloc "
                                                                      << str(c1.mallocs - c0.mallocs));
}

TEST_CASE_FIXTURE(Fixture, "redundant supports over a time step (the least-effort rule) do not allocate once warm") {
  // Four supports with friction, joint friction and a task, stepped at rest and moving: where the
  // supports and the sticking joints share the load the least-effort programme runs on the step's
  // problem (contact_effort.cpp), elsewhere the impulses are unique and it stops early.
  const vereshchagin::Model model(chain);
  vereshchagin::Data data(model);
  vereshchagin::SolveInput in(model);
  in.constraints.reserve(2);
  addFourSupports(in, ns);
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::LinSpaced(n, 3.0, 0.5);
  fm.kinetic_friction = 0.7 * fm.static_friction;
  in.friction = &fm;
  in.time_step = 1e-3;
  Eigen::VectorXd q_next(n), qd_next(n);
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(n);
  std::vector<Eigen::VectorXd> creeping;  // slow enough for friction to stop some joints within the step
  for (int s = 0; s < kSets; ++s) creeping.push_back(1e-3 * qd[s].data);
  double csum = 0.0;
  int cfail = 0;
  const auto run = [&](int s, int columns, bool moving) {
    in.setState(vereshchagin::JointPositions(q[s].data), vereshchagin::JointVelocities(moving ? creeping[s] : rest));
    in.ff_torques = ff[s].data;
    in.constraints.clear();
    if (columns > 0 && !in.addConstraint(static_cast<int>(ns) - 1, alfa_m[columns], beta[columns].data)) ++cfail;
    const vereshchagin::Status st = vereshchagin::step(model, data, in, q_next, qd_next);
    if (!st && st.code() != vereshchagin::Error::NoContactSolution) ++cfail;
    if (st) csum += q_next(0) + data.contactForces()(2, 0);
  };
  for (int s = 0; s < kSets; ++s)
    for (int columns = 0; columns <= 2; ++columns)
      for (const bool moving : {false, true}) run(s, columns, moving);  // warm: every size once
  const Counts c0 = now();
  for (int it = 0; it < 300; ++it) run(it % kSets, it % 3, it % 4 >= 2);
  const Counts c1 = now();
  CHECK_MESSAGE(cfail == 0, "steps failed: " << str(cfail));
  CHECK_MESSAGE(std::isfinite(csum), "non-finite step results");
  CHECK_MESSAGE((c1.news == c0.news && c1.mallocs == c0.mallocs), "steps allocated: operator new "
                                                                      << str(c1.news - c0.news) << ", malloc "
                                                                      << str(c1.mallocs - c0.mallocs));
}

TEST_CASE_FIXTURE(Fixture, "Simulator steps and rollouts with friction and contacts do not allocate once warm") {
  // A moving arm with joint friction, then with a support with friction under its last segment,
  // stepped one by one and by rollout() with a controller writing ff_torques; the first step of
  // each kind sizes the friction and contact stages. Both integrators.
  const vereshchagin::Model model(chain);
  for (const auto integrator : {vereshchagin::Integrator::SemiImplicitEuler, vereshchagin::Integrator::Symplectic}) {
    CAPTURE(static_cast<int>(integrator));
    vereshchagin::Simulator sim(model, 1e-3, integrator);
    sim.reserveFriction();
    vereshchagin::SolveInput in(model);
    vereshchagin::FrictionModel fm;
    fm.static_friction = Eigen::VectorXd::LinSpaced(n, 0.5, 3.0);
    fm.kinetic_friction = 0.5 * fm.static_friction;
    vereshchagin::PointContact pc;
    pc.segment = static_cast<int>(ns) - 1;
    pc.mu = 0.6;
    in.contacts.reserve(1);
    vereshchagin::RolloutRecord rec;
    rec.resize(static_cast<int>(n), 20, true, true, 1);
    const vereshchagin::Controller controller = [&](const Eigen::VectorXd& qs, const Eigen::VectorXd& qds, double,
                                                    vereshchagin::SolveInput& input) {
      input.ff_torques = -2.0 * qs - 0.1 * qds;
    };
    int sfail = 0;
    double ssum = 0.0;
    std::string last_error;
    const auto run = [&](int s, bool contact) {
      if (!sim.setState(vereshchagin::JointPositions(q[s].data), vereshchagin::JointVelocities(qd[s].data))) ++sfail;
      in.friction = &fm;
      in.contacts.clear();
      if (contact) in.contacts.push_back(pc);
      in.ff_torques = ff[s].data;
      for (int k = 0; k < 5; ++k) {
        const vereshchagin::Status st = sim.step(in);
        if (!st && st.code() != vereshchagin::Error::NoContactSolution) ++sfail, last_error = st.message();
      }
      rec.contact_force.resize(contact ? 3 : 0, contact ? 20 : 0);  // measured: always 3 x 20, no allocation
      const vereshchagin::Status st = sim.rollout(20, controller, in, rec);
      if (!st && st.code() != vereshchagin::Error::NoContactSolution) ++sfail, last_error = st.message();
      ssum += sim.q()(0) + sim.data().frictionTorques()(1);
    };
    for (int s = 0; s < kSets; ++s)
      for (const bool contact : {false, true}) run(s, contact);  // warm
    rec.contact_force.resize(3, 20);
    const Counts c0 = now();
    for (int it = 0; it < 40; ++it) run(it % kSets, true);
    const Counts c1 = now();
    CHECK_MESSAGE(sfail == 0, "Simulator steps failed: " << str(sfail) << " (" << last_error << ")");
    CHECK_MESSAGE(std::isfinite(ssum), "non-finite Simulator results");
    CHECK_MESSAGE((c1.news == c0.news && c1.mallocs == c0.mallocs), "Simulator steps allocated: operator new "
                                                                        << str(c1.news - c0.news) << ", malloc "
                                                                        << str(c1.mallocs - c0.mallocs));
  }
}

TEST_CASE("floating bases: solves, response columns, companions, steps and Simulator rollouts do not allocate") {
  // A free-flyer and a planar base under a random tree: solve with f_ext, a wrench on the base
  // (its rows of ff_torques) and constraints on two segments, response columns, the dynamics and
  // momentum companions, step(), stepSymplectic() and both integrators' Simulator steps and
  // rollouts with a controller; every state a little different from the last.
  for (const vereshchagin::BaseKind kind : {vereshchagin::BaseKind::FreeFlyer, vereshchagin::BaseKind::Planar}) {
    CAPTURE(static_cast<int>(kind));
    const vereshchagin::Model model = testutil::floatingTreeModel(kind, 31, 8);
    REQUIRE(model.status());
    const long nq = static_cast<long>(model.nq()), nv = static_cast<long>(model.nv());
    const int last = static_cast<int>(model.nrOfSegments()) - 1;
    vereshchagin::Data data(model);
    vereshchagin::DynamicsData dd(model);
    vereshchagin::SolveInput in(model, 2, 0);
    in.q = testutil::floatingConfiguration(model, -0.6, 0.7);
    in.q_dot = Eigen::VectorXd::LinSpaced(nv, 0.4, -0.3);
    in.ff_torques = Eigen::VectorXd::LinSpaced(nv, -1.0, 2.0);
    in.f_ext.setConstant(0.3);
    const Eigen::VectorXd beta = Eigen::VectorXd::LinSpaced(6, -1.0, 1.0);
    REQUIRE(in.addConstraint(last, Eigen::MatrixXd::Identity(6, 6), beta));
    REQUIRE(in.addConstraint(2, Eigen::MatrixXd::Identity(6, 3), beta.head(3)));
    const Eigen::VectorXi joints = Eigen::VectorXi::LinSpaced(3, 0, 2);
    Eigen::MatrixXd dqdd(nv, 3), dtau(nv, 3), H(nv, nv), Jc(3, nv);
    Eigen::VectorXd tau(nv), q_next(nq), qd_next(nv), p(nv), p_next(nv);
    Eigen::Vector3d com, com_vel;
    vereshchagin::Vector6 h;
    vereshchagin::Simulator euler(model, 1e-3, vereshchagin::Integrator::SemiImplicitEuler);
    vereshchagin::Simulator symplectic(model, 1e-3, vereshchagin::Integrator::Symplectic);
    vereshchagin::RolloutRecord rec;
    rec.resize(model, 10, true);
    const vereshchagin::Controller controller = [&](const Eigen::VectorXd&, const Eigen::VectorXd& qds, double,
                                                    vereshchagin::SolveInput& input) {
      input.ff_torques.tail(model.nrOfJoints()) = -0.1 * qds.tail(model.nrOfJoints());
    };
    int failed = 0;
    double sum = 0.0;
    const auto run = [&](int it) {
      in.q_dot(0) = 0.01 * it;
      in.time_step = 0.0;
      const vereshchagin::JointPositions q(in.q);
      const vereshchagin::JointVelocities qd(in.q_dot);
      failed += !vereshchagin::solve(model, data, in);
      failed += !data.responseColumns(joints, dqdd, dtau);
      sum += data.qdd()(0) + dqdd(0, 0);
      failed += !vereshchagin::massMatrix(model, dd, q, H);
      failed += !vereshchagin::inverseDynamics(model, dd, q, qd, vereshchagin::JointAccelerations(data.qdd()), in.f_ext,
                                               in.gravity, tau);
      failed += !vereshchagin::centerOfMass(model, dd, q, com);
      failed += !vereshchagin::centerOfMassJacobian(model, dd, q, Jc);
      failed += !vereshchagin::centerOfMassVelocity(model, dd, q, qd, com_vel);
      failed += !vereshchagin::centroidalMomentum(model, dd, q, qd, h);
      sum += H(0, 0) + tau(0) + com(0) + Jc(0, 0) + com_vel(0) + h(0);
      in.time_step = 1e-3;
      p.noalias() = H * in.q_dot;
      failed += !vereshchagin::step(model, data, in, q_next, qd_next);
      failed += !vereshchagin::stepSymplectic(model, data, in, p, q_next, qd_next, p_next);
      sum += q_next(0) + p_next(0);
      for (vereshchagin::Simulator* sim : {&euler, &symplectic}) {
        failed += !sim->setState(q, qd);
        failed += !sim->step(in);
        failed += !sim->rollout(10, controller, in, rec);
        sum += sim->q()(0);
      }
    };
    run(0);  // warm: the first symplectic step sizes its workspace
    const Counts c0 = now();
    for (int it = 1; it <= 20; ++it) run(it);
    const Counts c1 = now();
    CHECK_MESSAGE(failed == 0, "floating-base calls failed: " << str(failed));
    CHECK_MESSAGE(std::isfinite(sum), "non-finite floating-base results");
    CHECK_MESSAGE((c1.news == c0.news && c1.mallocs == c0.mallocs), "floating-base calls allocated: operator new "
                                                                        << str(c1.news - c0.news) << ", malloc "
                                                                        << str(c1.mallocs - c0.mallocs));
  }
}

TEST_CASE("the contact stage's real-time fallback (a pivot bound reached) does not allocate once warm") {
  // Random chains with 2-5 supports that carry and joint friction near breakaway (the cases of
  // test_contact_fallback.cpp), at the instant and over a step, with the pivot bound forced to 1 and
  // 3: the general complementarity problem reaches it and the solve returns Error::Degraded from the
  // held-normal fallback's sweeps. Each case is solved once before counting (its sizes), then again.
  testutil::RandomGen g(2714);
  std::vector<std::unique_ptr<testutil::Case>> cases;
  for (int t = 0; t < 24; ++t) {
    const int contacts = g.integer(2, 5), joints = g.integer(4, 8);  // (random_chain.hpp: draw order)
    cases.push_back(std::make_unique<testutil::Case>(g, joints, contacts, t % 2 ? 0.0 : 0.01));
  }
  std::vector<std::unique_ptr<vereshchagin::Data>> data;
  for (const auto& c : cases) data.push_back(std::make_unique<vereshchagin::Data>(c->model));
  int degraded = 0, failed = 0;
  double sum = 0.0;
  const auto run = [&](std::size_t k, int bound, double dt) {
    testutil::Case& c = *cases[k];
    c.in.contact_max_pivots = bound;
    c.in.time_step = dt;
    const vereshchagin::Status s = vereshchagin::solve(c.model, *data[k], c.in);
    degraded += s.code() == vereshchagin::Error::Degraded ? 1 : 0;
    failed += s ? 0 : 1;
    if (s) sum += data[k]->qdd()(0) + data[k]->contactForces()(2, 0);
  };
  const auto all = [&] {
    for (std::size_t k = 0; k < cases.size(); ++k)
      for (const double dt : {0.0, 1e-3})
        for (const int bound : {1, 3}) run(k, bound, dt);
  };
  all();  // warm: every case's sizes once
  degraded = failed = 0;
  const Counts c0 = now();
  all();
  const Counts c1 = now();
  CHECK_MESSAGE(degraded > 10, "too few fallbacks: " << str(degraded));
  CHECK_MESSAGE(std::isfinite(sum), "non-finite fallback results");
  CHECK_MESSAGE((c1.news == c0.news && c1.mallocs == c0.mallocs), "fallback solves allocated: operator new "
                                                                      << str(c1.news - c0.news) << ", malloc "
                                                                      << str(c1.mallocs - c0.mallocs));
  INFO("failed solves (problems without an answer, not this test's): " << failed);
}
