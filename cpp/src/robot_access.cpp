// Reading and editing RobotChain and RobotTree alike: segments, rotor inertias, name lookups (with
// the messages naming what exists) and the chain of a tree path (robot_access.hpp).
#include "vereshchagin/robot_access.hpp"

#include <algorithm>
#include <cmath>

#include "vereshchagin/robot_chain.hpp"  // withRotorInertia

namespace vereshchagin {

namespace {

// "" if `values` can be the rotor inertias of `n_joints` joints, else why.
std::string rotorFault(const std::vector<double>& values, std::size_t n_joints) {
  if (values.size() != n_joints)
    return "rotor_inertia must have " + std::to_string(n_joints) + " entries, got " + std::to_string(values.size());
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values[k])) return "rotor_inertia must be finite, got nan or inf at joint " + std::to_string(k);
    if (values[k] < 0.0)
      return "rotor_inertia must be >= 0, got " + std::to_string(values[k]) + " at joint " + std::to_string(k);
  }
  return "";
}

// Segments first, then links, then the base (robot_access.hpp's rule); `names` the segment names.
template <class Robot>
bool findFrameIn(const Robot& robot, const std::string& name, FrameRef& out) {
  for (int i = 0; i < segmentCount(robot); ++i) {
    if (segmentName(robot, i) == name) {
      out = FrameRef{i, KDL::Frame::Identity()};
      return true;
    }
  }
  for (const LinkPlacement& l : robot.links) {
    if (l.link == name) {
      out = FrameRef{l.segment, l.in_segment_tip};
      return true;
    }
  }
  if (robot.root_link.empty() || name != robot.root_link) return false;
  out = FrameRef{-1, KDL::Frame::Identity()};
  return true;
}

template <class Robot>
Status findFrameOrSay(const Robot& robot, const std::string& name, FrameRef& out, std::string& message) {
  if (findFrameIn(robot, name, out)) return Status();
  message = "no segment or link named '" + name + "' (segments: " + nameList(segmentNames(robot)) +
            (robot.root_link.empty() ? "" : "; base: '" + robot.root_link + "'") + ")";
  return Status(Error::OutOfRange, message.c_str());
}

template <class Robot>
Status findJointOrSay(const Robot& robot, const std::string& name, int& index, std::string& message) {
  index = findJoint(robot, name);
  if (index >= 0) return Status();
  std::vector<std::string> names;
  for (const JointInfo& j : robot.joints) names.push_back(j.name);
  message = "no joint named '" + name + "' (joints: " + nameList(names) + ")";
  return Status(Error::OutOfRange, message.c_str());
}

}  // namespace

std::string nameList(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t k = 0; k < names.size() && k < 12; ++k) out += (k ? ", '" : "'") + names[k] + "'";
  if (names.size() > 12) out += ", ... (" + std::to_string(names.size()) + " in all)";
  return out;
}

std::string indexRangeMessage(const std::string& what, const std::string& value, int n) {
  return what + " index " + value + " out of range for " + std::to_string(n) + " " + what + "s (valid " +
         std::to_string(-n) + " .. " + std::to_string(n - 1) +
         (what == "segment" ? "; the base is addressed by its name only)" : ")");
}

std::string indexTypeMessage(const std::string& what, const std::string& type_name) {
  const char* named_by = what == "segment" ? "a str (segment or link name)" : "a str";
  return "a " + what + " is named by " + named_by + " or an int index, got " + type_name;
}

Status findFrame(const RobotChain& robot, const std::string& name, FrameRef& out, std::string& message) {
  return findFrameOrSay(robot, name, out, message);
}
Status findFrame(const RobotTree& robot, const std::string& name, FrameRef& out, std::string& message) {
  return findFrameOrSay(robot, name, out, message);
}
Status findJoint(const RobotChain& robot, const std::string& name, int& index, std::string& message) {
  return findJointOrSay(robot, name, index, message);
}
Status findJoint(const RobotTree& robot, const std::string& name, int& index, std::string& message) {
  return findJointOrSay(robot, name, index, message);
}

Model RobotRef::model(const ModelOptions& options) const {
  return tree_ ? Model(*tree_, options) : Model(*chain_, options);
}

int segmentCount(const RobotChain& robot) {
  return static_cast<int>(robot.chain.getNrOfSegments());
}
int segmentCount(const RobotTree& robot) {
  return static_cast<int>(robot.segment_names.size());
}
int jointCount(const RobotChain& robot) {
  return static_cast<int>(robot.chain.getNrOfJoints());
}
int jointCount(const RobotTree& robot) {
  return static_cast<int>(robot.tree.getNrOfJoints());
}
const KDL::Segment& segmentAt(const RobotChain& robot, int index) {
  return robot.chain.getSegment(static_cast<unsigned int>(index));
}
const KDL::Segment& segmentAt(const RobotTree& robot, int index) {
  return robot.tree.getSegments().find(segmentName(robot, index))->second.segment;
}
const std::string& segmentName(const RobotChain& robot, int index) {
  return segmentAt(robot, index).getName();
}
const std::string& segmentName(const RobotTree& robot, int index) {
  return robot.segment_names[static_cast<std::size_t>(index)];
}

Status setRotorInertia(RobotChain& robot, const std::vector<double>& values, std::string& message) {
  message = rotorFault(values, robot.joints.size());
  if (!message.empty()) return Status(Error::OutOfRange, message.c_str());
  KDL::Chain rebuilt;
  std::size_t k = 0;
  for (unsigned int i = 0; i < robot.chain.getNrOfSegments(); ++i) {
    const KDL::Segment& seg = robot.chain.getSegment(i);
    const KDL::Joint& j = seg.getJoint();
    const KDL::Joint joint = j.getType() == KDL::Joint::Fixed ? j : withRotorInertia(j, values[k++]);
    rebuilt.addSegment(KDL::Segment(seg.getName(), joint, seg.getFrameToTip(), seg.getInertia()));
  }
  robot.chain = rebuilt;
  return Status();
}

Status setRotorInertia(RobotTree& robot, const std::vector<double>& values, std::string& message) {
  message = rotorFault(values, robot.joints.size());
  if (!message.empty()) return Status(Error::OutOfRange, message.c_str());
  std::vector<double> rotor(robot.segment_names.size(), 0.0);  // per segment
  for (std::size_t k = 0; k < robot.joints.size(); ++k) rotor[robot.joints[k].segment] = values[k];
  KDL::Tree rebuilt(robot.root_link);
  for (int i = 0; i < segmentCount(robot); ++i) {  // segment order: KDL numbers q_nr as before
    const KDL::Segment& seg = segmentAt(robot, i);
    const KDL::Joint& j = seg.getJoint();
    const KDL::Joint joint = j.getType() == KDL::Joint::None ? j : withRotorInertia(j, rotor[std::size_t(i)]);
    const int p = robot.parent[static_cast<std::size_t>(i)];
    rebuilt.addSegment(KDL::Segment(seg.getName(), joint, seg.getFrameToTip(), seg.getInertia()),
                       p < 0 ? robot.root_link : robot.segment_names[static_cast<std::size_t>(p)]);
  }
  copyTree(rebuilt, robot.tree);  // KDL::Tree's assignment recurses per level
  return Status();
}

bool findFrame(const RobotChain& robot, const std::string& name, FrameRef& out) {
  return findFrameIn(robot, name, out);
}
bool findFrame(const RobotTree& robot, const std::string& name, FrameRef& out) {
  return findFrameIn(robot, name, out);
}

RobotChain pathChain(const RobotTree& robot, int tip) {
  std::vector<int> path;
  for (int s = tip; s >= 0; s = robot.parent[static_cast<std::size_t>(s)]) path.push_back(s);
  std::reverse(path.begin(), path.end());
  const std::size_t n = robot.segment_names.size();
  std::vector<int> chain_index(n, -1), joint_of(n, -1);
  RobotChain c;
  for (std::size_t k = 0; k < path.size(); ++k) {
    chain_index[static_cast<std::size_t>(path[k])] = static_cast<int>(k);
    c.chain.addSegment(segmentAt(robot, path[k]));
  }
  for (std::size_t k = 0; k < robot.joints.size(); ++k) joint_of[robot.joints[k].segment] = static_cast<int>(k);
  for (int s : path) {
    const int j = joint_of[static_cast<std::size_t>(s)];
    if (j < 0) continue;
    JointInfo info = robot.joints[static_cast<std::size_t>(j)];
    info.segment = static_cast<unsigned int>(chain_index[static_cast<std::size_t>(s)]);
    c.joints.push_back(info);
  }
  for (const LinkPlacement& l : robot.links) {
    const int seg = l.segment < 0 ? -1 : chain_index[static_cast<std::size_t>(l.segment)];
    if (l.segment < 0 || seg >= 0) c.links.push_back({l.link, seg, l.in_segment_tip});
  }
  c.root_link = robot.root_link;
  for (const std::string& note : robot.notes)  // the base is the chain's base too
    if (note.rfind("root link '", 0) == 0) c.notes.push_back(note);
  if (path.size() < n)
    c.notes.push_back("extracted from a tree: the " + std::to_string(n - path.size()) + " segments off the path to '" +
                      robot.segment_names[static_cast<std::size_t>(tip)] + "' are left out");
  return c;
}

}  // namespace vereshchagin
