// FrictionSolver: the 1-DOF numbers of Vukcevic 2018 (ch. 6), holding by friction, and on random chains the
// physics of the result checked with KDL's forward dynamics (ff + tau_cmd + friction reproduces
// qdd) and the stick/slip complementarity conditions.
#include <cmath>

#include <doctest/doctest.h>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>

#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/friction_solver.hpp"

namespace {

using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using testutil::str;

// Vukcevic 2018, sec. 6: 1 kg, 1 m link, COM at 0.5 m, joint-axis inertia 2.25 kg m^2, about z.
// (Only the z moment matters; x and y are set so that the body is a rigid body: 1 + 1 >= 2.)
KDL::Chain oneDof() {
  KDL::Chain ch;
  ch.addSegment(KDL::Segment(
      "link", KDL::Joint("j", KDL::Joint::RotZ), KDL::Frame(KDL::Vector(1, 0, 0)),
      KDL::RigidBodyInertia(1.0, KDL::Vector(-0.5, 0, 0), KDL::RotationalInertia(1.0, 1.0, 2.0, 0, 0, 0))));
  return ch;
}

}  // namespace

// One solver through the three scenarios in turn (as in the report).
TEST_CASE("1-DOF numbers of Vukcevic 2018: stick, slip, fully constrained") {
  const KDL::Chain ch = oneDof();
  vereshchagin::FrictionSolver fs(ch, KDL::Twist::Zero());
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::Constant(1, 10.0);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
  const Matrix6X none(6, 0);
  const Eigen::VectorXd nobeta(0);
  // Scenario 1: -5 N m external torque, unconstrained: friction +5, qdd = 0.
  Eigen::VectorXd tau = Eigen::VectorXd::Constant(1, -5.0);
  CHECK_MESSAGE(fs.solve(zero, zero, none, nobeta, none, tau, fm) == 0, "scenario 1 solves");
  CHECK_MESSAGE((std::abs(fs.frictionTorques()(0) - 5.0) < 1e-12 && std::abs(fs.qdd()(0)) < 1e-12 &&
                 fs.status()[0] == vereshchagin::FrictionSolver::Stick),
                "scenario 1: friction +5 N m, qdd 0, stick (got " << str(fs.frictionTorques()(0)) << ", "
                                                                  << str(fs.qdd()(0)) << ")");
  // Scenario 2: -11 N m: friction +10, qdd = -1 / 2.25.
  tau(0) = -11.0;
  CHECK_MESSAGE(fs.solve(zero, zero, none, nobeta, none, tau, fm) == 0, "scenario 2 solves");
  CHECK_MESSAGE((std::abs(fs.frictionTorques()(0) - 10.0) < 1e-12 && std::abs(fs.qdd()(0) + 1.0 / 2.25) < 1e-12 &&
                 fs.status()[0] == vereshchagin::FrictionSolver::SlipNegative),
                "scenario 2: friction +10 N m, qdd -0.444 rad/s^2, slip");
  // Gauss value of scenario 2: 1/2 * 2.25 * (qdd - qdd_free)^2 + f |qdd|, qdd_free = -11 / 2.25.
  const double dq = -1.0 / 2.25 + 11.0 / 2.25;
  CHECK_MESSAGE(std::abs(fs.gaussValue() - (0.5 * 2.25 * dq * dq + 10.0 / 2.25)) < 1e-10, "scenario 2 Gauss value");
  // Fully constrained (fig. 5.5): angular acceleration 5 rad/s^2 -> friction -10, command 21.25.
  const Matrix6X alfa = Eigen::Matrix<double, 6, 1>::Unit(5);
  const Eigen::VectorXd beta = Eigen::VectorXd::Constant(1, 5.0);
  tau(0) = 0.0;
  CHECK_MESSAGE(fs.solve(zero, zero, alfa, beta, none, tau, fm) == 0, "constrained case solves");
  CHECK_MESSAGE((std::abs(fs.qdd()(0) - 5.0) < 1e-12 && std::abs(fs.frictionTorques()(0) + 10.0) < 1e-12 &&
                 std::abs(fs.commandTorques()(0) - 21.25) < 1e-12),
                "constrained case: qdd 5, friction -10, command 21.25 (got " << str(fs.commandTorques()(0)) << ")");
}

TEST_CASE("1-DOF link held still against gravity up to the breakaway torque") {
  const KDL::Chain ch = oneDof();
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::Constant(1, 10.0);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1), tau = zero;
  const Matrix6X none(6, 0);
  const Matrix6X alfa = Eigen::Matrix<double, 6, 1>::Unit(5);
  // Holding still against gravity torques of 4.9 and 14.7 N m (gravity along -y, arm along x).
  for (const double g : {9.8, 29.4}) {
    vereshchagin::FrictionSolver fg(ch, KDL::Twist(KDL::Vector(0, g, 0), KDL::Vector::Zero()));
    const Eigen::VectorXd still = Eigen::VectorXd::Zero(1);
    CHECK_MESSAGE(fg.solve(zero, zero, alfa, still, none, tau, fm) == 0, "holding solves");
    const double expected = std::max(0.0, 0.5 * g - 10.0);
    CHECK_MESSAGE((std::abs(std::abs(fg.commandTorques()(0)) - expected) < 1e-12 && std::abs(fg.qdd()(0)) < 1e-12),
                  "holding against " << str(0.5 * g) << " N m: |command| " << str(fg.commandTorques()(0))
                                     << ", expected " << str(expected));
  }
}

TEST_CASE("300 random chains: KDL forward dynamics and stick/slip complementarity") {
  int compared = 0;
  testutil::RandomGen g(4242);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = g.integer(2, 7);
    const KDL::Chain chain = g.chain(n, true, true);
    const unsigned int ns = chain.getNrOfSegments();
    const bool gravity = g.coin();
    const KDL::Twist root(KDL::Vector(0, 0, gravity ? 9.81 : 0.0), KDL::Vector::Zero());
    vereshchagin::FrictionSolver fs(chain, root);
    vereshchagin::FrictionModel fm;
    fm.static_friction = Eigen::VectorXd(n);
    for (int j = 0; j < n; ++j) fm.static_friction(j) = g.coin(0.15) ? 0.0 : g.uniform(0.0, 8.0);
    fm.kinetic_friction = fm.static_friction * g.uniform(0.3, 1.0);
    KDL::JntArray q = g.q(n), qd(n);
    for (int j = 0; j < n; ++j) qd(j) = g.coin(0.7) ? 0.0 : g.uniform(-1.0, 1.0);
    const KDL::JntArray ff = g.torques(n);
    const KDL::Wrenches fext = g.fext(ns);
    const int nc = g.integer(0, std::min(3, n - 1));
    const KDL::Jacobian alfa = g.alfa(nc);
    const KDL::JntArray beta = g.beta(nc);
    const int rc = fs.solve(q.data, qd.data, alfa.data, beta.data, testutil::toMatrix(fext), ff.data, fm);
    if (!CHECK_MESSAGE(rc == 0, "trial " << str(trial) << ": solve failed: " << fs.errorMessage())) continue;
    ++compared;
    // Equation of motion: KDL's forward dynamics with ff + tau_cmd + friction gives qdd. KDL's
    // RNE-based FD takes f_ext in segment-tip axes and gravity with the physical sign.
    KDL::Wrenches fext_local(ns);
    KDL::Frame f = KDL::Frame::Identity();
    unsigned int j = 0;
    for (unsigned int i = 0; i < ns; ++i) {
      const KDL::Segment& seg = chain.getSegment(i);
      f = f * seg.pose(seg.getJoint().getType() == KDL::Joint::Fixed ? 0.0 : q(j));
      if (seg.getJoint().getType() != KDL::Joint::Fixed) ++j;
      fext_local[i] = KDL::Wrench(f.M.Inverse(fext[i].force), f.M.Inverse(fext[i].torque));
    }
    KDL::ChainFdSolver_RNE fd(chain, KDL::Vector(0, 0, gravity ? -9.81 : 0.0));
    KDL::JntArray torques(n), qdd_fd(n);
    torques.data = ff.data + fs.commandTorques() + fs.frictionTorques() + fs.limitTorques();
    fd.CartToJnt(q, qd, torques, fext_local, qdd_fd);
    CHECK_MESSAGE(testutil::relErr(qdd_fd.data, fs.qdd()) < 1e-9,
                  "trial " << str(trial) << ": FD(ff + tau_cmd + friction) != qdd, rel err "
                           << str(testutil::relErr(qdd_fd.data, fs.qdd())));
    // The affine update equals a plain solve with the friction torques as feed-forward (qdd, nu,
    // tau_cmd), and the link accelerations (computed by that extra solve on request) agree.
    vereshchagin::ChainHdSolver plain(chain, root);
    const Eigen::VectorXd ff_total = ff.data + fs.limitTorques() + fs.frictionTorques();
    CHECK_MESSAGE(plain.solve(q.data, qd.data, alfa.data, beta.data, testutil::toMatrix(fext), ff_total) == 0,
                  "trial " << str(trial) << ": plain solve failed");
    CHECK_MESSAGE((testutil::relErr(plain.qdd(), fs.qdd()) < 1e-9 &&
                   testutil::relErr(plain.commandTorques(), fs.commandTorques()) < 1e-9 &&
                   testutil::relErr(plain.nu(), fs.nu()) < 1e-9),
                  "trial " << str(trial) << ": affine update differs from a solve with the friction torques");
    CHECK_MESSAGE(testutil::relErr(plain.linkAccelerations(), fs.linkAccelerations()) < 1e-9,
                  "trial " << str(trial) << ": link accelerations at the optimum differ");
    // Complementarity and kinetic friction.
    const double acc_scale = std::max(1.0, fs.qdd().cwiseAbs().maxCoeff());
    for (int jj = 0; jj < n; ++jj) {
      const double fr = fs.frictionTorques()(jj), f_s = fm.static_friction(jj), acc = fs.qdd()(jj);
      const auto st = fs.status()[jj];
      if (std::abs(qd(jj)) > fm.velocity_tolerance) {
        CHECK_MESSAGE((st == vereshchagin::FrictionSolver::Moving &&
                       std::abs(fr + fm.kinetic_friction(jj) * (qd(jj) > 0 ? 1 : -1)) < 1e-12),
                      "trial " << str(trial) << ": moving joint gets -fk sign(qd)");
        continue;
      }
      CHECK_MESSAGE(std::abs(fr) <= f_s * (1 + 1e-12) + 1e-12,
                    "trial " << str(trial) << ": |friction| above breakaway");
      if (st == vereshchagin::FrictionSolver::Stick) {
        CHECK_MESSAGE(std::abs(acc) <= 1e-9 * acc_scale, "trial " << str(trial) << ": sticking joint accelerates");
      } else {
        CHECK_MESSAGE(std::abs(fr + f_s * (acc > 0 ? 1 : -1)) <= 1e-9 * std::max(1.0, f_s),
                      "trial " << str(trial) << ": slipping joint " << str(jj) << " friction " << str(fr)
                               << " does not oppose its acceleration " << str(acc) << " at full breakaway "
                               << str(f_s));
      }
    }
  }
  CHECK_MESSAGE(compared >= 250, "too few random trials solved: " << str(compared));
  MESSAGE(str(compared) << " random chains checked with KDL's FD and complementarity");
}
