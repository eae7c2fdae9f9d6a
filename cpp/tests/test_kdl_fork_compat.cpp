// The KDL fork's classes (kdl_fork_compat.hpp) in a controller written in the style of the Kinova
// Gen3 code built on that fork: a 7-joint arm with fixed segments (a fixed link between joints 4
// and 5, the bracelet's end-effector and tool frames fixed at the end), task-space PD control of
// the tool through beta in the fork's gravity-free convention (a tilted task frame, so that
// alfa^T root_acc != 0), an external press on the tool along its free direction, and
// setDriverWeights. Oracle: Debian's KDL 1.5.1 (ChainHdSolver_Vereshchagin, ChainFdSolver_RNE) on
// the same arm with each fixed segment merged into its parent (KDL cannot take fixed joints),
// fed with beta_fork + alfa^T root_acc, the fork's documented semantics:
//  * weights 0 (Fixed_Joint): q_dotdot, nu, constraint_torques, total torque equal KDL's;
//  * f_ext weights 1 (setDriverWeights, and the Fext classes by default): nu and
//    constraint_torques equal KDL's solve without f_ext, q_dotdot that solve's plus the
//    unconstrained response to f_ext alone (KDL forward dynamics, no velocity, no gravity);
//  * beta_fork = 0 holds the tool still against gravity (physical acceleration 0).
// Every comparison at 1e-10 relative, at each step of a 200-step closed loop driven by the alias.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainfksolvervel_recursive.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>

#include "test_common.hpp"
#include "vereshchagin/kdl_fork_compat.hpp"

using testutil::relErr;
using testutil::str;

namespace {

KDL::RigidBodyInertia link(double m, double cz, double r) {
  return KDL::RigidBodyInertia(m, KDL::Vector(0.01, -0.005, cz), KDL::RotationalInertia(r, 1.1 * r, 0.6 * r, 0.01 * r));
}

// Kinova-Gen3-like arm: alternating z/y axes, link masses 1-1.7 kg, rotor inertias.
KDL::Chain kinovaLike() {
  KDL::Chain c;
  const KDL::Joint::JointType axes[7] = {KDL::Joint::RotZ, KDL::Joint::RotY, KDL::Joint::RotZ, KDL::Joint::RotY,
                                         KDL::Joint::RotZ, KDL::Joint::RotY, KDL::Joint::RotZ};
  const double len[7] = {0.156, 0.128, 0.21, 0.21, 0.208, 0.106, 0.061};
  const double mass[7] = {1.38, 1.16, 1.16, 0.93, 0.68, 0.68, 0.5};
  for (int j = 0; j < 7; ++j) {
    KDL::Joint joint("j" + str(j), axes[j], 1.0, 0.0, 0.02 + 0.01 * j);  // rotor inertia
    c.addSegment(KDL::Segment("link" + str(j), joint,
                              KDL::Frame(KDL::Rotation::RPY(0.1 * j, 0.0, 0.05), KDL::Vector(0.0, 0.005 * j, len[j])),
                              link(mass[j], 0.5 * len[j], 0.004 + 0.001 * j)));
    if (j == 3)  // a fixed link in the middle
      c.addSegment(KDL::Segment("spacer", KDL::Joint(KDL::Joint::Fixed), KDL::Frame(KDL::Vector(0.02, 0.0, 0.03)),
                                link(0.3, 0.015, 0.0005)));
  }
  // The bracelet's end-effector frame and a tool (fixed), as in the Kinova URDF chains.
  c.addSegment(KDL::Segment("end_effector", KDL::Joint(KDL::Joint::Fixed),
                            KDL::Frame(KDL::Rotation::RotX(M_PI), KDL::Vector(0.0, 0.0, -0.06)),
                            link(0.2, 0.01, 0.0003)));
  c.addSegment(KDL::Segment("tool_frame", KDL::Joint(KDL::Joint::Fixed), KDL::Frame(KDL::Vector(0.0, 0.0, 0.12)),
                            link(0.4, -0.05, 0.001)));
  return c;
}

// The same arm for KDL: every fixed segment merged into its parent (tip frames composed, the
// parent's inertia re-expressed in the merged tip frame).
KDL::Chain merged(const KDL::Chain& c) {
  std::vector<KDL::Segment> out;
  for (unsigned int i = 0; i < c.getNrOfSegments(); ++i) {
    const KDL::Segment& s = c.getSegment(i);
    if (s.getJoint().getType() != KDL::Joint::Fixed) {
      out.push_back(s);
      continue;
    }
    const KDL::Segment& p = out.back();
    const KDL::Frame f = s.getFrameToTip();
    out.back() =
        KDL::Segment(p.getName(), p.getJoint(), p.getFrameToTip() * f, f.Inverse() * p.getInertia() + s.getInertia());
  }
  KDL::Chain m;
  for (const KDL::Segment& s : out) m.addSegment(s);
  return m;
}

Eigen::Matrix<double, 6, 1> vec(const KDL::Twist& t) {
  Eigen::Matrix<double, 6, 1> v;
  v << t.vel.x(), t.vel.y(), t.vel.z(), t.rot.x(), t.rot.y(), t.rot.z();
  return v;
}

struct KdlResult {
  Eigen::VectorXd qdd, nu, ctau, total;
};

KdlResult kdlSolve(const KDL::Chain& chain, const KDL::Twist& root_acc, const KDL::JntArray& q, const KDL::JntArray& qd,
                   const KDL::Jacobian& alfa, const KDL::JntArray& beta, const KDL::Wrenches& f,
                   const KDL::JntArray& ff) {
  const unsigned int n = chain.getNrOfJoints();
  KDL::ChainHdSolver_Vereshchagin kdl(chain, root_acc, alfa.columns());
  KDL::JntArray qdd(n), ctau(n), total(n);
  KdlResult r;
  r.nu.resize(alfa.columns());
  if (kdl.CartToJnt(q, qd, qdd, alfa, beta, f, ff, ctau) != 0) return r;
  kdl.getContraintForceMagnitude(r.nu);
  kdl.getTotalTorque(total);
  r.qdd = qdd.data, r.ctau = ctau.data, r.total = total.data;
  return r;
}

// A 200-step closed loop on the Kinova-like arm against KDL on the merged chain.
void closedLoop(const std::string& name, bool weights_by_setter) {
  using Fork = vereshchagin::kdl_fork::ChainHdSolver_Vereshchagin_Fixed_Joint;
  using ForkFext = vereshchagin::kdl_fork::ChainHdSolver_Vereshchagin_Fext_FixedJoint;
  const KDL::Chain chain = kinovaLike(), oracle_chain = merged(chain);
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments(), nm = oracle_chain.getNrOfSegments();
  CHECK_MESSAGE((n == 7 && ns == 10 && nm == 7), name << ": chain sizes");
  const KDL::Twist root_acc(KDL::Vector(0.0, 0.0, 9.81), KDL::Vector::Zero());
  // Five columns in a task frame tilted by 0.3 rad about x: linear x', y' and the three
  // rotations; linear z' (the press direction) free. alfa^T root_acc != 0 for y'.
  const int nc = 5;
  const KDL::Rotation task = KDL::Rotation::RotX(0.3);
  KDL::Jacobian alfa(nc);
  KDL::SetToZero(alfa);
  for (int c = 0; c < 2; ++c)
    for (int r = 0; r < 3; ++r) alfa(r, c) = task(r, c);
  alfa(3, 2) = alfa(4, 3) = alfa(5, 4) = 1.0;
  Fork plain(chain, root_acc, nc);
  ForkFext fext_default(chain, root_acc, nc);
  Fork weighted(chain, root_acc, nc);
  if (weights_by_setter)
    CHECK_MESSAGE(weighted.setDriverWeights(Eigen::VectorXd::Ones(nc), Eigen::VectorXd::Zero(nc)) == 0,
                  name << ": weights");
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainFkSolverVel_recursive fkv(chain);
  KDL::JntArray q(n), qd(n), qdd(n), ctau(n), total(n), ff(n), beta(nc), beta_eff(nc);
  const double q0[7] = {0.1, 0.6, -0.2, 1.9, 0.3, -0.8, 0.4};
  for (unsigned int j = 0; j < n; ++j) q(j) = q0[j], ff(j) = 0.3 * std::sin(1.0 + j);
  KDL::Frame start;
  fk.JntToCart(q, start);
  KDL::Wrenches f_ext(ns, KDL::Wrench::Zero()), f_oracle(nm, KDL::Wrench::Zero()), none(nm, KDL::Wrench::Zero());
  const double dt = 1e-3;
  double worst[6] = {0, 0, 0, 0, 0, 0};
  int failures = 0;
  for (int step = 0; step < 200; ++step) {
    // Task: track a point moving along x, hold orientation (gravity-free beta, the fork's way).
    KDL::Frame tip;
    KDL::FrameVel tipv;
    fk.JntToCart(q, tip);
    fkv.JntToCart(KDL::JntArrayVel(q, qd), tipv);
    const KDL::Vector target = start.p + KDL::Vector(0.05 * std::sin(5.0 * step * dt), 0.0, 0.0);
    const KDL::Vector e_p = target - tip.p, e_r = KDL::diff(tip.M, start.M);
    const KDL::Twist v = tipv.GetTwist();
    const double kp = 400.0, kd = 40.0;
    const double acc[6] = {kp * e_p.x() - kd * v.vel.x(), kp * e_p.y() - kd * v.vel.y(), kp * e_p.z() - kd * v.vel.z(),
                           kp * e_r.x() - kd * v.rot.x(), kp * e_r.y() - kd * v.rot.y(), kp * e_r.z() - kd * v.rot.z()};
    for (int c = 0; c < nc; ++c) {
      beta(c) = 0.0;
      for (int r = 0; r < 6; ++r) beta(c) += alfa(r, c) * acc[r];
      beta_eff(c) = beta(c) + alfa(2, c) * 9.81;  // + alfa^T root_acc (root_acc = 9.81 along z)
    }
    // A press of 8 N along -z' on the tool (base axes, about the tool tip), ramped in.
    const double press = 8.0 * std::min(1.0, step / 50.0);
    f_ext[ns - 1] = KDL::Wrench(task * KDL::Vector(0.0, 0.0, -press), KDL::Vector::Zero());
    f_oracle[nm - 1] = f_ext[ns - 1];
    // Oracles (KDL).
    const KdlResult with_f = kdlSolve(oracle_chain, root_acc, q, qd, alfa, beta_eff, f_oracle, ff);
    const KdlResult without_f = kdlSolve(oracle_chain, root_acc, q, qd, alfa, beta_eff, none, ff);
    KDL::ChainFdSolver_RNE fd(oracle_chain, KDL::Vector::Zero());
    KDL::JntArray zero(n), qdd_f(n);
    const bool fd_ok = fd.CartToJnt(q, zero, zero, testutil::toTipAxes(oracle_chain, q, f_oracle), qdd_f) == 0;
    // Weights 0: KDL with the shifted beta.
    Eigen::VectorXd nu(nc);
    bool ok = plain.CartToJnt(q, qd, qdd, alfa, beta, f_ext, ff, ctau) == 0;
    plain.getContraintForceMagnitude(nu);
    plain.getTotalTorque(total);
    const double e0[4] = {relErr(qdd.data, with_f.qdd), relErr(nu, with_f.nu), relErr(ctau.data, with_f.ctau),
                          relErr(total.data, with_f.total)};
    // f_ext weights 1: the Fext class by default, or setDriverWeights on the Fixed_Joint class.
    KDL::JntArray qdd_w(n), ctau_w(n);
    Eigen::VectorXd nu_w(nc);
    Fork& w = weights_by_setter ? weighted : static_cast<Fork&>(fext_default);
    ok = ok && w.CartToJnt(q, qd, qdd_w, alfa, beta, f_ext, ff, ctau_w) == 0 && fd_ok;
    w.getContraintForceMagnitude(nu_w);
    const double e1[3] = {relErr(qdd_w.data, without_f.qdd + qdd_f.data), relErr(nu_w, without_f.nu),
                          relErr(ctau_w.data, without_f.ctau)};
    // The test can fail: the unshifted beta (KDL's convention) and the weights do change the result.
    if (step == 100) {
      const KdlResult unshifted = kdlSolve(oracle_chain, root_acc, q, qd, alfa, beta, f_oracle, ff);
      const double d_beta = relErr(qdd.data, unshifted.qdd), d_w = relErr(qdd_w.data, qdd.data);
      CHECK_MESSAGE((d_beta > 1e-2 && d_w > 1e-3),
                    name << ": the oracle does not discriminate (beta shift changes qdd by " << str(d_beta)
                         << ", weights by " << str(d_w) << ")");
    }
    for (int k = 0; k < 4; ++k) worst[k] = std::max(worst[k], e0[k]);
    for (int k = 0; k < 3; ++k) worst[4] = std::max(worst[4], e1[k]);
    const bool good = ok && *std::max_element(e0, e0 + 4) <= 1e-10 && *std::max_element(e1, e1 + 3) <= 1e-10;
    if (!good && failures++ < 3)
      CHECK_MESSAGE(false, name << ": step " << str(step) << ": weights 0 rel err qdd/nu/ctau/total " << str(e0[0])
                                << " " << str(e0[1]) << " " << str(e0[2]) << " " << str(e0[3])
                                << "; f_ext weights 1: " << str(e1[0]) << " " << str(e1[1]) << " " << str(e1[2]));
    // The controller runs on the plain class (semi-implicit Euler).
    for (unsigned int j = 0; j < n; ++j) qd(j) += dt * qdd(j), q(j) += dt * qd(j);
  }
  CHECK_MESSAGE(failures == 0, name << ": " << str(failures) << " of 200 steps differ from the oracle");
  KDL::Frame end;
  fk.JntToCart(q, end);
  MESSAGE(
      testutil::format("%s: 200 steps, worst rel err vs KDL (merged chain, beta + alfa^T root_acc): qdd %.1e, nu %.1e, "
                       "constraint_torques %.1e, total %.1e; f_ext weights 1 vs KDL without f_ext + FD(f_ext) %.1e; "
                       "tool moved %.4f m in x",
                       name.c_str(), worst[0], worst[1], worst[2], worst[3], worst[4], end.p.x() - start.p.x()));
}

// beta_fork = 0 (nc = 6) at rest holds the tool still against gravity: its acceleration
// (getTransformedLinkAcceleration, including root_acc) equals root_acc, i.e. physically zero.
TEST_CASE("beta_fork = 0 at rest holds the tool still against gravity") {
  const KDL::Chain chain = kinovaLike();
  const KDL::Twist root_acc(KDL::Vector(0.0, 0.0, 9.81), KDL::Vector::Zero());
  KDL::Jacobian alfa(6);
  KDL::SetToZero(alfa);
  for (int c = 0; c < 6; ++c) alfa(c, c) = 1.0;
  vereshchagin::kdl_fork::ChainHdSolver_Vereshchagin fork(chain, root_acc, 6);
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
  KDL::JntArray q(n), qd(n), qdd(n), ctau(n), ff(n), beta(6);
  for (unsigned int j = 0; j < n; ++j) q(j) = 0.4 * std::cos(j + 0.5);
  KDL::Wrenches f(ns, KDL::Wrench::Zero());
  std::vector<KDL::Twist> xdd(ns + 1);
  CHECK_MESSAGE(fork.CartToJnt(q, qd, qdd, alfa, beta, f, ff, ctau) == 0, "hold still: solve");
  fork.getTransformedLinkAcceleration(xdd);
  const double e = relErr(vec(xdd[ns]), vec(root_acc));
  CHECK_MESSAGE(e <= 1e-10, "hold still: beta_fork = 0 gives tool acceleration - root_acc rel err " << str(e));
  MESSAGE(testutil::format("hold still: beta_fork = 0, tool acceleration minus root_acc %.1e", e));
}

// The Fext classes keep their f_ext priority across updateInternalDataStructures(), and
// setDriverWeights(0, 0) on them gives the plain class's results.
TEST_CASE("the Fext classes keep their f_ext priority across updateInternalDataStructures") {
  const KDL::Chain chain = kinovaLike();
  const KDL::Twist root_acc(KDL::Vector(0.0, 0.0, 9.81), KDL::Vector::Zero());
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
  KDL::Jacobian alfa(3);
  KDL::SetToZero(alfa);
  alfa(0, 0) = alfa(1, 1) = alfa(5, 2) = 1.0;
  KDL::JntArray q(n), qd(n), ff(n), beta(3), a(n), b(n), c(n), t(n);
  for (unsigned int j = 0; j < n; ++j) q(j) = 0.2 * j - 0.3, qd(j) = 0.1 * j;
  KDL::Wrenches f(ns, KDL::Wrench::Zero());
  f[ns - 1] = KDL::Wrench(KDL::Vector(3.0, -2.0, -8.0), KDL::Vector(0.1, 0.0, 0.2));
  vereshchagin::kdl_fork::ChainHdSolver_Vereshchagin_Fext fext(chain, root_acc, 3);
  vereshchagin::kdl_fork::ChainHdSolver_Vereshchagin plain(chain, root_acc, 3);
  bool ok = fext.CartToJnt(q, qd, a, alfa, beta, f, ff, t) == 0;
  fext.updateInternalDataStructures();
  ok = ok && fext.CartToJnt(q, qd, b, alfa, beta, f, ff, t) == 0;
  CHECK_MESSAGE((ok && a.data == b.data), "Fext: weights kept across updateInternalDataStructures");
  ok = fext.setDriverWeights(Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3)) == 0 &&
       fext.CartToJnt(q, qd, b, alfa, beta, f, ff, t) == 0 && plain.CartToJnt(q, qd, c, alfa, beta, f, ff, t) == 0;
  CHECK_MESSAGE((ok && b.data == c.data && relErr(a.data, c.data) > 1e-3),
                "Fext with weights 0 equals the plain class (and differs from weights 1)");
}

}  // namespace

TEST_CASE("closed loop: Fixed_Joint class with setDriverWeights against KDL on the merged chain") {
  closedLoop("Fixed_Joint + setDriverWeights", /*weights_by_setter=*/true);
}

TEST_CASE("closed loop: Fext_FixedJoint class against KDL on the merged chain") {
  closedLoop("Fixed_Joint + Fext_FixedJoint", /*weights_by_setter=*/false);
}
