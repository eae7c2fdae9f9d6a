// C++ URDF loader: structure of the chain, merged inertias and errors, on hand-written URDFs.
// Expected values come from hand composition of the URDF's transforms and KDL's inertia algebra.
#include <cmath>
#include <cstdio>
#include <string>

#include <kdl/chainfksolverpos_recursive.hpp>

#include <doctest/doctest.h>

#include "test_common.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace {

using testutil::near;
using testutil::nearFrame;

const char* kArm = R"(<robot name="arm">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3" rpy="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2.5" effort="40" velocity="1.5"/>
    <dynamics damping="0.3" friction="1.2"/>
  </joint>
  <link name="l1">
    <inertial><origin xyz="0 0 0.1" rpy="0.1 0 0"/><mass value="2"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="f1" type="fixed">
    <parent link="l1"/><child link="l1b"/><origin xyz="0.1 0 0.2" rpy="0 0.3 0"/>
  </joint>
  <link name="l1b">
    <inertial><origin xyz="0.05 0 0"/><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial>
  </link>
  <joint name="j2" type="prismatic">
    <parent link="l1b"/><child link="l2"/>
    <origin xyz="0 0.1 0"/><axis xyz="1 1 0"/>
    <limit lower="0" upper="0.4" effort="100" velocity="0.5"/>
  </joint>
  <link name="l2">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="l2"/><child link="tool"/><origin xyz="0 0 0.15"/>
  </joint>
  <link name="tool">
    <inertial><mass value="0.25"/><inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.0001"/></inertial>
  </link>
</robot>)";

KDL::RigidBodyInertia diagInertia(double m, const KDL::Vector& c, double ixx, double iyy, double izz) {
  return KDL::RigidBodyInertia(m, c, KDL::RotationalInertia(ixx, iyy, izz, 0, 0, 0));
}

TEST_CASE("arm URDF: segments, joint metadata, forward kinematics and merged inertias") {
  const vereshchagin::UrdfResult r = vereshchagin::chainFromUrdfString(kArm);
  REQUIRE_MESSAGE(r.ok, "arm loads: " << r.message);
  const KDL::Chain& ch = r.robot.chain;
  CHECK_MESSAGE((ch.getNrOfSegments() == 2 && ch.getNrOfJoints() == 2), "two moving joints -> two segments");
  CHECK_MESSAGE((ch.getSegment(0).getName() == "l1b" && ch.getSegment(1).getName() == "tool"),
                "segments are named after their tip links");
  CHECK_MESSAGE((r.robot.joints.size() == 2 && r.robot.joints[0].name == "j1" && r.robot.joints[1].type == "prismatic"),
                "joint metadata");
  CHECK_MESSAGE((near(r.robot.joints[0].lower, -2) && near(r.robot.joints[0].upper, 2.5) &&
                 near(r.robot.joints[0].effort_limit, 40) && near(r.robot.joints[0].velocity_limit, 1.5) &&
                 near(r.robot.joints[0].friction, 1.2) && near(r.robot.joints[0].damping, 0.3)),
                "limits, friction and damping of j1");

  // Forward kinematics at q = (0.7, 0.2) against hand composition of the URDF transforms.
  const double q1 = 0.7, q2 = 0.2;
  const KDL::Frame o1(KDL::Rotation::RPY(0, 0, 0.2), KDL::Vector(0, 0, 0.3));
  const KDL::Frame f1(KDL::Rotation::RPY(0, 0.3, 0), KDL::Vector(0.1, 0, 0.2));
  const KDL::Frame o2(KDL::Rotation::Identity(), KDL::Vector(0, 0.1, 0));
  const KDL::Vector ax2 = KDL::Vector(1, 1, 0) / std::sqrt(2.0);
  const KDL::Frame tool_in_l2(KDL::Vector(0, 0, 0.15));
  const KDL::Frame l1b = o1 * KDL::Frame(KDL::Rotation::RotZ(q1)) * f1;
  const KDL::Frame tool = l1b * o2 * KDL::Frame(ax2 * q2) * tool_in_l2;
  KDL::ChainFkSolverPos_recursive fk(ch);
  KDL::JntArray q(2);
  q(0) = q1;
  q(1) = q2;
  KDL::Frame got0, got1;
  fk.JntToCart(q, got0, 1);
  fk.JntToCart(q, got1, 2);
  CHECK_MESSAGE(nearFrame(got0, l1b), "segment 0 tip is link l1b");
  CHECK_MESSAGE(nearFrame(got1, tool), "segment 1 tip is the tool link");

  // Merged inertias, expressed in each segment's tip frame.
  const KDL::Frame in1(KDL::Rotation::RPY(0.1, 0, 0), KDL::Vector(0, 0, 0.1));
  KDL::RigidBodyInertia l1_in_l1 = in1 * diagInertia(2, KDL::Vector::Zero(), 0.02, 0.03, 0.01);
  const KDL::RigidBodyInertia l1b_own = diagInertia(0.5, KDL::Vector(0.05, 0, 0), 0.001, 0.002, 0.002);
  const KDL::RigidBodyInertia seg0 = f1.Inverse() * l1_in_l1 + l1b_own;
  const KDL::RigidBodyInertia got_seg0 = ch.getSegment(0).getInertia();
  bool same0 = near(got_seg0.getMass(), 2.5) && near(got_seg0.getMass(), seg0.getMass());
  for (int k = 0; k < 3; ++k) same0 = same0 && near(got_seg0.getCOG()(k), seg0.getCOG()(k));
  for (int k = 0; k < 9; ++k)
    same0 = same0 && near(got_seg0.getRotationalInertia().data[k], seg0.getRotationalInertia().data[k]);
  CHECK_MESSAGE(same0, "segment 0 inertia = l1 (moved into l1b's frame) + l1b");
  const KDL::RigidBodyInertia seg1 = tool_in_l2.Inverse() * diagInertia(1, KDL::Vector::Zero(), 0.01, 0.01, 0.01) +
                                     diagInertia(0.25, KDL::Vector::Zero(), 1e-4, 1e-4, 1e-4);
  const KDL::RigidBodyInertia got_seg1 = ch.getSegment(1).getInertia();
  bool same1 = near(got_seg1.getMass(), 1.25);
  for (int k = 0; k < 3; ++k) same1 = same1 && near(got_seg1.getCOG()(k), seg1.getCOG()(k));
  for (int k = 0; k < 9; ++k)
    same1 = same1 && near(got_seg1.getRotationalInertia().data[k], seg1.getRotationalInertia().data[k]);
  CHECK_MESSAGE(same1, "segment 1 inertia = l2 (moved into the tool frame) + tool");
}

void expectError(const std::string& xml, const std::string& root, const std::string& tip, const std::string& fragment,
                 const std::string& what) {
  const vereshchagin::UrdfResult r = vereshchagin::chainFromUrdfString(xml, root, tip);
  CHECK_MESSAGE((!r.ok && r.message.find(fragment) != std::string::npos),
                what << " (message: '" << r.message << "', expected to contain '" << fragment << "')");
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST_CASE("chainFromUrdf and treeFromUrdf tell XML text from a file path") {
  CHECK(vereshchagin::chainFromUrdf(kArm).ok);
  CHECK(vereshchagin::treeFromUrdf(kArm).ok);
  const vereshchagin::UrdfResult missing = vereshchagin::chainFromUrdf("/no/such/robot.urdf");
  CHECK_FALSE(missing.ok);
  CHECK(missing.message == "URDF source is neither XML text nor a readable file: '/no/such/robot.urdf'");
  CHECK(vereshchagin::treeFromUrdf("/no/such/robot.urdf").message == missing.message);
  const vereshchagin::UrdfTreeResult directory = vereshchagin::treeFromUrdf(".");
  CHECK_FALSE(directory.ok);
  CHECK(directory.message.find("is a directory") != std::string::npos);
}

TEST_CASE("malformed or unusable URDFs and missing files are refused with a message") {
  expectError("<robot name='x'><link name='a'>", "", "", "malformed URDF", "malformed XML");
  expectError(kArm, "nowhere", "", "root link 'nowhere' not found", "missing root");
  expectError(kArm, "", "nowhere", "tip link 'nowhere' not found", "missing tip");
  expectError(kArm, "l2", "l1", "is not below root", "tip above root");
  expectError(replaced(kArm, "type=\"prismatic\"", "type=\"floating\""), "", "", "floating",
              "floating joint on the path");
  expectError(replaced(kArm, "<mass value=\"0.5\"/>", "<mass value=\"-0.5\"/>"), "", "", "negative mass",
              "negative mass");
  expectError(replaced(kArm, "ixx=\"0.001\"", "ixx=\"-0.5\""), "", "", "not positive semi-definite",
              "indefinite inertia");
  expectError(replaced(kArm, "<mass value=\"1\"/>", "<mass value=\"abc\"/>"), "", "", "malformed URDF",
              "unparsable number (urdfdom would silently use 0)");
  const vereshchagin::UrdfResult missing = vereshchagin::chainFromUrdfFile("/nonexistent/robot.urdf");
  CHECK_MESSAGE((!missing.ok && missing.message.find("'/nonexistent/robot.urdf' does not exist") != std::string::npos),
                "missing file: " << missing.message);
  const vereshchagin::UrdfResult dir = vereshchagin::chainFromUrdfFile("/");
  CHECK_MESSAGE((!dir.ok && dir.message.find("'/' is a directory") != std::string::npos),
                "a directory: " << dir.message);
}

// base -j1- l1 -j2- ... -jn- ln: revolute joints about z, 0.1 m apart along z, 1 kg per link.
std::string serialXml(int n) {
  std::string xml = "<robot name='serial'><link name='base'/>";
  const std::string inertial =
      "<inertial><mass value='1'/><inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial>";
  for (int k = 1; k <= n; ++k) {
    const std::string name = "l" + std::to_string(k), parent = k == 1 ? "base" : "l" + std::to_string(k - 1);
    xml += "<link name='" + name + "'>" + inertial + "</link><joint name='j" + std::to_string(k) +
           "' type='continuous'><parent link='" + parent + "'/><child link='" + name +
           "'/><origin xyz='0 0 0.1'/><axis xyz='0 0 1'/></joint>";
  }
  return xml + "</robot>";
}

// base -j1- a -j2- b, and n links of 0.01 kg in a line below `a` through fixed joints.
std::string sideBranchXml(int n) {
  std::string xml =
      "<robot name='branch'><link name='base'/><link name='a'><inertial><mass value='1'/><inertia ixx='0.01' "
      "ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link><link name='b'/>"
      "<joint name='j1' type='continuous'><parent link='base'/><child link='a'/><axis xyz='0 0 1'/></joint>"
      "<joint name='j2' type='continuous'><parent link='a'/><child link='b'/><axis xyz='1 0 0'/></joint>";
  for (int k = 1; k <= n; ++k) {
    const std::string name = "s" + std::to_string(k), parent = k == 1 ? "a" : "s" + std::to_string(k - 1);
    xml += "<link name='" + name +
           "'><inertial><mass value='0.01'/><inertia ixx='1e-6' ixy='0' ixz='0' iyy='1e-6' iyz='0' "
           "izz='1e-6'/></inertial></link><joint name='f" +
           std::to_string(k) + "' type='fixed'><parent link='" + parent + "'/><child link='" + name +
           "'/><origin xyz='0.001 0 0'/></joint>";
  }
  return xml + "</robot>";
}

// Deep documents used to overflow the stack in the recursive walks (leaves, side branches).
TEST_CASE("30000-deep chain and fixed side branch load (no stack overflow)") {
  const int n = 30000;
  const vereshchagin::UrdfResult serial = vereshchagin::chainFromUrdfString(serialXml(n));
  CHECK_MESSAGE((serial.ok && serial.robot.chain.getNrOfJoints() == static_cast<unsigned>(n)),
                "deep chain: " << serial.message);
  if (serial.ok) {
    KDL::ChainFkSolverPos_recursive fk(serial.robot.chain);
    KDL::JntArray q(static_cast<unsigned>(n));
    KDL::Frame tip;
    fk.JntToCart(q, tip);
    CHECK_MESSAGE((near(tip.p.z(), 0.1 * n) && near(tip.p.x(), 0.0)), "deep chain: the tip is n * 0.1 m up");
  }
  const vereshchagin::UrdfResult branch = vereshchagin::chainFromUrdfString(sideBranchXml(n), "", "b");
  CHECK_MESSAGE((branch.ok && branch.robot.chain.getNrOfSegments() == 2), "deep fixed side branch: " << branch.message);
  if (branch.ok) {
    const KDL::RigidBodyInertia& body = branch.robot.chain.getSegment(0).getInertia();
    CHECK_MESSAGE(near(body.getMass(), 1.0 + 0.01 * n), "the side branch's mass is lumped into segment 0");
    // Centre of mass: s_k sits k mm along x, so sum(0.01 * k mm) / total mass.
    const double cx = 0.01 * 0.001 * 0.5 * n * (n + 1.0) / (1.0 + 0.01 * n);
    CHECK_MESSAGE(std::abs(body.getCOG().x() - cx) <= 1e-9 * cx, "the side branch's centre of mass");
    CHECK_MESSAGE(branch.robot.links.size() == static_cast<std::size_t>(n) + 3, "every branch link is placed");
  }
}

// Documents refused before urdfdom reads them (its reader recurses per nesting level).
TEST_CASE("nesting depth and link count limits refuse documents before urdfdom reads them") {
  const std::string body =
      "<link name='a'/><link name='b'/><joint name='j' type='continuous'><parent "
      "link='a'/><child link='b'/><axis xyz='0 0 1'/></joint>";
  const auto nested = [&](int levels) {  // <robot> plus `levels` nested elements
    std::string xml = "<robot name='r'>" + body;
    for (int k = 0; k < levels; ++k) xml += "<x a='>'>";
    for (int k = 0; k < levels; ++k) xml += "</x>";
    return xml + "<!-- <y><y> --><![CDATA[<z>]]></robot>";
  };
  CHECK_MESSAGE(vereshchagin::chainFromUrdfString(nested(999)).ok, "1000 nesting levels load");
  expectError(nested(1000), "", "", "nested more than 1000 levels", "1001 nesting levels are refused");
  expectError(nested(200000), "", "", "nested more than 1000 levels", "200000 nesting levels are refused");
  std::string many = "<robot name='r'>";
  for (int k = 0; k <= 50000; ++k) many += "<link name='l" + std::to_string(k) + "'/>";
  expectError(many + "</robot>", "", "", "more than 50000 links", "more links than the limit");
}

// The fixed base leaves the root link's mass out: a note says so, with the mass and the link.
TEST_CASE("a heavy root link is noted: the fixed base leaves its mass out") {
  const vereshchagin::UrdfResult bare = vereshchagin::chainFromUrdfString(kArm);
  CHECK_MESSAGE((bare.ok && bare.robot.notes.empty()), "a massless root link gives no note");
  const std::string heavy =
      replaced(kArm, "<link name=\"base\"/>",
               "<link name=\"base\"><inertial><mass value=\"7.5\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" "
               "iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>");
  const vereshchagin::UrdfResult r = vereshchagin::chainFromUrdfString(heavy);
  CHECK_MESSAGE((r.ok && r.robot.notes.size() == 1 &&
                 r.robot.notes[0].find("root link 'base' carries 7.5 kg: ") != std::string::npos &&
                 r.robot.notes[0].find("welded to the world") != std::string::npos &&
                 r.robot.notes[0].find("a floating base (base=\"free\") is not supported yet") != std::string::npos),
                "the root link's mass is noted: " << (r.robot.notes.empty() ? std::string() : r.robot.notes[0]));
}

}  // namespace

TEST_CASE("loadUrdf loads a chain or a tree into place, or says why and leaves it") {
  vereshchagin::RobotChain chain;
  vereshchagin::RobotTree tree;
  std::string message;
  REQUIRE(vereshchagin::loadUrdf(kArm, "", "", {}, chain, message));
  CHECK(chain.chain.getNrOfSegments() == vereshchagin::chainFromUrdf(kArm).robot.chain.getNrOfSegments());
  REQUIRE(vereshchagin::loadUrdf(kArm, "", "ignored for a tree", {}, tree, message));
  CHECK(tree.segment_names.size() == vereshchagin::treeFromUrdf(kArm).robot.segment_names.size());
  const vereshchagin::Status s = vereshchagin::loadUrdf("/no/such/robot.urdf", "", "", {}, chain, message);
  CHECK(s.code() == vereshchagin::Error::InvalidModel);
  CHECK(message.find("neither XML text nor a readable file") != std::string::npos);
  CHECK(chain.chain.getNrOfSegments() > 0);  // unchanged
}
