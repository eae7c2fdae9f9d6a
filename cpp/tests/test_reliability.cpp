// Reliability of the C++ entry points beyond argument checks (issue 7):
//  * invalid segment geometry (NaN / Inf tip frame, non-orthonormal or reflecting rotation, NaN
//    joint origin) is E_INVALID_MODEL naming the segment;
//  * finite inputs whose results overflow (|q_dot| = 1e160, ff_torques = 1e308, beta = 1e308)
//    are E_NONFINITE_RESULT, never a success with Inf/NaN; the solver stays usable;
//  * FrictionSolver messages name the FrictionModel field; huge static friction (1e300) holds a
//    resting arm exactly (no overflow, qdd = 0, |friction| <= static);
//  * extreme but valid scales: masses 1e-6..1e4 kg and lengths 1e-4..1e2 m (every combination)
//    give finite outputs, full constraint rank with the task met, and command torques that
//    reproduce qdd through unconstrained forward dynamics to 1e-8 relative;
//  * determinism: two instances and repeated calls give bit-identical outputs.
#include <cmath>
#include <string>

#include <doctest/doctest.h>

#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"

using testutil::str;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using Solver = vereshchagin::ChainHdSolver;
using vereshchagin::FrictionSolver;

namespace {

const KDL::Twist kGrav(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());

// n revolute joints alternating y / z axes, links of `length` along x, masses `mass`.
KDL::Chain scaledArm(int n, double mass, double length) {
  KDL::Chain ch;
  for (int i = 0; i < n; ++i) {
    const double r = 0.1 * length;  // slender rod: inertia about the centre m (3 r^2 + L^2) / 12
    const double Ia = mass * r * r / 2, Ib = mass * (3 * r * r + length * length) / 12;
    ch.addSegment(
        KDL::Segment("s" + str(i), KDL::Joint("j" + str(i), i % 2 ? KDL::Joint::RotZ : KDL::Joint::RotY),
                     KDL::Frame(KDL::Rotation::RPY(0.3, 0.0, 0.0), KDL::Vector(length, 0, 0)),
                     KDL::RigidBodyInertia(mass, KDL::Vector(-length / 2, 0, 0), KDL::RotationalInertia(Ia, Ib, Ib))));
  }
  return ch;
}

bool allFinite(const Solver& s) {
  return s.qdd().allFinite() && s.commandTorques().allFinite() && s.nu().allFinite() &&
         s.linkAccelerations().allFinite();
}

}  // namespace

TEST_CASE("invalid segment geometry is E_INVALID_MODEL naming the segment") {
  const KDL::RigidBodyInertia body(1.0, KDL::Vector(0.1, 0, 0), KDL::RotationalInertia(0.1, 0.1, 0.1));
  KDL::Frame nan_tip(KDL::Vector(NAN, 0, 0));
  KDL::Frame inf_rot;
  inf_rot.M = KDL::Rotation(INFINITY, 0, 0, 0, 1, 0, 0, 0, 1);
  KDL::Frame skewed;
  skewed.M = KDL::Rotation(1, 0.1, 0, 0, 1, 0, 0, 0, 1);
  KDL::Frame reflect;
  reflect.M = KDL::Rotation(1, 0, 0, 0, 1, 0, 0, 0, -1);
  struct Case {
    std::string what;
    KDL::Segment seg;
  };
  const Case cases[] = {
      {"NaN tip position", KDL::Segment("bad", KDL::Joint("jb", KDL::Joint::RotZ), nan_tip, body)},
      {"Inf in tip rotation", KDL::Segment("bad", KDL::Joint("jb", KDL::Joint::RotZ), inf_rot, body)},
      {"non-orthonormal tip rotation", KDL::Segment("bad", KDL::Joint("jb", KDL::Joint::RotZ), skewed, body)},
      {"reflecting tip rotation", KDL::Segment("bad", KDL::Joint("jb", KDL::Joint::RotZ), reflect, body)},
      {"NaN joint origin",
       KDL::Segment("bad", KDL::Joint("jb", KDL::Vector(NAN, 0, 0), KDL::Vector(0, 0, 1), KDL::Joint::RotAxis),
                    KDL::Frame::Identity(), body)},
  };
  for (const Case& c : cases) {
    KDL::Chain ch = scaledArm(2, 1.0, 0.5);
    ch.addSegment(c.seg);
    Solver s(ch, kGrav);
    const std::string msg = s.errorMessage();
    CHECK_MESSAGE(s.modelError() == Solver::E_INVALID_MODEL, c.what << ": modelError " << str(s.modelError()));
    CHECK_MESSAGE(msg.find("segment 2 ('bad')") != std::string::npos,
                  c.what << ": message does not name the segment: " << msg);
    const Eigen::VectorXd z = Eigen::VectorXd::Zero(3);
    CHECK_MESSAGE(s.solve(z, z, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X(6, 0), z) == Solver::E_INVALID_MODEL,
                  c.what << ": solve does not refuse");
  }
}

TEST_CASE("finite inputs whose results overflow are E_NONFINITE_RESULT and the solver stays usable") {
  const KDL::Chain ch = scaledArm(4, 1.0, 0.5);
  Solver s(ch, kGrav);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(4, 0.2, 1.1), z = Eigen::VectorXd::Zero(4);
  Matrix6X alfa = Matrix6X::Zero(6, 1);
  alfa(2, 0) = 1.0;
  const Eigen::VectorXd beta0 = Eigen::VectorXd::Constant(1, 1.0);
  CHECK_MESSAGE((s.solve(q, z, alfa, beta0, Matrix6X(6, 0), z) == 0 && allFinite(s)), "valid solve");
  const Eigen::VectorXd qdd_ok = s.qdd();
  struct Huge {
    std::string what;
    Eigen::VectorXd qd, ff, beta;
  };
  const Huge cases[] = {{"q_dot 1e160", Eigen::VectorXd::Constant(4, 1e160), z, beta0},
                        {"ff_torques 1e308", z, Eigen::VectorXd::Constant(4, 1e308), beta0},
                        {"beta 1e308", z, z, Eigen::VectorXd::Constant(1, 1e308)}};
  for (const Huge& h : cases) {
    const int rc = s.solve(q, h.qd, alfa, h.beta, Matrix6X(6, 0), h.ff);
    CHECK_MESSAGE(rc == Solver::E_NONFINITE_RESULT, h.what << ": expected E_NONFINITE_RESULT, got " << str(rc));
    CHECK_MESSAGE(std::string(s.errorMessage()).find("overflow") != std::string::npos,
                  h.what << ": message " << s.errorMessage());
    Eigen::MatrixXd a(4, 1), b(4, 1);
    Eigen::VectorXi j(1);
    j << 0;
    CHECK_MESSAGE(s.responseColumns(j, a, b) == Solver::E_NO_SOLUTION, h.what << ": responseColumns after overflow");
  }
  CHECK_MESSAGE((s.solve(q, z, alfa, beta0, Matrix6X(6, 0), z) == 0 && s.qdd() == qdd_ok),
                "solver unusable after overflow");
  CHECK_MESSAGE(std::string(s.strError(Solver::E_NONFINITE_RESULT)) != s.strError(123456),
                "E_NONFINITE_RESULT has no description");
}

TEST_CASE("FrictionSolver messages name the field and huge static friction holds a resting arm") {
  const KDL::Chain ch = scaledArm(3, 1.0, 0.5);
  FrictionSolver fs(ch, kGrav);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(3, 0.4, 1.0), z = Eigen::VectorXd::Zero(3);
  vereshchagin::FrictionModel fm;
  auto msgFor = [&](const vereshchagin::FrictionModel& m) {
    const int rc = fs.solve(q, z, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X(6, 0), z, m);
    return rc == FrictionSolver::E_INVALID_FRICTION ? std::string(fs.errorMessage()) : "rc " + str(rc);
  };
  fm.static_friction = Eigen::VectorXd::Ones(3);
  fm.kinetic_friction = Eigen::VectorXd::Constant(3, 2.0);
  CHECK_MESSAGE(msgFor(fm).find("kinetic_friction(0)") != std::string::npos, "kinetic > static: " << msgFor(fm));
  fm.kinetic_friction.resize(0);
  fm.static_friction(1) = -1.0;
  CHECK_MESSAGE(msgFor(fm).find("static_friction(1)") != std::string::npos, "negative static: " << msgFor(fm));
  fm.static_friction(1) = 1.0;
  fm.velocity_tolerance = NAN;
  CHECK_MESSAGE(msgFor(fm).find("velocity_tolerance") != std::string::npos, "NaN velocity tolerance: " << msgFor(fm));
  fm.velocity_tolerance = 1e-6;
  fm.lower = Eigen::VectorXd::Ones(3);
  fm.upper = Eigen::VectorXd::Zero(3);
  CHECK_MESSAGE(msgFor(fm).find("friction.lower(0)") != std::string::npos, "lower > upper: " << msgFor(fm));
  fm.lower.resize(0);
  fm.upper.resize(0);
  // Huge and zero friction on a resting arm under gravity.
  for (double f : {0.0, 1e3, 1e9, 1e300}) {
    fm.static_friction = Eigen::VectorXd::Constant(3, f);
    const int rc = fs.solve(q, z, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X(6, 0), z, fm);
    const bool finite = fs.qdd().allFinite() && fs.frictionTorques().allFinite() && fs.commandTorques().allFinite();
    CHECK_MESSAGE((rc == 0 && finite), "static friction " << str(f) << ": rc " << str(rc) << " " << fs.errorMessage());
    if (f >= 1e3) {
      CHECK_MESSAGE(fs.qdd().cwiseAbs().maxCoeff() <= 1e-9,
                    "static friction " << str(f) << " does not hold the arm: qdd " << testutil::mat(fs.qdd()));
    } else {
      CHECK_MESSAGE(fs.qdd().cwiseAbs().maxCoeff() > 1e-3, "zero friction holds the arm");
    }
    CHECK_MESSAGE((fs.frictionTorques().cwiseAbs().array() <= f).all(), "friction torque above its bound");
  }
}

TEST_CASE("chains without moving joints solve, with and without friction") {
  // Regression: FrictionSolver::solve took the maximum of an empty vector (a crash found by the
  // fuzz corpus replay).
  KDL::Chain fixed_only;
  fixed_only.addSegment(KDL::Segment("base_plate", KDL::Joint(KDL::Joint::Fixed), KDL::Frame(KDL::Vector(0, 0, 0.1)),
                                     KDL::RigidBodyInertia(1.0)));
  for (const KDL::Chain& ch : {KDL::Chain(), fixed_only}) {
    const std::string tag = ch.getNrOfSegments() ? "fixed-only chain" : "empty chain";
    const Eigen::VectorXd none(0);
    Solver s(ch, kGrav);
    CHECK_MESSAGE((s.solve(none, none, Matrix6X(6, 0), none, Matrix6X(6, 0), none) == 0 && allFinite(s)),
                  tag << ": solve");
    FrictionSolver fs(ch, kGrav);
    vereshchagin::FrictionModel fm;
    fm.static_friction = none;
    const int rc = fs.solve(none, none, Matrix6X(6, 0), none, Matrix6X(6, 0), none, fm);
    CHECK_MESSAGE((rc == 0 && fs.qdd().size() == 0 && std::isfinite(fs.gaussValue())),
                  tag << ": friction solve rc " << str(rc));
    Matrix6X alfa = Matrix6X::Zero(6, 1);
    alfa(2, 0) = 1.0;
    CHECK_MESSAGE((fs.solve(none, none, alfa, Eigen::VectorXd::Ones(1), Matrix6X(6, 0), none, fm) == 0 &&
                   fs.linkAccelerations().allFinite()),
                  tag << ": friction solve with a constraint");
  }
}

TEST_CASE("masses 1e-6..1e4 kg and lengths 1e-4..1e2 m: finite, full rank, FD-consistent, deterministic") {
  int scale_cases = 0;
  for (double mass : {1e-6, 1e-2, 1.0, 1e4}) {
    for (double length : {1e-4, 1e-2, 1.0, 1e2}) {
      ++scale_cases;
      const KDL::Chain ch = scaledArm(6, mass, length);
      const std::string tag = "mass " + str(mass) + ", length " + str(length);
      Solver s(ch, kGrav), free(ch, kGrav);
      const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(6, 0.3, -1.2), qd = Eigen::VectorXd::LinSpaced(6, 0.5, -0.5);
      const Eigen::VectorXd ff = Eigen::VectorXd::LinSpaced(6, 1.0, -1.0) * mass * length * length;
      Matrix6X alfa = Matrix6X::Zero(6, 2);
      alfa(2, 0) = 1.0;
      alfa(4, 1) = 1.0;
      const Eigen::Vector2d beta(9.81, 0.0);
      int rc = s.solve(q, qd, alfa, beta, Matrix6X(6, 0), ff);
      if (!CHECK_MESSAGE((rc == 0 && allFinite(s)), tag << ": rc " << str(rc) << " " << s.errorMessage())) continue;
      // Both constraints are independent at every scale (regression: the truncation scale kappa
      // mixed N and N m and dropped the linear constraint at lengths 1e-4).
      CHECK_MESSAGE(s.constraintRank() == 2, tag << ": constraint rank " << str(s.constraintRank()) << ", expected 2");
      const Eigen::Vector2d met(s.linkAccelerations()(2, 6), s.linkAccelerations()(4, 6));
      CHECK_MESSAGE(testutil::relErr(met, beta) <= 1e-8, tag << ": task not met: " << testutil::mat(met));
      rc = free.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X(6, 0), ff + s.commandTorques());
      CHECK_MESSAGE((rc == 0 && testutil::relErr(free.qdd(), s.qdd()) <= 1e-8),
                    tag << ": command torques do not reproduce qdd: " << testutil::mat(free.qdd()) << " vs "
                        << testutil::mat(s.qdd()));
      // Determinism: another instance and a repeated call, bit for bit.
      Solver again(ch, kGrav);
      again.solve(q, qd, alfa, beta, Matrix6X(6, 0), ff);
      s.solve(q, qd, alfa, beta, Matrix6X(6, 0), ff);
      CHECK_MESSAGE((again.qdd() == s.qdd() && again.nu() == s.nu() && again.commandTorques() == s.commandTorques() &&
                     again.linkAccelerations() == s.linkAccelerations()),
                    tag << ": not bit-identical across instances");
    }
  }
  MESSAGE(scale_cases << " scale combinations");
}
