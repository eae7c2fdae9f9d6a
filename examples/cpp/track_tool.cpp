// A real-time loop on the (model, data, input) API: a Model loaded once from URDF, a Data and a
// SolveInput filled in place every step (no allocation), the tool frame found by name (a link
// merged into its segment by a fixed joint, with its offset), its classical acceleration set
// directly (solve() adds gravity and -w x v itself), and the tool's pose and twist read back from
// the solve's own sweeps.
//
// Usage: track_tool [robot.urdf root_link tip_link tool_frame]   (default: a built-in 3-link arm)
#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Core>
#include <vereshchagin/data.hpp>
#include <vereshchagin/input.hpp>
#include <vereshchagin/model.hpp>
#include <vereshchagin/urdf_loader.hpp>

namespace {

// Three links of 1 kg and 0.4 m about y, z, y; the tool 0.1 m beyond the last one (fixed joint).
const char* kArm = R"(<robot name="arm3">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.001" iyy="0.015" izz="0.015" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.001" iyy="0.015" izz="0.015" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l3"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.001" iyy="0.015" izz="0.015" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 1 0"/></joint>
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/><origin xyz="0.4 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="mount" type="fixed"><parent link="l3"/><child link="tool"/><origin xyz="0.5 0 0"/></joint>
</robot>)";

}  // namespace

int main(int argc, char** argv) {
  namespace vs = vereshchagin;
  const vs::UrdfResult urdf =
      argc >= 5 ? vs::chainFromUrdfFile(argv[1], argv[2], argv[3]) : vs::chainFromUrdfString(kArm, "base", "tool");
  const std::string tool_name = argc >= 5 ? argv[4] : "tool";
  if (!urdf.ok) {
    std::fprintf(stderr, "URDF: %s\n", urdf.message.c_str());
    return 1;
  }
  const vs::Model model(urdf.robot);  // immutable; share it between threads
  if (const vs::Status s = model.status(); !s) {
    std::fprintf(stderr, "model: %s\n", s.message());
    return 1;
  }
  vs::FrameRef tool;
  if (!model.findFrame(tool_name, tool)) {
    std::fprintf(stderr, "no frame named '%s'\n", tool_name.c_str());
    return 1;
  }
  const int n = static_cast<int>(model.nrOfJoints());
  vs::Data data(model);                          // one per thread: workspace and results
  vs::SolveInput input(model);                   // everything one solve reads, refilled every step
  input.gravity = KDL::Vector(0.0, 0.0, -9.81);  // physical gravity, base axes

  // The tool's linear acceleration is constrained (3 columns: unit forces along base x, y, z at
  // the tool frame); its orientation is left free. A PD law on the position gives the classical
  // acceleration set-point.
  Eigen::MatrixXd alfa = Eigen::MatrixXd::Zero(6, 3);
  alfa.topRows(3).setIdentity();
  if (const vs::Status s = input.addConstraint(tool, alfa, Eigen::VectorXd::Zero(3)); !s) {
    std::fprintf(stderr, "constraint: %s\n", s.message());
    return 1;
  }
  vs::ConstraintBlock& task = input.constraints[0];
  task.classical = true;  // beta from classical_acceleration, inside the solve

  Eigen::VectorXd q = Eigen::VectorXd::Constant(n, 0.4), qd = Eigen::VectorXd::Zero(n);
  q(n - 1) = 1.2;  // elbow bent: away from the stretched (singular) pose
  input.setState(vs::JointPositions(q), vs::JointVelocities(qd));
  if (const vs::Status s = vs::solve(model, data, input); !s) {
    std::fprintf(stderr, "solve: %s\n", s.message());
    return 1;
  }
  const KDL::Vector start = data.framePose(tool).p;
  const KDL::Vector goal = start + KDL::Vector(0.0, 0.05, -0.05);
  const double dt = 1e-3, kp = 100.0, kd = 20.0;
  std::printf("%d joints; frame '%s' on segment %d, %.3f m from its tip\n", n, tool_name.c_str(), tool.segment,
              tool.in_tip.p.Norm());
  for (int step = 0; step <= 1000; ++step) {
    input.setState(vs::JointPositions(q), vs::JointVelocities(qd));
    const KDL::Vector p = data.framePose(tool).p;  // at the previous solve's state
    const KDL::Vector v = data.frameTwist(tool).vel;
    const KDL::Vector a = kp * (goal - p) - kd * v;
    task.classical_acceleration << a.x(), a.y(), a.z(), 0.0, 0.0, 0.0;
    if (const vs::Status s = vs::solve(model, data, input); !s) {
      std::fprintf(stderr, "step %d: %s\n", step, s.message());
      return 1;
    }
    if (step % 250 == 0)
      std::printf("t = %.2f s  tool error %.2e m  command torques [%8.3f %8.3f %8.3f] N m\n", step * dt,
                  (goal - p).Norm(), data.commandTorques()(0), data.commandTorques()(1), data.commandTorques()(2));
    qd += dt * data.qdd();  // semi-implicit Euler
    q += dt * qd;
  }
  const double error = (goal - data.framePose(tool).p).Norm();
  std::printf("final tool error %.2e m\n", error);
  return error < 1e-3 ? 0 : 1;
}
