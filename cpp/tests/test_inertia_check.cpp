// SolverOptions::inertia_check and UrdfOptions::inertia_check (inertia_check.hpp):
//  * Physical rejects the KUKA LWR 4's identified parameters (kuka_lwr4.hpp) with a message naming
//    the option, and a positive semi-definite tensor that breaks the triangle inequality
//    (diag(0.1, 0.01, 0.01)); it accepts the extreme valid case (a thin rod, I1 + I2 = I3);
//  * JointSpace accepts the LWR 4: its forward dynamics equal KDL's ChainFdSolver_RNE, its
//    constrained solve KDL's dense formula, and static friction on it satisfies the stick/slip
//    complementarity with KDL forward dynamics reproducing qdd;
//  * a model whose joint-space inertia is positive definite at some configurations only: solves
//    there (against KDL's H) and fails elsewhere with E_DEGENERATE_INERTIA naming the joint;
//  * setOptions() switching the check rebuilds the model; the URDF loader's option likewise;
//  * parseInertiaCheck: the Python spelling of the option, anything else refused with a message.
#include <string>

#include <doctest/doctest.h>
#include <Eigen/LU>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>

#include "kuka_lwr4.hpp"
#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"
#include "vereshchagin/urdf_loader.hpp"

using testutil::relErr;
using testutil::str;
using Solver = vereshchagin::ChainHdSolver;
using Matrix6X = Solver::Matrix6X;

namespace {

bool contains(const char* text, const std::string& part) {
  return std::string(text).find(part) != std::string::npos;
}

vereshchagin::SolverOptions jointSpace() {
  vereshchagin::SolverOptions o;
  o.inertia_check = vereshchagin::InertiaCheck::JointSpace;
  return o;
}

const KDL::Twist kGravityUp(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());

TEST_CASE("KUKA LWR 4: physical check rejects it, joint-space check accepts it and matches KDL") {
  const KDL::Chain lwr = testutil::kukaLwr4();
  Solver physical(lwr, kGravityUp);
  CHECK_MESSAGE(
      (physical.modelError() == Solver::E_INVALID_MODEL && contains(physical.errorMessage(), "inertia_check") &&
       contains(physical.errorMessage(), "joint_space")),
      "LWR 4 under physical: E_INVALID_MODEL naming the option (" << std::string(physical.errorMessage()) << ")");
  Solver js(lwr, kGravityUp, jointSpace());
  CHECK_MESSAGE(js.modelError() == 0, "LWR 4 under joint_space accepted: " << std::string(js.errorMessage()));
  CHECK_MESSAGE((physical.setOptions(jointSpace()) == 0 && physical.modelError() == 0),
                "setOptions(joint_space) rebuilds");
  // Forward dynamics and a constrained solve at several states against KDL.
  double worst_fd = 0.0, worst_task = 0.0;
  for (int k = 0; k < 20; ++k) {
    testutil::RandomGen g(900 + k);
    const KDL::JntArray q = g.q(7), qd = g.qdot(7), ff = g.torques(7);
    const KDL::Wrenches fext = g.fext(7);
    const Matrix6X fe = testutil::toMatrix(fext);
    CHECK_MESSAGE(js.solve(q.data, qd.data, Matrix6X(6, 0), Eigen::VectorXd(0), fe, ff.data) == 0, "LWR FD solve");
    KDL::ChainFdSolver_RNE fd(lwr, KDL::Vector(0, 0, -9.81));
    KDL::JntArray qdd(7);
    fd.CartToJnt(q, qd, ff, testutil::toTipAxes(lwr, q, fext), qdd);
    worst_fd = std::max(worst_fd, relErr(js.qdd(), qdd.data));
    // Task: nu from K nu = a_free - beta, qdd = qdd_free - H^-1 A^T nu (A = alfa^T J).
    const Matrix6X alfa = g.alfa(3).data;
    const Eigen::VectorXd beta = g.beta(3).data;
    const testutil::DenseModel d = testutil::denseModel(lwr, q);
    if (!testutil::wellConditioned(testutil::couplingEigenvalues(d, alfa))) continue;
    CHECK_MESSAGE(js.solve(q.data, qd.data, alfa, beta, fe, ff.data) == 0, "LWR task solve");
    // alfa^T Xdd of the free arm, from KDL's own solver without constraints.
    KDL::ChainHdSolver_Vereshchagin kdl(lwr, kGravityUp, 0);
    KDL::JntArray qdd_k(7), tc(7), no_beta(0);
    kdl.CartToJnt(q, qd, qdd_k, KDL::Jacobian(0), no_beta, fext, ff, tc);
    std::vector<KDL::Twist> acc(8);
    kdl.getTransformedLinkAcceleration(acc);
    const Eigen::VectorXd a_free = alfa.transpose() * Eigen::VectorXd(testutil::toMatrix(acc).col(7));
    const Eigen::MatrixXd A = alfa.transpose() * d.J;
    const Eigen::MatrixXd HinvAt = d.H.lu().solve(A.transpose());
    const Eigen::VectorXd nu = (A * HinvAt).ldlt().solve(a_free - beta);
    worst_task = std::max({worst_task, relErr(js.nu(), nu), relErr(js.qdd(), qdd.data - HinvAt * nu)});
  }
  CHECK_MESSAGE(worst_fd <= 1e-9, "LWR joint_space FD vs KDL FD_RNE rel err " << str(worst_fd));
  CHECK_MESSAGE(worst_task <= 1e-9, "LWR joint_space task vs dense formula rel err " << str(worst_task));
  MESSAGE(testutil::format("LWR 4 (joint_space): FD vs KDL %.2e, task vs dense %.2e", worst_fd, worst_task));
}

// Static friction on the identified LWR 4 (the max-min needs G PSD: D_j > 0 makes it so).
TEST_CASE("KUKA LWR 4 with static friction: complementarity and KDL forward dynamics") {
  const KDL::Chain lwr = testutil::kukaLwr4();
  vereshchagin::FrictionSolver fs(lwr, kGravityUp, jointSpace());
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::Constant(7, 8.0);
  double worst = 0.0;
  for (int k = 0; k < 20; ++k) {
    testutil::RandomGen g(1900 + k);
    const KDL::JntArray q = g.q(7), ff = g.torques(7);
    const Eigen::VectorXd qd = Eigen::VectorXd::Zero(7);
    const Matrix6X alfa = g.alfa(2).data;
    const Eigen::VectorXd beta = g.beta(2).data;
    if (!CHECK_MESSAGE(fs.solve(q.data, qd, alfa, beta, Matrix6X(6, 0), ff.data, fm) == 0,
                       "LWR friction solve " << str(k) << ": " << fs.errorMessage()))
      continue;
    KDL::ChainFdSolver_RNE fd(lwr, KDL::Vector(0, 0, -9.81));
    KDL::JntArray tau(7), qdd(7), qdv(7);
    tau.data = ff.data + fs.commandTorques() + fs.frictionTorques();
    fd.CartToJnt(q, qdv, tau, KDL::Wrenches(7, KDL::Wrench::Zero()), qdd);
    worst = std::max(worst, relErr(qdd.data, fs.qdd()));
    const double scale = std::max(1.0, fs.qdd().cwiseAbs().maxCoeff());
    for (int j = 0; j < 7; ++j) {
      const double f = fs.frictionTorques()(j), a = fs.qdd()(j);
      const bool stick = std::abs(a) <= 1e-8 * scale && std::abs(f) <= 8.0 * (1 + 1e-12);
      const bool slip = std::abs(std::abs(f) - 8.0) <= 1e-10 * 8.0 && f * a <= 0.0;
      CHECK_MESSAGE((stick || slip), "LWR friction " << str(k) << " joint " << str(j) << ": neither stick nor slip");
    }
  }
  CHECK_MESSAGE(worst <= 1e-9, "LWR friction: KDL FD with ff + command + friction rel err " << str(worst));
  MESSAGE(testutil::format("LWR 4 friction (joint_space): FD reproduction %.2e", worst));
}

KDL::Chain oneBody(const KDL::RotationalInertia& I_com) {
  KDL::Chain ch;
  ch.addSegment(KDL::Segment("body", KDL::Joint("j", KDL::Joint::RotZ), KDL::Frame(KDL::Vector(0.2, 0, 0)),
                             KDL::RigidBodyInertia(1.0, KDL::Vector(-0.1, 0, 0), I_com)));
  return ch;
}

TEST_CASE("triangle inequality: a broken PSD tensor is rejected and a thin rod accepted") {
  Solver bad(oneBody(KDL::RotationalInertia(0.1, 0.01, 0.01)), KDL::Twist::Zero());
  CHECK_MESSAGE((bad.modelError() == Solver::E_INVALID_MODEL && contains(bad.errorMessage(), "triangle") &&
                 contains(bad.errorMessage(), "joint_space")),
                "diag(0.1, 0.01, 0.01) rejected (" << std::string(bad.errorMessage()) << ")");
  Solver rod(oneBody(KDL::RotationalInertia(0.0, 0.02, 0.02)), KDL::Twist::Zero());
  CHECK_MESSAGE(rod.modelError() == 0, "thin rod diag(0, 0.02, 0.02) accepted: " << std::string(rod.errorMessage()));
  Solver js(oneBody(KDL::RotationalInertia(0.1, 0.01, 0.01)), KDL::Twist::Zero(), jointSpace());
  CHECK_MESSAGE(js.modelError() == 0, "diag(0.1, 0.01, 0.01) accepted under joint_space");
}

// Two RotZ links in a plane; link 1 has inertia -0.5 kg m^2 about its joint, link 2 is 1 kg at
// 0.5 m with 0.1 kg m^2 about its centre: det H = 0.35 (J1 + 1) - 0.25 cos^2 q2 with J1 = -0.5, so
// H is positive definite for |cos q2| < 0.837 and indefinite near q2 = 0.
KDL::Chain partlyDefinite() {
  KDL::Chain ch;
  ch.addSegment(
      KDL::Segment("l1", KDL::Joint("shoulder", KDL::Joint::RotZ), KDL::Frame(KDL::Vector(1, 0, 0)),
                   KDL::RigidBodyInertia(1.0, KDL::Vector(-0.5, 0, 0), KDL::RotationalInertia(0.01, 0.01, -0.75))));
  ch.addSegment(
      KDL::Segment("l2", KDL::Joint("elbow", KDL::Joint::RotZ), KDL::Frame(KDL::Vector(1, 0, 0)),
                   KDL::RigidBodyInertia(1.0, KDL::Vector(-0.5, 0, 0), KDL::RotationalInertia(0.01, 0.01, 0.1))));
  return ch;
}

TEST_CASE("joint-space inertia positive definite at some configurations only") {
  const KDL::Chain ch = partlyDefinite();
  Solver s(ch, KDL::Twist::Zero(), jointSpace());
  CHECK_MESSAGE(s.modelError() == 0, "partly definite model accepted: " << std::string(s.errorMessage()));
  Eigen::VectorXd q(2), qd = Eigen::VectorXd::Zero(2), tau(2);
  q << 0.3, M_PI / 2;
  tau << 1.0, -0.5;
  CHECK_MESSAGE(s.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X(6, 0), tau) == 0, "solves at q2 = pi/2");
  KDL::JntArray qk(2);
  qk.data = q;
  const testutil::DenseModel d = testutil::denseModel(ch, qk);
  const double e = relErr(s.qdd(), d.H.lu().solve(tau));
  CHECK_MESSAGE(e <= 1e-12, "q2 = pi/2: qdd vs H^-1 tau (KDL's H) rel err " << str(e));
  q(1) = 0.0;
  const int rc = s.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X(6, 0), tau);
  CHECK_MESSAGE((rc == Solver::E_DEGENERATE_INERTIA && contains(s.errorMessage(), "'shoulder'") &&
                 contains(s.errorMessage(), "not positive definite")),
                "q2 = 0: E_DEGENERATE_INERTIA naming the joint (rc " << str(rc) << ": " << s.errorMessage() << ")");
  CHECK_MESSAGE(s.qdd().allFinite(), "no NaN left in the outputs");
}

const char* kUrdf = R"(<robot name="r">
  <link name="base"/>
  <link name="a"><inertial><mass value="1.0"/><origin xyz="0.1 0 0"/>
    <inertia ixx="IXX" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>)";

TEST_CASE("URDF loader option: physical and joint-space checks") {
  const auto with = [](const std::string& ixx) {
    std::string x = kUrdf;
    x.replace(x.find("IXX"), 3, ixx);
    return x;
  };
  vereshchagin::UrdfOptions js;
  js.inertia_check = vereshchagin::InertiaCheck::JointSpace;
  for (const char* ixx : {"-0.5", "0.1"}) {
    const auto phys = vereshchagin::chainFromUrdfString(with(ixx));
    CHECK_MESSAGE((!phys.ok && contains(phys.message.c_str(), "'a'") && contains(phys.message.c_str(), "joint_space")),
                  std::string("URDF ixx = ") << ixx << " rejected under physical naming the option: " << phys.message);
    const auto ok = vereshchagin::chainFromUrdfString(with(ixx), "", "", js);
    CHECK_MESSAGE(ok.ok, std::string("URDF ixx = ") << ixx << " accepted under joint_space: " << ok.message);
  }
  CHECK_MESSAGE(contains(vereshchagin::chainFromUrdfString(with("0.1")).message.c_str(), "triangle"),
                "URDF triangle message");
  CHECK_MESSAGE(vereshchagin::chainFromUrdfString(with("0.02")).ok, "URDF valid inertia accepted");
}

}  // namespace

TEST_CASE("parseInertiaCheck: the two spellings, anything else refused") {
  vereshchagin::InertiaCheck c = vereshchagin::InertiaCheck::Physical;
  CHECK(vereshchagin::parseInertiaCheck("joint_space", c).ok());
  CHECK(c == vereshchagin::InertiaCheck::JointSpace);
  CHECK(vereshchagin::parseInertiaCheck("physical", c).ok());
  CHECK(c == vereshchagin::InertiaCheck::Physical);
  const vereshchagin::Status s = vereshchagin::parseInertiaCheck("Physical", c);
  CHECK(s.code() == vereshchagin::Error::InvalidOptions);
  CHECK(std::string(s.message()).find("inertia_check must be 'physical'") == 0);
  CHECK(c == vereshchagin::InertiaCheck::Physical);
}
