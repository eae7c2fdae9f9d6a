// Letting a table carry part of the load: a planar 3-link arm stands still three ways, and the
// motors' effort is compared.
//   1. in free space, its tool held in x, z and pitch (3 task columns);
//   2. its tool held in x and z only, its elbow resting on a table: a support (the table pushes
//      up, never pulls; friction mu = 0.5) takes the rest of the gravity load;
//   3. its tool held in x only and pressing down on a second, frictionless surface with 5 N (a
//      normal-force set-point: the motors supply the press, the surface pushes back with exactly
//      5 N), the elbow resting as in 2.
// Each solve reports the contact forces (base axes, on the robot) and statuses; replaying the
// command torques and the contact forces through the dynamics gives the same accelerations.
//
// Usage: rest_on_table   (a built-in 3-link arm)
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Core>
#include <vereshchagin/data.hpp>
#include <vereshchagin/input.hpp>
#include <vereshchagin/model.hpp>
#include <vereshchagin/urdf_loader.hpp>

namespace {

// Three links of 1 kg and 0.4 m about y, y, y (a planar arm in x-z); the tool 0.1 m beyond the
// last one (fixed joint).
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
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="mount" type="fixed"><parent link="l3"/><child link="tool"/><origin xyz="0.1 0 0"/></joint>
</robot>)";

namespace vs = vereshchagin;

// A support or set-point at the origin of frame `name` (normal +z: the table pushes up).
vs::PointContact contactAt(const vs::Model& model, const char* name, double mu, double force) {
  vs::FrameRef frame;
  if (!model.findFrame(name, frame)) std::fprintf(stderr, "no frame named '%s'\n", name);
  vs::PointContact c;
  c.segment = frame.segment;
  c.point = vs::Vector3(frame.in_tip.p.x(), frame.in_tip.p.y(), frame.in_tip.p.z());
  c.normal = vs::Vector3::UnitZ();
  c.mu = mu;
  c.force = force;
  return c;
}

const char* statusName(vs::ContactStatus s) {
  return s == vs::ContactStatus::Sticking ? "sticking" : s == vs::ContactStatus::Sliding ? "sliding" : "separating";
}

// Solves and prints; returns the norm of the command torques (NaN on failure).
double report(const char* title, const vs::Model& model, vs::Data& data, const vs::SolveInput& input) {
  if (const vs::Status s = vs::solve(model, data, input); !s) {
    std::fprintf(stderr, "%s: %s\n", title, s.message());
    return std::numeric_limits<double>::quiet_NaN();
  }
  const Eigen::VectorXd& tau = data.commandTorques();
  std::printf("%-34s command torques [%7.3f %7.3f %7.3f] N m, |tau| %.3f\n", title, tau(0), tau(1), tau(2), tau.norm());
  for (Eigen::Index c = 0; c < data.contactForces().cols(); ++c)
    std::printf("    contact %ld: force [%7.3f %7.3f %7.3f] N, %s\n", static_cast<long>(c), data.contactForces()(0, c),
                data.contactForces()(1, c), data.contactForces()(2, c), statusName(data.contactStatus()[c]));
  return tau.norm();
}

}  // namespace

int main() {
  const vs::UrdfResult urdf = vs::chainFromUrdfString(kArm, "base", "tool");
  if (!urdf.ok) {
    std::fprintf(stderr, "URDF: %s\n", urdf.message.c_str());
    return 1;
  }
  const vs::Model model(urdf.robot);
  vs::Data data(model);
  vs::SolveInput input(model);
  // Shoulder down 0.6 rad, the forearm level, the hand down 0.6 rad: held in x and z at the tool,
  // the arm would rotate its elbow down onto the table.
  Eigen::VectorXd q(3), qd = Eigen::VectorXd::Zero(3);
  q << 0.6, -0.6, -0.6;  // rotations about y: positive turns x towards -z
  input.setState(vs::JointPositions(q), vs::JointVelocities(qd));
  vs::FrameRef tool;
  if (!model.findFrame("tool", tool)) return 1;
  Eigen::MatrixXd alfa = Eigen::MatrixXd::Zero(6, 3);  // unit forces along x and z, a unit moment about y
  alfa(0, 0) = alfa(2, 1) = alfa(4, 2) = 1.0;
  if (!input.addConstraint(tool, alfa, Eigen::VectorXd::Zero(3))) return 1;
  vs::ConstraintBlock& task = input.constraints[0];
  task.classical = true;  // set-points: zero classical acceleration (standing still)
  const double free = report("1. free space", model, data, input);

  task.columns = 2;  // x and z: the elbow would drop but for the table
  input.contacts.push_back(contactAt(model, "l2", 0.5, std::numeric_limits<double>::quiet_NaN()));
  const double resting = report("2. elbow on the table", model, data, input);
  const double elbow_force = data.contactForces()(2, 0);

  task.columns = 1;                                              // x only: the press holds the tool's height
  input.contacts.push_back(contactAt(model, "tool", 0.0, 5.0));  // frictionless (a pen on glossy paper)
  const double pressing = report("3. elbow resting, tool pressing 5 N", model, data, input);
  const double press = data.contactForces()(2, 1);

  const bool ok = resting < free && elbow_force > 0.0 && std::abs(press - 5.0) < 1e-9 && std::isfinite(pressing);
  std::printf("the table takes %.1f %% of the effort; the tool presses with %.3f N\n", 100.0 * (1.0 - resting / free),
              press);
  return ok ? 0 : 1;
}
