// Fixed joints: a chain with fixed segments (first, in the middle, last, several in a row) must
// give the same motion as the chain where every fixed segment is merged into its parent:
//  * a fixed segment F after a moving segment P: one segment with P's joint, tip frame
//    f_tip_P * T_F and inertia T_F^-1 * I_P + I_F (both in F's tip frame); the wrenches applied on
//    P and F are moved to F's tip and added;
//  * fixed segments before the first moving joint: they only move the base, to B' = T0 (product of
//    their tip frames). The merged chain is expressed in B': root_acc' = T0^-1 root_acc, alfa and
//    f_ext rotated by R0^T; wrenches on these segments are carried by the immovable base.
// The merge itself is validated with KDL's inverse dynamics (ChainIdSolver_RNE handles fixed
// joints), and the merged chain (no fixed joint) against KDL's ChainHdSolver_Vereshchagin.
// Also: massless moving bodies carried by a massive fixed segment are fine; a joint with nothing to
// move (zero articulated inertia) is rejected with E_DEGENERATE_INERTIA.
#include <doctest/doctest.h>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>

#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"

using testutil::relErr;
using testutil::str;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;

namespace {

struct Merged {
  KDL::Chain chain;
  KDL::Frame T0 = KDL::Frame::Identity();  // merged base B' in the original base B
  std::vector<int> group;                  // original segment -> merged segment (-1: the base)
  std::vector<int> group_tip;              // merged segment -> original segment with the same tip
};

Merged mergeFixed(const KDL::Chain& ch) {
  Merged m;
  bool open = false;
  KDL::Joint joint;
  KDL::Frame tip;
  KDL::RigidBodyInertia inertia;
  std::string name;
  int last_orig = -1;
  auto flush = [&]() {
    m.chain.addSegment(KDL::Segment(name, joint, tip, inertia));
    m.group_tip.push_back(last_orig);
  };
  for (unsigned int i = 0; i < ch.getNrOfSegments(); ++i) {
    const KDL::Segment& s = ch.getSegment(i);
    if (s.getJoint().getType() == KDL::Joint::Fixed) {
      const KDL::Frame T = s.getFrameToTip();
      if (!open) {
        m.T0 = m.T0 * T;
        m.group.push_back(-1);
      } else {
        tip = tip * T;
        inertia = T.Inverse() * inertia + s.getInertia();
        last_orig = static_cast<int>(i);
        m.group.push_back(static_cast<int>(m.group_tip.size()));
      }
    } else {
      if (open) flush();
      open = true;
      joint = s.getJoint();
      tip = s.getFrameToTip();
      inertia = s.getInertia();
      name = s.getName();
      last_orig = static_cast<int>(i);
      m.group.push_back(static_cast<int>(m.group_tip.size()));
    }
  }
  if (open) flush();
  return m;
}

Eigen::Matrix<double, 6, 1> rotate6(const Eigen::Matrix3d& R, const Eigen::Matrix<double, 6, 1>& v) {
  Eigen::Matrix<double, 6, 1> out;
  out.head<3>() = R * v.head<3>();
  out.tail<3>() = R * v.tail<3>();
  return out;
}

Matrix6X rotate6(const Eigen::Matrix3d& R, const Matrix6X& m) {
  Matrix6X out(6, m.cols());
  for (Eigen::Index c = 0; c < m.cols(); ++c) out.col(c) = rotate6(R, Eigen::Matrix<double, 6, 1>(m.col(c)));
  return out;
}

std::vector<KDL::Frame> tipPoses(const KDL::Chain& ch, const KDL::JntArray& q) {
  KDL::ChainFkSolverPos_recursive fk(ch);
  std::vector<KDL::Frame> out(ch.getNrOfSegments());
  for (unsigned int i = 0; i < out.size(); ++i) fk.JntToCart(q, out[i], static_cast<int>(i) + 1);
  return out;
}

// Wrenches (base axes, moment about each original tip) -> merged chain (B' axes, merged tips).
KDL::Wrenches mergeWrenches(const Merged& m, const std::vector<KDL::Frame>& X, const KDL::Wrenches& f) {
  KDL::Wrenches out(m.group_tip.size(), KDL::Wrench::Zero());
  const KDL::Rotation R0inv = m.T0.M.Inverse();
  for (std::size_t i = 0; i < f.size(); ++i) {
    const int g = m.group[i];
    if (g < 0) continue;  // carried by the base
    const KDL::Vector to_tip = X[m.group_tip[g]].p - X[i].p;
    out[g] = out[g] + R0inv * f[i].RefPoint(to_tip);
  }
  return out;
}

KDL::Wrenches tipAxes(const std::vector<KDL::Frame>& X, const KDL::Wrenches& f,
                      const KDL::Rotation& R0 = KDL::Rotation::Identity()) {
  KDL::Wrenches out(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) out[i] = (R0 * X[i].M).Inverse() * f[i];
  return out;
}

struct Case {
  const char* name;
  std::vector<int> (*fixed)(int n, testutil::RandomGen& g);
  int min_n;
};

// Makes segment `idx` (a moving one) massless and rotor-free.
KDL::Chain masslessSegment(const KDL::Chain& ch, unsigned int idx) {
  KDL::Chain out;
  for (unsigned int i = 0; i < ch.getNrOfSegments(); ++i) {
    const KDL::Segment& s = ch.getSegment(i);
    if (i != idx) {
      out.addSegment(s);
      continue;
    }
    const KDL::Joint& j = s.getJoint();
    KDL::Joint j0 = (j.getType() == KDL::Joint::RotAxis || j.getType() == KDL::Joint::TransAxis)
                        ? KDL::Joint(j.getName(), j.JointOrigin(), j.JointAxis(), j.getType(), 1.0, 0.0, 0.0)
                        : KDL::Joint(j.getName(), j.getType(), 1.0, 0.0, 0.0);
    out.addSegment(KDL::Segment(s.getName(), j0, s.getFrameToTip(), KDL::RigidBodyInertia::Zero()));
  }
  return out;
}

struct Stats {
  int compared = 0, skipped = 0, kdl_compared = 0;
  double worst = 0.0;
};

void runSample(Stats& st, const KDL::Chain& orig, testutil::RandomGen& g, const std::string& tag0) {
  const Merged m = mergeFixed(orig);
  const unsigned int n = orig.getNrOfJoints(), ns = orig.getNrOfSegments(), nsm = m.chain.getNrOfSegments();
  if (!CHECK_MESSAGE((m.chain.getNrOfJoints() == n && nsm == n), tag0 << ": merge bookkeeping")) return;
  const int nc = g.integer(0, std::min(6, static_cast<int>(n)));
  const int root_kind = g.integer(0, 2);  // 0: none, 1: gravity, 2: random spatial base acceleration
  KDL::Twist root_acc = KDL::Twist::Zero();
  if (root_kind == 1) root_acc = KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());
  if (root_kind == 2) {  // (draws in their own statements: random_chain.hpp)
    const KDL::Vector angular = g.vector(-3, 3), linear = g.vector(-10, 10);
    root_acc = KDL::Twist(linear, angular);
  }
  const KDL::JntArray q = g.q(n), qd = g.qdot(n), ff = g.torques(n);
  const KDL::Wrenches fext = g.fext(ns);
  const KDL::Jacobian alfa = g.alfa(nc);
  const KDL::JntArray beta = g.beta(nc);
  const std::string tag = tag0 + " nc=" + str(nc) + " root=" + str(root_kind);

  const Eigen::Matrix3d R0 = testutil::toMatrix(m.T0.M);
  const std::vector<KDL::Frame> X = tipPoses(orig, q);
  const KDL::Twist root_acc_m = m.T0.Inverse() * root_acc;
  const KDL::Wrenches fext_m = mergeWrenches(m, X, fext);
  KDL::Jacobian alfa_m(nc);
  alfa_m.data = rotate6(R0.transpose(), Matrix6X(alfa.data));

  // Validate the merge itself with KDL's inverse dynamics (which supports fixed joints), using
  // gravity only (RNE takes a gravity vector, not a spatial base acceleration).
  {
    const KDL::Vector grav(0, 0, -9.81);
    KDL::ChainIdSolver_RNE id_o(orig, grav), id_m(m.chain, m.T0.M.Inverse() * grav);
    const KDL::JntArray qdd_any = g.jntArray(n, -3, 3);
    KDL::JntArray t_o(n), t_m(n);
    const int r1 = id_o.CartToJnt(q, qd, qdd_any, tipAxes(X, fext), t_o);
    const std::vector<KDL::Frame> Xm = tipPoses(m.chain, q);
    const int r2 = id_m.CartToJnt(q, qd, qdd_any, tipAxes(Xm, fext_m), t_m);
    CHECK_MESSAGE(
        (r1 == 0 && r2 == 0 && relErr(t_m.data, t_o.data) <= 1e-10),
        tag << ": test bug: merged chain has different inverse dynamics, rel err " << str(relErr(t_m.data, t_o.data)));
  }

  vereshchagin::ChainHdSolver so(orig, root_acc), sm(m.chain, root_acc_m);
  if (!CHECK_MESSAGE((so.modelError() == 0 && sm.modelError() == 0), tag << ": modelError " << str(so.modelError())
                                                                         << "/" << str(sm.modelError()) << " "
                                                                         << so.errorMessage()))
    return;
  KDL::JntArray qdd_o(n), tau_o(n), qdd_m(n), tau_m(n);
  int rc = so.CartToJnt(q, qd, qdd_o, alfa, beta, fext, ff, tau_o);
  if (!CHECK_MESSAGE(rc == 0, tag << ": original chain solve returned " << str(rc) << " " << so.errorMessage())) return;
  rc = sm.CartToJnt(q, qd, qdd_m, alfa_m, beta, fext_m, ff, tau_m);
  if (!CHECK_MESSAGE(rc == 0, tag << ": merged chain solve returned " << str(rc) << " " << sm.errorMessage())) return;
  CHECK_MESSAGE(
      (qdd_o.data.allFinite() && tau_o.data.allFinite() && so.nu().allFinite() && so.linkAccelerations().allFinite()),
      tag << ": non-finite output");

  const testutil::DenseModel dense = testutil::denseModel(m.chain, q);
  if (!testutil::wellConditioned(testutil::couplingEigenvalues(dense, alfa_m.data))) {
    ++st.skipped;
    return;
  }
  ++st.compared;
  const double e_qdd = relErr(qdd_o.data, qdd_m.data), e_nu = relErr(so.nu(), sm.nu()),
               e_tau = relErr(tau_o.data, tau_m.data);
  st.worst = std::max({st.worst, e_qdd, e_nu, e_tau});
  CHECK_MESSAGE(e_qdd <= 1e-10, tag << ": qdd differs from merged chain, rel err " << str(e_qdd) << "\n  fixed  "
                                    << testutil::mat(qdd_o.data) << "\n  merged " << testutil::mat(qdd_m.data));
  CHECK_MESSAGE(e_nu <= 1e-10, tag << ": nu differs from merged chain, rel err " << str(e_nu));
  CHECK_MESSAGE(e_tau <= 1e-10, tag << ": command torques differ from merged chain, rel err " << str(e_tau));
  CHECK_MESSAGE(so.constraintRank() == sm.constraintRank(), tag << ": rank differs");

  // Link accelerations: every original tip, from the merged chain's (rigid-body reference-point shift).
  const Matrix6X& acc_o = so.linkAccelerations();
  const Matrix6X& acc_m = sm.linkAccelerations();
  CHECK_MESSAGE(relErr(acc_o.col(0), testutil::toVector(root_acc)) == 0.0, tag << ": link acceleration 0 != root_acc");
  double e_acc = 0.0;
  for (unsigned int i = 0; i < ns; ++i) {
    const int gi = m.group[i];
    KDL::Twist expect;
    if (gi < 0) {
      expect = root_acc.RefPoint(X[i].p);
    } else {
      const Eigen::Matrix<double, 6, 1> a_base = rotate6(R0, Eigen::Matrix<double, 6, 1>(acc_m.col(gi + 1)));
      const KDL::Twist a(KDL::Vector(a_base(0), a_base(1), a_base(2)), KDL::Vector(a_base(3), a_base(4), a_base(5)));
      expect = a.RefPoint(X[i].p - X[m.group_tip[gi]].p);
    }
    e_acc = std::max(e_acc, relErr(acc_o.col(i + 1), testutil::toVector(expect)));
  }
  st.worst = std::max(st.worst, e_acc);
  CHECK_MESSAGE(e_acc <= 1e-10, tag << ": link accelerations differ from the merged chain's, rel err " << str(e_acc));

  // The merged chain has no fixed joint, so KDL's solver applies.
  KDL::ChainHdSolver_Vereshchagin kdl(m.chain, root_acc_m, static_cast<unsigned int>(nc));
  KDL::JntArray qdd_k(n), ct_k(n);
  rc = kdl.CartToJnt(q, qd, qdd_k, alfa_m, beta, fext_m, ff, ct_k);
  Eigen::VectorXd nu_k = Eigen::VectorXd::Zero(nc);
  kdl.getContraintForceMagnitude(nu_k);
  ++st.kdl_compared;
  CHECK_MESSAGE((rc == 0 && relErr(qdd_o.data, qdd_k.data) <= 1e-10 && relErr(so.nu(), nu_k) <= 1e-10),
                tag << ": chain with fixed joints vs KDL on the merged chain: qdd rel err "
                    << str(relErr(qdd_o.data, qdd_k.data)) << ", nu rel err " << str(relErr(so.nu(), nu_k)));
}

void degenerateCase(const std::string& tag, const KDL::Chain& ch, int nc) {
  vereshchagin::ChainHdSolver s(ch, KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()));
  const unsigned int n = ch.getNrOfJoints(), ns = ch.getNrOfSegments();
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(n, 0.3), qd = Eigen::VectorXd::Constant(n, 0.5);
  Matrix6X alfa = Matrix6X::Zero(6, nc);
  for (int c = 0; c < nc; ++c) alfa(c, c) = 1.0;
  const Eigen::VectorXd beta = Eigen::VectorXd::Zero(nc), ff = Eigen::VectorXd::Constant(n, 1.0);
  const Matrix6X fext = Matrix6X::Zero(6, ns);
  const int rc = s.solve(q, qd, alfa, beta, fext, ff);
  CHECK_MESSAGE(rc == vereshchagin::ChainHdSolver::E_DEGENERATE_INERTIA, tag << ": expected E_DEGENERATE_INERTIA, got "
                                                                             << str(rc) << " (modelError "
                                                                             << str(s.modelError()) << ")");
  CHECK_MESSAGE(std::string(s.errorMessage()).size() > 0, tag << ": empty errorMessage()");
  CHECK_MESSAGE((s.qdd().allFinite() && s.commandTorques().allFinite() && s.linkAccelerations().allFinite()),
                tag << ": NaN in outputs after rejection");
  KDL::JntArray qk(n), qdk(n), qdd(n), tau(n), ffk(n), betak(nc);
  KDL::Jacobian alfak(nc);
  alfak.data = alfa;
  const int rc2 = s.CartToJnt(qk, qdk, qdd, alfak, betak, KDL::Wrenches(ns, KDL::Wrench::Zero()), ffk, tau);
  CHECK_MESSAGE((rc2 == vereshchagin::ChainHdSolver::E_DEGENERATE_INERTIA && qdd.data.allFinite()),
                tag << ": CartToJnt: expected E_DEGENERATE_INERTIA, got " << str(rc2));
}

}  // namespace

TEST_CASE("fixed segments anywhere, and massless moving bodies carried by them, move like the merged chain") {
  Stats st;

  const std::vector<Case> cases = {
      {"first", [](int, testutil::RandomGen&) { return std::vector<int>{0}; }, 1},
      {"two-first",
       [](int, testutil::RandomGen&) {
         return std::vector<int>{0, 0};
       },
       1},
      {"middle", [](int n, testutil::RandomGen& g) { return std::vector<int>{g.integer(1, n - 1)}; }, 2},
      {"two-middle",
       [](int n, testutil::RandomGen& g) {
         int k = g.integer(1, n - 1);
         return std::vector<int>{k, k};
       },
       2},
      {"last", [](int n, testutil::RandomGen&) { return std::vector<int>{n}; }, 1},
      {"two-last",
       [](int n, testutil::RandomGen&) {
         return std::vector<int>{n, n};
       },
       1},
      {"first-middle-last",
       [](int n, testutil::RandomGen& g) {
         return std::vector<int>{0, g.integer(1, n - 1), n};
       },
       2},
      {"everywhere",
       [](int n, testutil::RandomGen&) {
         std::vector<int> v;
         for (int k = 0; k <= n; ++k) v.push_back(k);
         return v;
       },
       1},
  };

  int ci = 0;
  for (const Case& c : cases) {
    for (int s = 0; s < 40; ++s, ++ci) {
      const unsigned long long seed = 7919ULL * static_cast<unsigned long long>(ci) + 3ULL;
      testutil::RandomGen g(seed);
      testutil::ChainSpec spec;
      spec.n_joints = g.integer(c.min_n, 8);
      spec.fixed_before = c.fixed(spec.n_joints, g);
      const KDL::Chain orig = g.chain(spec);
      runSample(st, orig, g, std::string(c.name) + " seed " + str(seed) + " n=" + str(spec.n_joints));
    }
  }

  // Massless moving bodies whose motion is given inertia by fixed segments after them.
  for (int s = 0; s < 40; ++s) {
    const unsigned long long seed = 104729ULL * static_cast<unsigned long long>(s) + 11ULL;
    testutil::RandomGen g(seed);
    testutil::ChainSpec spec;
    spec.n_joints = g.integer(1, 6);
    spec.fixed_before = {spec.n_joints};
    KDL::Chain ch = g.chain(spec);
    ch = masslessSegment(ch, ch.getNrOfSegments() - 2);  // the last moving body
    runSample(st, ch, g, "massless-last-moving seed " + str(seed) + " n=" + str(spec.n_joints));
  }

  CHECK_MESSAGE(st.compared >= 250, "too few samples compared: " << str(st.compared));
  CHECK_MESSAGE(st.skipped * 10 <= st.compared, "too many ill-conditioned samples skipped: " << str(st.skipped));
  MESSAGE(str(st.compared) << " chains compared with their merged versions (" << str(st.skipped)
                           << " ill-conditioned skipped), " << str(st.kdl_compared) << " with KDL; worst rel err "
                           << str(st.worst));
}

TEST_CASE("a joint with nothing to move is rejected with E_DEGENERATE_INERTIA") {
  KDL::Chain one;
  one.addSegment(KDL::Segment("s0", KDL::Joint("j0", KDL::Joint::RotZ), KDL::Frame(KDL::Vector(1, 0, 0)),
                              KDL::RigidBodyInertia::Zero()));
  degenerateCase("1 joint, zero mass, no rotor, nc=0", one, 0);
  degenerateCase("1 joint, zero mass, no rotor, nc=1", one, 1);

  KDL::Chain one_fixed = one;  // a massless fixed segment does not help
  one_fixed.addSegment(
      KDL::Segment(KDL::Joint(KDL::Joint::Fixed), KDL::Frame(KDL::Vector(0, 1, 0)), KDL::RigidBodyInertia::Zero()));
  degenerateCase("1 joint + massless fixed segment", one_fixed, 0);

  KDL::Chain on_axis;  // a point mass on the revolute axis: no inertia about it
  on_axis.addSegment(KDL::Segment("s0", KDL::Joint("j0", KDL::Joint::RotZ), KDL::Frame::Identity(),
                                  KDL::RigidBodyInertia(2.0, KDL::Vector(0, 0, 0.4))));
  degenerateCase("point mass on the joint axis", on_axis, 0);

  testutil::RandomGen g(99);
  KDL::Chain three = g.chain(3, true, true);
  three = masslessSegment(three, 2);
  degenerateCase("3 joints, last body massless, no rotor", three, 0);
  degenerateCase("3 joints, last body massless, no rotor, nc=2", three, 2);
}
