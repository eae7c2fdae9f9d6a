// The drop-in class vereshchagin::kdl_compat::ChainHdSolver_Vereshchagin against Orocos KDL
// 1.5.1's KDL::ChainHdSolver_Vereshchagin. Every scenario is one function template written only
// with KDL's API and instantiated twice, once with KDL's class and once with ours (the type is the
// only change), on KDL's own test scenarios (written here from their description):
//  * the KUKA LWR 4 with identified parameters and rotor inertias (kuka_lwr4.hpp), a six-column
//    task with two zero columns, an external wrench on the end-effector and feed-forward torques:
//    the end-effector accelerations equal beta along the enabled columns, nu equals KDL's (and
//    KDL's published regression values), q_dotdot equals KDL's;
//  * the same arm with an all-zero alfa: q_dotdot equals KDL's forward dynamics (ChainFdSolver_RNE);
//  * random chains with a mix of zero and random columns.
// By default every output equals KDL's (constraint_torques: the felt torques -Z^T E nu;
// getTotalTorque: D_j q_dotdot_j), to 1e-10 relative, on the LWR task and random chains. With
// TorqueConvention::Command (ours): constraint_torques realise q_dotdot (KDL forward dynamics with
// ff + constraint_torques), getTotalTorque = ff + constraint_torques. Also ours: link poses and
// velocities against KDL's forward kinematics, setDriverWeights with weight 1 on ff torques
// against the dense formula (the task solved without ff, plus H^-1 ff), error codes, and
// E_NOT_UP_TO_DATE for a grown chain exactly when KDL returns it.
#include <string>
#include <type_traits>
#include <vector>

#include <doctest/doctest.h>
#include <Eigen/LU>
#include <Eigen/QR>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainfksolvervel_recursive.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <kdl/chainidsolver_vereshchagin.hpp>
#include <kdl/chainjnttojacdotsolver.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "kuka_lwr4.hpp"
#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/kdl_compat.hpp"

using testutil::relErr;
using testutil::str;
using Ours = vereshchagin::kdl_compat::ChainHdSolver_Vereshchagin;
using Theirs = KDL::ChainHdSolver_Vereshchagin;

namespace {

struct Scenario {
  KDL::Chain chain;
  KDL::Twist root_acc;
  KDL::JntArray q, qd, ff;
  KDL::Wrenches f_ext;
  KDL::Jacobian alfa;
  KDL::JntArray beta;
};

struct Outcome {
  int rc = 0;
  Eigen::VectorXd qdd, constraint_tau, total_tau, nu;
  std::vector<KDL::Twist> xdd;
};

// Written against KDL's API only: the same text for both classes.
template <class HdSolver>
Outcome run(const Scenario& s, bool command = false) {
  const unsigned int nj = s.chain.getNrOfJoints(), ns = s.chain.getNrOfSegments();
  HdSolver solver(s.chain, s.root_acc, s.alfa.columns());
  if constexpr (std::is_same<HdSolver, Ours>::value) {
    if (command) solver.setTorqueConvention(vereshchagin::kdl_compat::TorqueConvention::Command);
  }
  KDL::JntArray qdd(nj), constraint_tau(nj), total(nj);
  Outcome out;
  out.rc = solver.CartToJnt(s.q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, constraint_tau);
  out.xdd.resize(ns + 1);
  solver.getTransformedLinkAcceleration(out.xdd);
  solver.getTotalTorque(total);
  out.nu.resize(s.alfa.columns());
  solver.getContraintForceMagnitude(out.nu);
  out.qdd = qdd.data;
  out.constraint_tau = constraint_tau.data;
  out.total_tau = total.data;
  return out;
}

Eigen::Matrix<double, 6, 1> toVec(const KDL::Twist& t) {
  Eigen::Matrix<double, 6, 1> v;
  v << t.vel.x(), t.vel.y(), t.vel.z(), t.rot.x(), t.rot.y(), t.rot.z();
  return v;
}

// KDL's forward dynamics (RNE convention: gravity as gravity, f_ext in each tip's axes).
Eigen::VectorXd kdlForward(const Scenario& s, const Eigen::VectorXd& tau) {
  const unsigned int nj = s.chain.getNrOfJoints();
  KDL::ChainFdSolver_RNE fd(s.chain, -s.root_acc.vel);
  KDL::JntArray t(nj), qdd(nj);
  t.data = tau;
  const int rc = fd.CartToJnt(s.q, s.qd, t, testutil::toTipAxes(s.chain, s.q, s.f_ext), qdd);
  return rc == 0 ? qdd.data : Eigen::VectorXd::Constant(nj, NAN);
}

// KDL's Vereshchagin test 1 state on the LWR 4 (gravity as root acceleration 9.81 up).
Scenario lwrTask() {
  Scenario s;
  s.chain = testutil::kukaLwr4();
  const unsigned int n = 7;
  s.root_acc = KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());
  s.q.resize(n), s.qd.resize(n), s.ff.resize(n);
  const double q[7] = {1.6, 0.0, -1.6, -1.57, 0.0, 1.57, -0.8};
  const double qd[7] = {1.0, -2.0, 3.0, -4.0, 5.0, -6.0, 7.0};
  const double ff[7] = {5.0, 0.0, 0.0, 0.0, 0.0, -6.0, 0.0};
  for (unsigned int j = 0; j < n; ++j) s.q(j) = q[j], s.qd(j) = qd[j], s.ff(j) = ff[j];
  s.f_ext.assign(n, KDL::Wrench::Zero());
  s.f_ext[n - 1] = KDL::Wrench(KDL::Vector(10.0, 15.0, 0.0), KDL::Vector(0.0, 0.0, 5.0));  // base axes
  // Linear x, y, z and angular z constrained; angular x and y disabled (zero columns).
  s.alfa = KDL::Jacobian(6);
  KDL::SetToZero(s.alfa);
  s.alfa(0, 0) = s.alfa(1, 1) = s.alfa(2, 2) = s.alfa(5, 5) = 1.0;
  s.beta.resize(6);
  const double beta[6] = {-0.5, -0.5, 0.0, 0.0, 0.0, 0.2};
  for (int c = 0; c < 6; ++c) s.beta(c) = beta[c];
  return s;
}

// KDL's forward-dynamics consistency state on the LWR 4, with an all-zero six-column alfa.
Scenario lwrFree() {
  Scenario s = lwrTask();
  const double q[7] = {1.0, 0.0, 0.0, -1.57, 0.0, 1.57, -0.8};
  const double ff[7] = {50.0, -20.0, 10.0, 40.0, -60.0, 15.0, -10.0};
  for (int j = 0; j < 7; ++j) s.q(j) = q[j], s.ff(j) = ff[j];
  KDL::ChainFkSolverPos_recursive fk(s.chain);
  KDL::Frame tip;
  fk.JntToCart(s.q, tip);
  s.f_ext[6] = tip.M * KDL::Wrench(KDL::Vector(10.0, -20.0, 30.0), KDL::Vector(3.0, -4.0, 5.0));
  KDL::SetToZero(s.alfa);
  KDL::SetToZero(s.beta);
  return s;
}

TEST_CASE("KUKA LWR 4 task: nu, q_dotdot and torques equal KDL's and its published values") {
  const Scenario s = lwrTask();
  const Outcome kdl = run<Theirs>(s), ours = run<Ours>(s);
  CHECK_MESSAGE((kdl.rc == 0 && ours.rc == 0), "LWR task: return codes " << str(kdl.rc) << ", " << str(ours.rc));
  // End-effector accelerations along the enabled columns equal beta.
  const Eigen::Matrix<double, 6, 1> a_ours = toVec(ours.xdd[7]), a_kdl = toVec(kdl.xdd[7]);
  for (int c : {0, 1, 2, 5}) {
    CHECK_MESSAGE(std::abs(a_ours(c) - s.beta(c)) <= 1e-9,
                  "LWR task: ours Xdd(" << str(c) << ") = " << str(a_ours(c)) << " vs beta " << str(s.beta(c)));
    CHECK_MESSAGE(std::abs(a_kdl(c) - s.beta(c)) <= 1e-3, "LWR task: KDL Xdd(" << str(c) << ") = " << str(a_kdl(c)));
  }
  // nu equals KDL's, and KDL's published regression values (its tests' tolerance 1e-3).
  const double e_nu = relErr(ours.nu, kdl.nu), e_qdd = relErr(ours.qdd, kdl.qdd);
  CHECK_MESSAGE(e_nu <= 1e-6, "LWR task: nu vs KDL rel err " << str(e_nu) << " (ours " << testutil::mat(ours.nu)
                                                             << ", KDL " << testutil::mat(kdl.nu) << ")");
  CHECK_MESSAGE(e_qdd <= 1e-6, "LWR task: qdd vs KDL rel err " << str(e_qdd));
  const double published[6] = {669693.30355, 5930.60826, -639.5238, 0.0, 0.0, 573.90485};
  for (int c = 0; c < 6; ++c)
    CHECK_MESSAGE(
        std::abs(ours.nu(c) - published[c]) <= 1e-3 * std::max(1.0, std::abs(published[c])),
        "LWR task: nu(" << str(c) << ") = " << str(ours.nu(c)) << " vs KDL's published " << str(published[c]));
  CHECK_MESSAGE((ours.nu(3) == 0.0 && ours.nu(4) == 0.0), "LWR task: disabled columns have nu exactly 0");
  // Default: KDL's torques (felt torques; total = D_j qdd_j), and KDL's published total torques.
  const double e_ct = relErr(ours.constraint_tau, kdl.constraint_tau), e_tt = relErr(ours.total_tau, kdl.total_tau);
  CHECK_MESSAGE(e_ct <= 1e-10, "LWR task: constraint_torques vs KDL rel err " << str(e_ct));
  CHECK_MESSAGE(e_tt <= 1e-10, "LWR task: getTotalTorque vs KDL rel err " << str(e_tt) << " (ours "
                                                                          << testutil::mat(ours.total_tau) << ", KDL "
                                                                          << testutil::mat(kdl.total_tau) << ")");
  const double published_total[7] = {2013.3541, -6073.4999, 2227.4487, 56.87456, -11.3789, -6.05957, 569.0776};
  for (int j = 0; j < 7; ++j)
    CHECK_MESSAGE(std::abs(ours.total_tau(j) - published_total[j]) <= 1e-3,
                  "LWR task: total torque(" << str(j) << ") = " << str(ours.total_tau(j)) << " vs KDL's published "
                                            << str(published_total[j]));
  // TorqueConvention::Command: the torques realise q_dotdot; total torque = ff + constraint torques.
  const Outcome cmd = run<Ours>(s, /*command=*/true);
  const Eigen::VectorXd fd = kdlForward(s, s.ff.data + cmd.constraint_tau);
  const double e_fd = relErr(fd, cmd.qdd), e_kdl_fd = relErr(kdlForward(s, s.ff.data + kdl.constraint_tau), kdl.qdd);
  CHECK_MESSAGE((cmd.rc == 0 && cmd.qdd == ours.qdd && cmd.nu == ours.nu),
                "LWR task: the convention changes only torques");
  CHECK_MESSAGE(e_fd <= 1e-9, "LWR task: KDL FD with ff + our command torques rel err " << str(e_fd));
  CHECK_MESSAGE(e_kdl_fd > 1e-3, "LWR task: KDL's felt torques unexpectedly realise qdd (" << str(e_kdl_fd) << ")");
  CHECK_MESSAGE(cmd.total_tau == s.ff.data + cmd.constraint_tau,
                "LWR task: Command getTotalTorque != ff + constraint_torques");
  MESSAGE(
      testutil::format("LWR 4 task: |qdd - KDL| rel %.2e, |nu - KDL| rel %.2e, constraint_torques %.2e, total %.2e; FD "
                       "with command torques %.2e (with KDL's: %.2e)",
                       e_qdd, e_nu, e_ct, e_tt, e_fd, e_kdl_fd));
}

TEST_CASE("KUKA LWR 4 with an all-zero alfa: KDL forward dynamics") {
  const Scenario s = lwrFree();
  const Outcome kdl = run<Theirs>(s), ours = run<Ours>(s);
  const Eigen::VectorXd fd = kdlForward(s, s.ff.data);
  const double e_ours = relErr(ours.qdd, fd), e_kdl = relErr(kdl.qdd, fd);
  CHECK_MESSAGE((ours.rc == 0 && e_ours <= 1e-9), "LWR all-zero alfa: ours vs KDL FD rel err " << str(e_ours));
  CHECK_MESSAGE((kdl.rc == 0 && e_kdl <= 1e-9),
                "LWR all-zero alfa: KDL's Vereshchagin vs KDL FD rel err " << str(e_kdl));
  CHECK_MESSAGE((ours.constraint_tau.isZero(0.0) && ours.nu.isZero(0.0)),
                "LWR all-zero alfa: no constraint torques, nu = 0");
  MESSAGE(testutil::format("LWR 4 all-zero alfa: ours vs FD_RNE %.2e, KDL vs FD_RNE %.2e", e_ours, e_kdl));
}

// Random chains (no fixed joints: KDL needs n_joints = n_segments), zero and random columns.
TEST_CASE("random chains with zero and random columns equal KDL's") {
  double worst_qdd = 0.0, worst_nu = 0.0, worst_ct = 0.0, worst_tt = 0.0, worst_fd = 0.0;
  int compared = 0;
  for (int k = 0; k < 60; ++k) {
    testutil::RandomGen g(424242ULL + 31ULL * static_cast<unsigned long long>(k));
    Scenario s;
    const int n = g.integer(3, 9);
    s.chain = g.chain(n, /*allow_prismatic=*/true, /*rotor_inertia=*/true);
    s.root_acc = KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());
    s.q = g.q(n), s.qd = g.qdot(n), s.ff = g.torques(n);
    s.f_ext = g.fext(n);
    const int nc = g.integer(1, std::min(6, n));
    s.alfa = g.alfa(nc);
    s.beta = g.beta(nc);
    for (int c = 0; c < nc; ++c)
      if (g.coin(0.3)) s.alfa.data.col(c).setZero();
    const testutil::DenseModel d = testutil::denseModel(s.chain, s.q);
    Eigen::MatrixXd on(6, 0);
    for (int c = 0; c < nc; ++c)
      if (!s.alfa.data.col(c).isZero(0.0))
        on.conservativeResize(6, on.cols() + 1), on.rightCols(1) = s.alfa.data.col(c);
    if (!testutil::wellConditioned(testutil::couplingEigenvalues(d, on))) continue;
    const Outcome kdl = run<Theirs>(s), ours = run<Ours>(s);
    const std::string tag =
        "random " + str(k) + " (n=" + str(n) + ", nc=" + str(nc) + ", enabled " + str(on.cols()) + ")";
    CHECK_MESSAGE((kdl.rc == 0 && ours.rc == 0), tag << ": return codes");
    const double e_qdd = relErr(ours.qdd, kdl.qdd), e_nu = relErr(ours.nu, kdl.nu);
    const double e_ct = relErr(ours.constraint_tau, kdl.constraint_tau), e_tt = relErr(ours.total_tau, kdl.total_tau);
    CHECK_MESSAGE((e_qdd <= 1e-8 && e_nu <= 1e-8),
                  tag << ": vs KDL rel err qdd " << str(e_qdd) << ", nu " << str(e_nu));
    CHECK_MESSAGE((e_ct <= 1e-10 && e_tt <= 1e-10),
                  tag << ": vs KDL rel err constraint_torques " << str(e_ct) << ", total torque " << str(e_tt));
    const Outcome cmd = run<Ours>(s, /*command=*/true);
    const double e_fd = relErr(kdlForward(s, s.ff.data + cmd.constraint_tau), cmd.qdd);
    CHECK_MESSAGE(e_fd <= 1e-9, tag << ": Command torques: KDL FD rel err " << str(e_fd));
    worst_qdd = std::max(worst_qdd, e_qdd), worst_nu = std::max(worst_nu, e_nu);
    worst_ct = std::max(worst_ct, e_ct), worst_tt = std::max(worst_tt, e_tt), worst_fd = std::max(worst_fd, e_fd);
    ++compared;
  }
  CHECK_MESSAGE(compared >= 30, "random chains: too few compared (" << str(compared) << ")");
  MESSAGE(
      testutil::format("random chains: %d compared with KDL, worst rel err qdd %.2e, nu %.2e, constraint_torques %.2e, "
                       "total torque %.2e; Command torques through KDL FD %.2e",
                       compared, worst_qdd, worst_nu, worst_ct, worst_tt, worst_fd));
}

// Link getters (ours only: KDL 1.5.1 declares but does not define them) against KDL's FK.
TEST_CASE("link getters against KDL forward kinematics") {
  const Scenario s = lwrTask();
  Ours solver(s.chain, s.root_acc, 6);
  KDL::JntArray qdd(7), tc(7);
  CHECK_MESSAGE(solver.CartToJnt(s.q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, tc) == 0, "getters: solve");
  std::vector<KDL::Frame> pose_base, pose_local;
  std::vector<KDL::Twist> vel_base, vel_local, acc_base, acc_local, xdd;
  solver.getLinkCartesianPose(pose_base);
  solver.getLinkPose(pose_local);
  solver.getLinkCartesianVelocity(vel_base);
  solver.getLinkVelocity(vel_local);
  solver.getLinkCartesianAcceleration(acc_base);
  solver.getLinkAcceleration(acc_local);
  solver.getTransformedLinkAcceleration(xdd);
  KDL::ChainFkSolverPos_recursive fk(s.chain);
  KDL::ChainFkSolverVel_recursive fkv(s.chain);
  KDL::JntArrayVel qv(s.q, s.qd);
  double worst = 0.0;
  for (int i = 0; i < 7; ++i) {
    KDL::Frame F;
    KDL::FrameVel FV;
    fk.JntToCart(s.q, F, i + 1);
    fkv.JntToCart(qv, FV, i + 1);
    const KDL::Frame F_parent = i == 0 ? KDL::Frame::Identity() : pose_base[i - 1];
    worst = std::max({worst, relErr(toVec(FV.GetTwist()), toVec(vel_base[i])),
                      relErr(toVec(pose_base[i].M * vel_local[i]), toVec(vel_base[i])),
                      relErr(toVec(pose_base[i].M * acc_local[i]), toVec(acc_base[i])),
                      relErr(toVec(xdd[i + 1]), toVec(acc_base[i]))});
    CHECK_MESSAGE((KDL::Equal(F, pose_base[i], 1e-12) && KDL::Equal(F_parent * pose_local[i], F, 1e-12)),
                  "getters: pose of segment " << str(i));
  }
  CHECK_MESSAGE(worst <= 1e-12, "getters: velocities / accelerations inconsistent, worst " << str(worst));
}

// setDriverWeights: with weight 1 on the ff torques in every column the task is solved as if ff
// were absent and ff then acts unconstrained: nu unchanged, qdd + H^-1 ff.
TEST_CASE("setDriverWeights: weight 1 on ff torques against the dense formula") {
  Scenario s = lwrTask();
  s.alfa.data.col(3)(3) = 1.0;  // enable all six columns
  s.alfa.data.col(4)(4) = 1.0;
  Scenario no_ff = s;
  no_ff.ff.data.setZero();
  Ours passing(s.chain, s.root_acc, 6), plain(s.chain, s.root_acc, 6);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(6), one = Eigen::VectorXd::Ones(6);
  CHECK_MESSAGE(passing.setDriverWeights(zero, one) == 0, "setDriverWeights accepted");
  CHECK_MESSAGE(passing.setDriverWeights(zero, Eigen::VectorXd::Ones(5)) == Ours::E_SIZE_MISMATCH,
                "5 weights for nc = 6 refused");
  CHECK_MESSAGE(passing.setDriverWeights(zero, 2.0 * one) == Ours::E_OUT_OF_RANGE, "weight 2 refused");
  KDL::JntArray qdd(7), tc(7), qdd0(7), tc0(7);
  CHECK_MESSAGE((passing.CartToJnt(s.q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, tc) == 0 &&
                 plain.CartToJnt(no_ff.q, no_ff.qd, qdd0, no_ff.alfa, no_ff.beta, no_ff.f_ext, no_ff.ff, tc0) == 0),
                "driver weights: solves");
  Eigen::VectorXd nu(6), nu0(6);
  passing.getContraintForceMagnitude(nu);
  plain.getContraintForceMagnitude(nu0);
  const testutil::DenseModel d = testutil::denseModel(s.chain, s.q);
  const Eigen::VectorXd expect = qdd0.data + d.H.lu().solve(s.ff.data);
  const double e_qdd = relErr(qdd.data, expect), e_nu = relErr(nu, nu0);
  CHECK_MESSAGE((e_qdd <= 1e-9 && e_nu <= 1e-9),
                "ff passed through: qdd rel err " << str(e_qdd) << ", nu rel err " << str(e_nu));
  // Zero weights again: bit for bit KDL's behaviour of this class.
  Ours fresh(s.chain, s.root_acc, 6);
  KDL::JntArray qdd1(7), qdd2(7);
  passing.setDriverWeights(zero, zero);
  passing.CartToJnt(s.q, s.qd, qdd1, s.alfa, s.beta, s.f_ext, s.ff, tc);
  fresh.CartToJnt(s.q, s.qd, qdd2, s.alfa, s.beta, s.f_ext, s.ff, tc);
  CHECK_MESSAGE(qdd1.data == qdd2.data, "zero driver weights: not bit-identical to none");
}

TEST_CASE("error codes and a temporary chain") {
  const Scenario s = lwrTask();
  Ours solver(s.chain, s.root_acc, 6);
  KDL::JntArray qdd(7), tc(7), short_q(6);
  KDL::Jacobian five(5);
  CHECK_MESSAGE(solver.CartToJnt(short_q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, tc) == Ours::E_SIZE_MISMATCH,
                "q size");
  CHECK_MESSAGE(solver.CartToJnt(s.q, s.qd, qdd, five, s.beta, s.f_ext, s.ff, tc) == Ours::E_SIZE_MISMATCH,
                "alfa columns != nc");
  KDL::JntArray bad_q = s.q;
  bad_q(2) = NAN;
  CHECK_MESSAGE(solver.CartToJnt(bad_q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, tc) ==
                    vereshchagin::ChainHdSolver::E_NONFINITE_INPUT,
                "NaN q: E_NONFINITE_INPUT");
  // A temporary chain: ours copies it (KDL would keep a dangling reference).
  Ours from_temporary(testutil::kukaLwr4(), s.root_acc, 6);
  KDL::JntArray qdd2(7);
  CHECK_MESSAGE((from_temporary.CartToJnt(s.q, s.qd, qdd2, s.alfa, s.beta, s.f_ext, s.ff, tc) == 0 &&
                 solver.CartToJnt(s.q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, tc) == 0 && qdd.data == qdd2.data),
                "temporary chain");
  // A temporary chain is only copied: updateInternalDataStructures() keeps working on the copy.
  from_temporary.updateInternalDataStructures();
  CHECK_MESSAGE(
      (from_temporary.CartToJnt(s.q, s.qd, qdd2, s.alfa, s.beta, s.f_ext, s.ff, tc) == 0 && qdd.data == qdd2.data),
      "temporary chain: updateInternalDataStructures");
}

// The caller's chain grows by one segment: the return codes of a sequence of calls, and the
// accelerations after updateInternalDataStructures(). Written with KDL's API only.
struct Growth {
  std::vector<int> codes;
  Eigen::VectorXd qdd;
};

template <class HdSolver>
Growth growth() {
  Scenario s = lwrTask();
  HdSolver solver(s.chain, s.root_acc, 6);
  KDL::JntArray q8(8), qd8(8), qdd8(8), ff8(8), tc8(8), qdd(7), tc(7);
  for (int j = 0; j < 7; ++j) q8(j) = s.q(j), qd8(j) = s.qd(j), ff8(j) = s.ff(j);
  q8(7) = 0.3, qd8(7) = -0.7, ff8(7) = 0.5;
  KDL::Wrenches f8 = s.f_ext;
  f8.push_back(KDL::Wrench(KDL::Vector(1.0, -2.0, 3.0), KDL::Vector(0.1, 0.2, -0.3)));
  Growth g;
  g.codes.push_back(solver.CartToJnt(s.q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, tc));
  s.chain.addSegment(
      KDL::Segment("extra", KDL::Joint(KDL::Joint::RotZ), KDL::Frame(KDL::Vector(0, 0, 0.1)),
                   KDL::RigidBodyInertia(1.0, KDL::Vector(0, 0, 0.05), KDL::RotationalInertia(0.01, 0.01, 0.01))));
  g.codes.push_back(solver.CartToJnt(s.q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, tc));  // old sizes
  g.codes.push_back(solver.CartToJnt(q8, qd8, qdd8, s.alfa, s.beta, f8, ff8, tc8));        // new sizes
  solver.updateInternalDataStructures();
  g.codes.push_back(solver.CartToJnt(s.q, s.qd, qdd, s.alfa, s.beta, s.f_ext, s.ff, tc));  // old sizes
  g.codes.push_back(solver.CartToJnt(q8, qd8, qdd8, s.alfa, s.beta, f8, ff8, tc8));        // new sizes
  g.qdd = qdd8.data;
  return g;
}

TEST_CASE("a grown chain: E_NOT_UP_TO_DATE exactly when KDL returns it") {
  const Growth kdl = growth<Theirs>(), ours = growth<Ours>();
  CHECK_MESSAGE((kdl.codes == std::vector<int>{0, KDL::SolverI::E_NOT_UP_TO_DATE, KDL::SolverI::E_NOT_UP_TO_DATE,
                                               KDL::SolverI::E_SIZE_MISMATCH, 0}),
                "grown chain: KDL's return codes changed");
  std::string codes;
  for (std::size_t k = 0; k < ours.codes.size(); ++k) codes += str(ours.codes[k]) + "/" + str(kdl.codes[k]) + " ";
  CHECK_MESSAGE(ours.codes == kdl.codes, "grown chain: return codes ours/KDL " << codes);
  const double e = relErr(ours.qdd, kdl.qdd);
  CHECK_MESSAGE(e <= 1e-9, "grown chain: qdd after updateInternalDataStructures vs KDL rel err " << str(e));
  MESSAGE(testutil::format("grown chain: return codes (ours/KDL) %s; qdd after update rel err %.2e", codes.c_str(), e));
}

// KDL's deprecated name: the same results as KDL's ChainIdSolver_Vereshchagin.
TEST_CASE("the deprecated name gives ChainIdSolver_Vereshchagin's results") {
  const Scenario s = lwrTask();
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  const Outcome kdl = run<KDL::ChainIdSolver_Vereshchagin>(s);
  const Outcome ours = run<vereshchagin::kdl_compat::ChainIdSolver_Vereshchagin>(s);
#pragma GCC diagnostic pop
  const double e = std::max({relErr(ours.qdd, kdl.qdd), relErr(ours.nu, kdl.nu),
                             relErr(ours.constraint_tau, kdl.constraint_tau), relErr(ours.total_tau, kdl.total_tau)});
  CHECK_MESSAGE((kdl.rc == 0 && ours.rc == 0 && e <= 1e-10), "ChainIdSolver_Vereshchagin vs KDL's: rel err " << str(e));
}

// KDL's massless test chain (its solvertest's chain2: five segments without inertia). Its dynamics
// leave every acceleration free: KDL returns 0 with NaN outputs; the drop-in returns E_DEGRADED
// (>= 0, as KDL's solvertest asks) with the smallest q_dotdot meeting the constraints. Oracle: that
// least-norm solution from KDL's own kinematics, A q_dotdot = beta - alfa^T b with A = alfa^T J and
// b = Jdot qd - [omega x v; 0] + root_acc (the tip's spatial acceleration at q_dotdot = 0; KDL's
// Jdot qd is the classical one).
KDL::Chain kdlMasslessChain() {
  KDL::Chain chain;
  const KDL::Joint::JointType types[5] = {KDL::Joint::RotZ, KDL::Joint::RotX, KDL::Joint::RotX, KDL::Joint::RotX,
                                          KDL::Joint::RotZ};
  const double len[5] = {0.5, 0.4, 0.3, 0.2, 0.1};
  for (int i = 0; i < 5; ++i)
    chain.addSegment(KDL::Segment(KDL::Joint(types[i]), KDL::Frame(KDL::Vector(0.0, 0.0, len[i]))));
  return chain;
}

Eigen::VectorXd leastNormQdd(const Scenario& s) {
  const unsigned int n = s.chain.getNrOfJoints();
  KDL::Jacobian J(n);
  KDL::ChainJntToJacSolver(s.chain).JntToJac(s.q, J);
  KDL::Twist jdqd;
  KDL::ChainJntToJacDotSolver(s.chain).JntToJacDot(KDL::JntArrayVel(s.q, s.qd), jdqd);
  const Eigen::VectorXd t = J.data * s.qd.data;  // [v; omega] of the tip origin
  const Eigen::Vector3d v = t.head<3>(), w = t.tail<3>();
  Eigen::Matrix<double, 6, 1> b;
  b << Eigen::Vector3d(jdqd.vel.x(), jdqd.vel.y(), jdqd.vel.z()) - w.cross(v) +
           Eigen::Vector3d(s.root_acc.vel.x(), s.root_acc.vel.y(), s.root_acc.vel.z()),
      Eigen::Vector3d(jdqd.rot.x(), jdqd.rot.y(), jdqd.rot.z()) +
          Eigen::Vector3d(s.root_acc.rot.x(), s.root_acc.rot.y(), s.root_acc.rot.z());
  const Eigen::MatrixXd A = s.alfa.data.transpose() * J.data;
  const Eigen::VectorXd rhs = s.beta.data - s.alfa.data.transpose() * b;
  return Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(A).solve(rhs);
}

TEST_CASE("KDL's massless chain: E_DEGRADED with the least-norm q_dotdot") {
  Scenario s;
  s.chain = kdlMasslessChain();
  s.root_acc = KDL::Twist(KDL::Vector(0.0, 0.0, 9.81), KDL::Vector::Zero());
  s.q = KDL::JntArray(5), s.qd = KDL::JntArray(5), s.ff = KDL::JntArray(5);
  for (int j = 0; j < 5; ++j) s.q(j) = 0.3 * j - 0.5, s.qd(j) = 0.2 * j + 0.1;
  s.f_ext.assign(5, KDL::Wrench::Zero());
  s.alfa = KDL::Jacobian(3);
  s.alfa.data.setZero();
  s.alfa.data(2, 0) = 1.0;                           // tip z
  s.alfa.data(0, 1) = 0.6, s.alfa.data(4, 1) = 0.8;  // x force with a y moment
  s.beta = KDL::JntArray(3);                         // column 2 stays zero: disabled, as in KDL
  s.beta(0) = 9.81, s.beta(1) = 0.5;
  const Outcome kdl = run<Theirs>(s), ours = run<Ours>(s);
  CHECK_MESSAGE((kdl.rc == 0 && !kdl.qdd.allFinite()), "massless chain: KDL no longer returns 0 with NaN");
  CHECK_MESSAGE(ours.rc == KDL::SolverI::E_DEGRADED,
                "massless chain: ours returns " << str(ours.rc) << ", expected E_DEGRADED");
  const Eigen::VectorXd expected = leastNormQdd(s);
  const double e = relErr(ours.qdd, expected);
  CHECK_MESSAGE(e <= 1e-10, "massless chain: least-norm q_dotdot, rel err " << str(e));
  CHECK_MESSAGE(expected.norm() > 1.0, "massless chain: the oracle's q_dotdot is not trivial");
  CHECK_MESSAGE((ours.constraint_tau.isZero(0.0) && ours.total_tau.isZero(0.0) && ours.nu.isZero(0.0)),
                "massless chain: no torque and no constraint force");
  // Torques or wrenches on a massless chain accelerate it without bound: an error, not a guess.
  s.ff(2) = 0.1;
  CHECK_MESSAGE(run<Ours>(s).rc == vereshchagin::ChainHdSolver::E_DEGENERATE_INERTIA,
                "massless chain with ff_torques: E_DEGENERATE_INERTIA");
  s.ff(2) = 0.0;
  s.f_ext[4] = KDL::Wrench(KDL::Vector(1.0, 0.0, 0.0), KDL::Vector::Zero());
  CHECK_MESSAGE(run<Ours>(s).rc == vereshchagin::ChainHdSolver::E_DEGENERATE_INERTIA,
                "massless chain with f_ext: E_DEGENERATE_INERTIA");
}

}  // namespace
