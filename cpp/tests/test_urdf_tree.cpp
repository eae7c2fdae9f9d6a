// C++ URDF tree loader on a hand-written branched URDF (fixed links, side branches, a prismatic
// joint, a two-finger leaf): segment and joint order, merged masses and inertias, link
// placements, root-to-leaf paths against the chain loader, rejection messages. Expected values
// come from hand composition of the URDF's transforms, KDL's inertia algebra and KDL's own
// tree forward kinematics (TreeFkSolverPos_recursive).
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include <kdl/treefksolverpos_recursive.hpp>

#include <doctest/doctest.h>

#include "test_common.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace {

using testutil::near;
using testutil::nearFrame;

bool nearInertia(const KDL::RigidBodyInertia& a, const KDL::RigidBodyInertia& b) {
  bool same = near(a.getMass(), b.getMass());
  for (int k = 0; k < 3; ++k) same = same && near(a.getCOG()(k), b.getCOG()(k));
  for (int k = 0; k < 9; ++k) same = same && near(a.getRotationalInertia().data[k], b.getRotationalInertia().data[k]);
  return same;
}

// A joint and its child link; `extra` goes inside <joint>.
std::string joint(const std::string& name, const std::string& type, const std::string& parent, const std::string& child,
                  const std::string& xyz, const std::string& rpy, const std::string& extra = "") {
  return "<joint name='" + name + "' type='" + type + "'><parent link='" + parent + "'/><child link='" + child +
         "'/><origin xyz='" + xyz + "' rpy='" + rpy + "'/>" + extra + "</joint>";
}

std::string link(const std::string& name, double mass, const std::string& com, double ixx, double iyy, double izz) {
  return "<link name='" + name + "'><inertial><origin xyz='" + com + "' rpy='0.1 -0.2 0.3'/><mass value='" +
         std::to_string(mass) + "'/><inertia ixx='" + std::to_string(ixx) + "' ixy='0' ixz='0' iyy='" +
         std::to_string(iyy) + "' iyz='0' izz='" + std::to_string(izz) + "'/></inertial></link>";
}

// One row per link: its parent joint (name, type, parent, origin xyz / rpy, axis) and inertial.
struct LinkSpec {
  const char *link, *joint, *type, *parent, *xyz, *rpy, *axis;
  double mass, ixx, iyy, izz;
  const char* com;
};

// base -fixed- pedestal -rev- torso { -fixed- plate, -fixed- chest -rev- right1 -fixed- hand
// { -fixed- finger_a, -fixed- finger_b }, -rev- left1 -prismatic- left2 -fixed- left_tool,
// -continuous- head }.
const LinkSpec kLinks[] = {
    {"base", "", "", "", "", "", "", 3.0, 0.1, 0.1, 0.1, "0 0 0"},
    {"pedestal", "f_pedestal", "fixed", "base", "0 0 0.5", "0 0 0.4", "", 5.0, 0.2, 0.3, 0.25, "0 0 0.1"},
    {"torso", "a_torso", "revolute", "pedestal", "0.1 0 0.3", "0.2 0 0", "0 0 1", 4.0, 0.2, 0.2, 0.1, "0 0.1 0"},
    {"plate", "f_plate", "fixed", "torso", "0 0.2 0.1", "0 0 1.0", "", 0.7, 0.01, 0.02, 0.02, "0.03 0 0"},
    {"chest", "f_chest", "fixed", "torso", "0 0 0.4", "0.3 0.1 0", "", 1.5, 0.03, 0.03, 0.02, "0 0 0.05"},
    {"right1", "c_right", "revolute", "chest", "0 -0.3 0", "-0.5 0 0", "0 1 1", 1.2, 0.01, 0.012, 0.011, "0 -0.1 0"},
    {"hand", "f_hand", "fixed", "right1", "0 -0.25 0", "0 0 0.7", "", 0.6, 0.002, 0.003, 0.003, "0 0 0.02"},
    {"finger_a", "f_finger_a", "fixed", "hand", "0.02 0 0.1", "0 0 0", "", 0.05, 1e-4, 1e-4, 1e-4, "0 0 0.01"},
    {"finger_b", "f_finger_b", "fixed", "hand", "-0.02 0 0.1", "0 0 0", "", 0.05, 1e-4, 1e-4, 1e-4, "0 0 0.01"},
    {"left1", "b_left", "revolute", "torso", "0 0.3 0.3", "0.5 0 0", "1 0 0", 1.1, 0.01, 0.01, 0.012, "0 0.1 0"},
    {"left2", "b_left2", "prismatic", "left1", "0 0.2 0", "0 0.2 0", "0 1 0", 0.8, 0.004, 0.005, 0.005, "0 0.05 0"},
    {"left_tool", "f_left_tool", "fixed", "left2", "0 0.1 0", "0 0 -0.6", "", 0.3, 0.001, 0.001, 0.001, "0 0 0.03"},
    {"head", "d_head", "continuous", "torso", "0 0 0.6", "0 0 0", "0 0 1", 0.9, 0.005, 0.005, 0.004, "0.02 0 0.05"},
};

std::string treeXml(const std::map<std::string, std::string>& type_override = {}) {
  std::string xml = "<robot name='tree'>";
  for (const LinkSpec& s : kLinks) {
    xml += link(s.link, s.mass, s.com, s.ixx, s.iyy, s.izz);
    if (s.joint[0] == '\0') continue;
    const auto o = type_override.find(s.joint);
    const std::string type = o == type_override.end() ? s.type : o->second;
    std::string extra;
    if (s.axis[0] != '\0') extra = std::string("<axis xyz='") + s.axis + "'/>";
    if (type == "revolute" || type == "prismatic")
      extra += "<limit lower='-1.5' upper='" + std::to_string(1.0 + s.mass) + "' effort='" +
               std::to_string(10 * s.mass) + "' velocity='" + std::to_string(2 * s.mass) + "'/>";
    if (type != "fixed")
      extra +=
          "<dynamics damping='" + std::to_string(0.1 * s.mass) + "' friction='" + std::to_string(0.5 * s.mass) + "'/>";
    xml += joint(s.joint, type, s.parent, s.link, s.xyz, s.rpy, extra);
  }
  return xml + "</robot>";
}

KDL::Frame originOf(const LinkSpec& s) {
  double v[6];
  std::sscanf(s.xyz, "%lf %lf %lf", &v[0], &v[1], &v[2]);
  std::sscanf(s.rpy, "%lf %lf %lf", &v[3], &v[4], &v[5]);
  return KDL::Frame(KDL::Rotation::RPY(v[3], v[4], v[5]), KDL::Vector(v[0], v[1], v[2]));
}

// Pose of every link in the base frame at q = 0, by composing the URDF origins.
std::map<std::string, KDL::Frame> linkPosesAtZero() {
  std::map<std::string, KDL::Frame> pose;
  for (const LinkSpec& s : kLinks)
    pose[s.link] = s.parent[0] == '\0' ? KDL::Frame::Identity() : pose[s.parent] * originOf(s);
  return pose;
}

// The link's own inertia in its link frame, from the table.
KDL::RigidBodyInertia ownInertia(const LinkSpec& s) {
  double c[3];
  std::sscanf(s.com, "%lf %lf %lf", &c[0], &c[1], &c[2]);
  const KDL::Frame inertial(KDL::Rotation::RPY(0.1, -0.2, 0.3), KDL::Vector(c[0], c[1], c[2]));
  // Inertia about the centre of mass, rotated from inertial to link axes: R I R^T.
  const KDL::RotationalInertia Ic(s.ixx, s.iyy, s.izz, 0, 0, 0);
  const KDL::RigidBodyInertia at_com(s.mass, KDL::Vector::Zero(), Ic);
  return inertial * at_com;
}

std::map<std::string, KDL::Frame> treeFk(const KDL::Tree& tree, const KDL::JntArray& q,
                                         const std::vector<std::string>& names) {
  KDL::TreeFkSolverPos_recursive fk(tree);
  std::map<std::string, KDL::Frame> out;
  for (const std::string& n : names) fk.JntToCart(q, out[n], n);
  return out;
}

TEST_CASE("the branched tree loads without a message") {
  const vereshchagin::UrdfTreeResult r = vereshchagin::treeFromUrdfString(treeXml());
  CHECK_MESSAGE((r.ok && r.message.empty()), "branched tree loads: " << r.message);
}

TEST_CASE("branched tree: segments in preorder, joint metadata and treeSegmentOrder") {
  const vereshchagin::UrdfTreeResult r = vereshchagin::treeFromUrdfString(treeXml());
  REQUIRE_MESSAGE(r.ok, "branched tree loads: " << r.message);
  const vereshchagin::RobotTree& t = r.robot;
  const std::vector<std::string> names = {"torso", "left1", "left_tool", "head", "hand"};
  CHECK_MESSAGE(t.segment_names == names, "segments in preorder, children by joint name, named after their tip links");
  CHECK_MESSAGE(t.parent == std::vector<int>({-1, 0, 1, 0, 0}), "parent array");
  CHECK_MESSAGE((t.root_link == "base" && t.tree.getRootSegment()->first == "base"), "root link");
  CHECK_MESSAGE((t.tree.getNrOfJoints() == 5 && t.tree.getNrOfSegments() == 5 && t.joints.size() == 5),
                "five moving joints");
  const std::vector<std::string> joints = {"a_torso", "b_left", "b_left2", "d_head", "c_right"};
  for (std::size_t k = 0; k < t.joints.size(); ++k) {
    const auto& j = t.joints[k];
    CHECK_MESSAGE((j.name == joints[k] && j.segment == k), "joint " << std::to_string(k) << " is " << joints[k]);
    CHECK_MESSAGE(GetTreeElementQNr(t.tree.getSegments().find(names[k])->second) == k, "q_nr of segment " << names[k]);
    for (const LinkSpec& s : kLinks) {
      if (j.name != s.joint) continue;
      CHECK_MESSAGE(j.type == s.type, "type of " << j.name);
      const bool limited = j.type != "continuous";
      CHECK_MESSAGE((near(j.friction, 0.5 * s.mass) && near(j.damping, 0.1 * s.mass)),
                    "friction and damping of " << j.name);
      CHECK_MESSAGE((limited ? near(j.lower, -1.5) && near(j.upper, 1.0 + s.mass) &&
                                   near(j.effort_limit, 10 * s.mass) && near(j.velocity_limit, 2 * s.mass)
                             : std::isinf(j.lower) && std::isinf(j.upper)),
                    "limits of " << j.name);
    }
  }
  std::vector<KDL::SegmentMap::const_iterator> order;
  std::vector<int> parent;
  vereshchagin::treeSegmentOrder(t.tree, order, parent);
  bool same = order.size() == names.size() && parent == t.parent;
  for (std::size_t i = 0; same && i < order.size(); ++i) same = order[i]->first == names[i];
  CHECK_MESSAGE(same, "treeSegmentOrder gives the loader's order");
}

// Placements: every link's pose = fk(its segment) * in_segment_tip, at q = 0 (hand-composed
// URDF poses) and in mass: total spatial inertia in the base frame conserved.
TEST_CASE("branched tree: link placements and merged inertias") {
  const vereshchagin::UrdfTreeResult r = vereshchagin::treeFromUrdfString(treeXml());
  REQUIRE_MESSAGE(r.ok, "branched tree loads: " << r.message);
  const vereshchagin::RobotTree& t = r.robot;
  const std::map<std::string, KDL::Frame> expected = linkPosesAtZero();
  KDL::JntArray q0(t.tree.getNrOfJoints());
  const std::map<std::string, KDL::Frame> fk = treeFk(t.tree, q0, t.segment_names);
  CHECK_MESSAGE(t.links.size() == sizeof kLinks / sizeof kLinks[0], "every link placed once");
  std::map<std::string, int> expected_segment = {
      {"base", -1},    {"pedestal", -1}, {"torso", 0}, {"plate", 0}, {"chest", 0},     {"right1", 4}, {"hand", 4},
      {"finger_a", 4}, {"finger_b", 4},  {"left1", 1}, {"left2", 2}, {"left_tool", 2}, {"head", 3}};
  for (const auto& l : t.links) {
    const KDL::Frame seg = l.segment < 0 ? KDL::Frame::Identity() : fk.at(t.segment_names[l.segment]);
    CHECK_MESSAGE(nearFrame(seg * l.in_segment_tip, expected.at(l.link)), "placement of link " << l.link);
    CHECK_MESSAGE(l.segment == expected_segment.at(l.link), "segment of link " << l.link);
  }
  KDL::RigidBodyInertia want = KDL::RigidBodyInertia::Zero(), got = KDL::RigidBodyInertia::Zero();
  double mass = 0.0;
  for (const LinkSpec& s : kLinks) {
    if (std::string(s.link) == "base" || std::string(s.link) == "pedestal") continue;  // the base's own
    want = want + expected.at(s.link) * ownInertia(s);
    mass += s.mass;
  }
  for (const std::string& n : t.segment_names)
    got = got + fk.at(n) * t.tree.getSegments().find(n)->second.segment.getInertia();
  CHECK_MESSAGE((near(got.getMass(), mass) && nearInertia(got, want)),
                "total spatial inertia below the base conserved");
  const KDL::RigidBodyInertia hand = t.tree.getSegments().find("hand")->second.segment.getInertia();
  KDL::RigidBodyInertia hand_want = KDL::RigidBodyInertia::Zero();
  for (const char* n : {"right1", "hand", "finger_a", "finger_b"})
    for (const LinkSpec& s : kLinks)
      if (std::string(s.link) == n)
        hand_want = hand_want + (expected.at("hand").Inverse() * expected.at(n)) * ownInertia(s);
  CHECK_MESSAGE(nearInertia(hand, hand_want),
                "right arm segment: right1, hand and both fingers merged in the hand frame");
}

bool sameSegment(const KDL::Segment& a, const KDL::Segment& b) {
  const KDL::Joint &ja = a.getJoint(), &jb = b.getJoint();
  bool same = a.getName() == b.getName() && ja.getName() == jb.getName() && ja.getType() == jb.getType() &&
              ja.JointOrigin() == jb.JointOrigin() && ja.JointAxis() == jb.JointAxis() &&
              a.getFrameToTip() == b.getFrameToTip();
  const KDL::RigidBodyInertia &ia = a.getInertia(), &ib = b.getInertia();
  same = same && ia.getMass() == ib.getMass() && ia.getCOG() == ib.getCOG();
  for (int k = 0; k < 9; ++k) same = same && ia.getRotationalInertia().data[k] == ib.getRotationalInertia().data[k];
  return same;
}

// Root-to-leaf paths without other branches equal the chain loader's chains, bit for bit.
TEST_CASE("root-to-leaf paths equal the chain loader's chains bit for bit") {
  const std::string xml = treeXml();
  const struct {
    const char *root, *leaf;
    std::vector<std::string> segments;
    bool from_base;  // also in the whole tree (false: the path's first joint leaves a merged link)
  } paths[] = {{"torso", "left_tool", {"left1", "left_tool"}, true},
               {"torso", "head", {"head"}, true},
               {"left1", "left_tool", {"left_tool"}, true},
               {"chest", "hand", {"hand"}, false}};
  for (const auto& p : paths) {
    const auto chain = vereshchagin::chainFromUrdfString(xml, p.root, p.leaf);
    for (const std::string& root : {std::string(p.from_base ? "base" : p.root), std::string(p.root)}) {
      const auto tree = vereshchagin::treeFromUrdfString(xml, root);
      CHECK_MESSAGE((chain.ok && tree.ok), std::string("path ") << p.root << " -> " << p.leaf << " loads");
      if (!chain.ok || !tree.ok) continue;
      bool same = chain.robot.chain.getNrOfSegments() == p.segments.size();
      for (std::size_t i = 0; same && i < p.segments.size(); ++i)
        same = sameSegment(chain.robot.chain.getSegment(static_cast<unsigned int>(i)),
                           tree.robot.tree.getSegments().find(p.segments[i])->second.segment);
      CHECK_MESSAGE(same, std::string("tree (root ")
                              << root << ") path " << p.root << " -> " << p.leaf << " equals the chain");
    }
  }
  // chest -> hand: the chain's tip is `hand` only because its fingers are no path; to finger_a it
  // ends at the finger, the tree's segment at the hand (the fingers' common parent).
  const auto to_finger = vereshchagin::chainFromUrdfString(xml, "chest", "finger_a");
  CHECK_MESSAGE((to_finger.ok && to_finger.robot.chain.getSegment(0).getName() == "finger_a"),
                "chain to a finger ends there");
}

void expectTreeError(const std::string& xml, const std::string& root, const std::vector<std::string>& fragments,
                     const std::string& what) {
  const auto r = vereshchagin::treeFromUrdfString(xml, root);
  bool has = !r.ok;
  for (const auto& f : fragments) has = has && r.message.find(f) != std::string::npos;
  CHECK_MESSAGE(has, what << " (message: '" << r.message << "')");
}

TEST_CASE("floating and planar joints, mimic joints, bad roots and missing files") {
  for (const char* type : {"floating", "planar"}) {
    const std::string xml = treeXml({{"b_left", type}});
    expectTreeError(xml, "", {"joint 'b_left'", type, "root='left1'"}, std::string(type) + " joint in the tree");
    const auto below = vereshchagin::treeFromUrdfString(xml, "left1");
    CHECK_MESSAGE((below.ok && below.robot.segment_names == std::vector<std::string>({"left_tool"})),
                  std::string("the sub-tree below the ") << type << " joint loads: " << below.message);
  }
  std::string mimic = treeXml();
  mimic.insert(mimic.find("</joint>", mimic.find("name='d_head'")), "<mimic joint='a_torso'/>");
  const auto mimicked = vereshchagin::treeFromUrdfString(mimic);
  CHECK_MESSAGE((mimicked.ok && mimicked.robot.joints.size() == 5 && mimicked.robot.notes.size() == 2 &&
                 mimicked.robot.notes[1].find("'d_head' mimics joint 'a_torso'") != std::string::npos),
                "a mimic joint becomes an independent joint, with a note");
  expectTreeError(treeXml(), "nowhere", {"root link 'nowhere' not found"}, "unknown root");
  expectTreeError(treeXml(), "finger_a", {"no moving joint below root link 'finger_a'"}, "a leaf as root");
  expectTreeError("<robot name='x'><link name='a'>", "", {"malformed URDF"}, "malformed XML");
  const auto missing = vereshchagin::treeFromUrdfFile("/nonexistent/robot.urdf");
  CHECK_MESSAGE((!missing.ok && missing.message.find("'/nonexistent/robot.urdf' does not exist") != std::string::npos),
                "missing file: " << missing.message);
  const auto dir = vereshchagin::treeFromUrdfFile("/");
  CHECK_MESSAGE((!dir.ok && dir.message.find("'/' is a directory") != std::string::npos),
                "a directory: " << dir.message);
}

// The base (base 3 kg, pedestal 5 kg fixed to it) is welded to the world: a note gives its mass.
TEST_CASE("branched tree: the base's mass and a sub-tree root's mass are noted") {
  const vereshchagin::UrdfTreeResult r = vereshchagin::treeFromUrdfString(treeXml());
  REQUIRE_MESSAGE(r.ok, "branched tree loads: " << r.message);
  const vereshchagin::RobotTree& t = r.robot;
  CHECK_MESSAGE(
      (!t.notes.empty() && t.notes[0].find("root link 'base' carries 8 kg (with the links fixed to it): ") == 0 &&
       t.notes[0].find("a floating base (base=\"free\") is not supported yet") != std::string::npos),
      "the base's mass is noted: " << (t.notes.empty() ? std::string() : t.notes[0]));
  const auto sub = vereshchagin::treeFromUrdfString(treeXml(), "left1");  // left1 carries 1.1 kg
  CHECK_MESSAGE(
      (sub.ok && sub.robot.notes.size() == 1 && sub.robot.notes[0].find("root link 'left1' carries 1.1 kg: ") == 0),
      "a sub-tree root's mass is noted");
}

// base -j1- l1 -j2- ... -jn- ln: revolute joints about z, 0.1 m apart along z, 1 kg per link;
// `branch`: n links of 0.01 kg fixed in a line below l1 instead (l1 -j2- l2 the only other joint).
std::string deepXml(int n, bool branch) {
  std::string xml = "<robot name='deep'><link name='base'/>";
  const auto add = [&xml](const std::string& name, const std::string& parent, const std::string& type, double mass) {
    xml += "<link name='" + name + "'><inertial><mass value='" + std::to_string(mass) +
           "'/><inertia ixx='1e-4' ixy='0' ixz='0' iyy='1e-4' iyz='0' izz='1e-4'/></inertial></link><joint name='j_" +
           name + "' type='" + type + "'><parent link='" + parent + "'/><child link='" + name +
           "'/><origin xyz='0 0 0.1'/><axis xyz='0 0 1'/></joint>";
  };
  for (int k = 1; k <= (branch ? 2 : n); ++k)
    add("l" + std::to_string(k), k == 1 ? "base" : "l" + std::to_string(k - 1), "continuous", 1.0);
  for (int k = 1; branch && k <= n; ++k)
    add("s" + std::to_string(k), k == 1 ? "l1" : "s" + std::to_string(k - 1), "fixed", 0.01);
  return xml + "</robot>";
}

// Deep trees used to overflow the stack: the loader's walks, treeSegmentOrder, and copies of a
// RobotTree (KDL::Tree's own copy recurses per level).
TEST_CASE("30000-deep tree and fixed side branch: loader, treeSegmentOrder and copies") {
  const int n = 30000;
  const auto serial = vereshchagin::treeFromUrdfString(deepXml(n, false));
  CHECK_MESSAGE((serial.ok && serial.robot.segment_names.size() == static_cast<std::size_t>(n)),
                "deep tree: " << serial.message);
  if (!serial.ok) return;
  bool chain = true;
  for (int i = 0; i < n; ++i) chain = chain && serial.robot.parent[static_cast<std::size_t>(i)] == i - 1;
  CHECK_MESSAGE(chain, "deep tree: parent[i] = i - 1");
  std::vector<KDL::SegmentMap::const_iterator> order;
  std::vector<int> parent;
  vereshchagin::treeSegmentOrder(serial.robot.tree, order, parent);
  CHECK_MESSAGE((parent == serial.robot.parent && order.back()->first == "l30000"), "deep tree: treeSegmentOrder");
  const vereshchagin::RobotTree copy = serial.robot;
  vereshchagin::RobotTree assigned;
  assigned = copy;
  for (const vereshchagin::RobotTree* t : {&copy, static_cast<const vereshchagin::RobotTree*>(&assigned)}) {
    const auto last = t->tree.getSegments().find("l30000");
    CHECK_MESSAGE((t->tree.getNrOfJoints() == static_cast<unsigned>(n) && last != t->tree.getSegments().end() &&
                   GetTreeElementQNr(last->second) == static_cast<unsigned>(n - 1) &&
                   t->segment_names == serial.robot.segment_names),
                  "deep tree: copies keep every segment and q_nr");
  }
  const auto branch = vereshchagin::treeFromUrdfString(deepXml(n, true));
  CHECK_MESSAGE((branch.ok && branch.robot.segment_names == std::vector<std::string>({"l1", "l2"})),
                "deep fixed side branch: " << branch.message);
  if (branch.ok) {
    const KDL::Segment& s = branch.robot.tree.getSegments().find("l1")->second.segment;
    CHECK_MESSAGE(near(s.getInertia().getMass(), 1.0 + 0.01 * n), "the side branch's mass is lumped into l1");
  }
}

// copyTree on a KDL tree deeper than KDL's own (recursive) copy survives with an 8 MB stack.
TEST_CASE("copyTree of a 400000-deep KDL tree") {
  const int n = 400000;
  KDL::Tree deep("root");
  std::string previous = "root";
  for (int k = 0; k < n; ++k) {
    const std::string name = "s" + std::to_string(k);
    deep.addSegment(KDL::Segment(name, KDL::Joint(k % 3 == 2 ? KDL::Joint::None : KDL::Joint::RotZ)), previous);
    previous = name;
  }
  KDL::Tree copy;
  vereshchagin::copyTree(deep, copy);
  const auto last = copy.getSegments().find(previous);
  CHECK_MESSAGE((copy.getNrOfSegments() == static_cast<unsigned>(n) && copy.getNrOfJoints() == deep.getNrOfJoints() &&
                 last != copy.getSegments().end() &&
                 GetTreeElementQNr(last->second) == GetTreeElementQNr(deep.getSegments().find(previous)->second) &&
                 GetTreeElementParent(last->second)->first == "s" + std::to_string(n - 2)),
                "copyTree of a 400000-deep tree");
}

}  // namespace
