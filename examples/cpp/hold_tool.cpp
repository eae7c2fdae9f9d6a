// Load a robot from URDF, hold its tool's height with the plain solver, then let static joint
// friction hold the whole tool with the friction-aware solver and watch the motor command vanish.
//
// Usage: hold_tool [robot.urdf root_link tip_link]   (default: a built-in two-link arm)
#include <cstdio>
#include <string>

#include <Eigen/Core>
#include <vereshchagin/chain_hd_solver.hpp>
#include <vereshchagin/friction_solver.hpp>
#include <vereshchagin/urdf_loader.hpp>

namespace {

// Two links of 1 kg and 0.5 m swinging about y, the tool frame at the end of the second.
const char* kTwoLinkArm = R"(<robot name="two_link">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.25 0 0"/><mass value="1"/>
    <inertia ixx="0.001" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="lower"><inertial><origin xyz="0.25 0 0"/><mass value="1"/>
    <inertia ixx="0.001" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
  <joint name="tool_mount" type="fixed"><parent link="lower"/><child link="tool"/><origin xyz="0.5 0 0"/></joint>
</robot>)";

void print(const char* what, const Eigen::VectorXd& v) {
  std::printf("  %-22s", what);
  for (Eigen::Index i = 0; i < v.size(); ++i) std::printf(" %9.4f", v(i));
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const vereshchagin::UrdfResult urdf = argc >= 4 ? vereshchagin::chainFromUrdfFile(argv[1], argv[2], argv[3])
                                                  : vereshchagin::chainFromUrdfString(kTwoLinkArm, "base", "tool");
  if (!urdf.ok) {
    std::fprintf(stderr, "URDF: %s\n", urdf.message.c_str());
    return 1;
  }
  const KDL::Chain& chain = urdf.robot.chain;
  const int n = static_cast<int>(chain.getNrOfJoints());
  std::printf("%d joints, %u segments, base frame '%s'\n", n, chain.getNrOfSegments(), urdf.robot.root_link.c_str());
  for (const std::string& note : urdf.robot.notes) std::printf("note: %s\n", note.c_str());

  // Gravity enters as an upward acceleration of the base (KDL's convention).
  const KDL::Twist root_acc(KDL::Vector(0.0, 0.0, 9.81), KDL::Vector::Zero());
  Eigen::VectorXd q = Eigen::VectorXd::Constant(n, 0.3), qd = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd ff = Eigen::VectorXd::Zero(n);
  const vereshchagin::ChainHdSolver::Matrix6X no_wrenches(6, 0);  // empty: no external wrenches

  // 1. Hold the tool's height: one unit force along base z; beta = +9.81 (the base's upward
  //    acceleration) means zero classical vertical acceleration of the tool.
  vereshchagin::ChainHdSolver solver(chain, root_acc);
  vereshchagin::ChainHdSolver::Matrix6X alfa = vereshchagin::ChainHdSolver::Matrix6X::Zero(6, 1);
  alfa(2, 0) = 1.0;
  Eigen::VectorXd beta(1);
  beta << 9.81;
  if (solver.solve(q, qd, alfa, beta, no_wrenches, ff) != 0) {
    std::fprintf(stderr, "solve: %s\n", solver.errorMessage());
    return 1;
  }
  std::printf("tool height held (m = 1), rank %d:\n", solver.constraintRank());
  print("qdd [rad/s^2]", solver.qdd());
  print("tau_command [N m]", solver.commandTorques());
  std::printf("  tool acceleration z    %9.4f m/s^2 (incl. the base's +9.81)\n", solver.linkAccelerations()(2, n));

  // 2. Hold the whole tool still (m = 6) with breakaway friction on every joint: the motors
  //    supply only what friction cannot.
  const vereshchagin::ChainHdSolver::Matrix6X hold = vereshchagin::ChainHdSolver::Matrix6X::Identity(6, 6);
  Eigen::VectorXd hold_beta = Eigen::VectorXd::Zero(6);
  hold_beta(2) = 9.81;
  vereshchagin::FrictionSolver friction_solver(chain, root_acc);
  vereshchagin::FrictionModel friction;
  for (double f : {0.0, 2.0, 5.0, 10.0}) {
    friction.static_friction = Eigen::VectorXd::Constant(n, f);
    if (friction_solver.solve(q, qd, hold, hold_beta, no_wrenches, ff, friction) != 0) {
      std::fprintf(stderr, "friction solve: %s\n", friction_solver.errorMessage());
      return 1;
    }
    std::printf("tool held still, breakaway friction %4.1f N m on every joint (rank %d):\n", f,
                friction_solver.constraintRank());
    print("tau_command [N m]", friction_solver.commandTorques());
    print("friction torque [N m]", friction_solver.frictionTorques());
  }
  return 0;
}
