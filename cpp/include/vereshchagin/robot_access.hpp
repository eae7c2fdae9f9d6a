/// @file
/// One way to read and edit a RobotChain and a RobotTree alike: segments by index, names,
/// masses, rotor inertias, lookups of frames and joints by name, and the chain of one
/// root-to-segment path of a tree. Indices are segment indices (robot_tree.hpp's segment order;
/// a chain's order) and joint indices (q order: RobotChain::joints / RobotTree::joints).
#pragma once

#include <string>
#include <vector>

#include <kdl/segment.hpp>

#include "vereshchagin/array_arg.hpp"
#include "vereshchagin/model.hpp"  // FrameRef
#include "vereshchagin/robot_chain.hpp"
#include "vereshchagin/robot_tree.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

int segmentCount(const RobotChain& robot);  ///< number of segments
int segmentCount(const RobotTree& robot);   ///< number of segments, the base excluded
int jointCount(const RobotChain& robot);    ///< number of moving joints (KDL's count)
int jointCount(const RobotTree& robot);     ///< number of moving joints (KDL's count)
/// Segment `index` (0 <= index < segmentCount): joint, tip frame, inertia about the tip origin.
const KDL::Segment& segmentAt(const RobotChain& robot, int index);
/// Segment `index` of the tree's segment order (0 <= index < segmentCount).
const KDL::Segment& segmentAt(const RobotTree& robot, int index);
/// The name of segment `index` (0 <= index < segmentCount).
const std::string& segmentName(const RobotChain& robot, int index);
/// The name of segment `index` (0 <= index < segmentCount).
const std::string& segmentName(const RobotTree& robot, int index);

/// Mass of every segment, kg, in segment order.
template <class Robot>
std::vector<double> segmentMasses(const Robot& robot) {
  std::vector<double> out(static_cast<std::size_t>(segmentCount(robot)));
  for (int i = 0; i < segmentCount(robot); ++i)
    out[static_cast<std::size_t>(i)] = segmentAt(robot, i).getInertia().getMass();
  return out;
}

/// Rotor inertia reflected to every moving joint, in q order (kg m^2 revolute, kg prismatic).
template <class Robot>
std::vector<double> rotorInertia(const Robot& robot) {
  std::vector<double> out(robot.joints.size());
  for (std::size_t k = 0; k < robot.joints.size(); ++k)
    out[k] = segmentAt(robot, static_cast<int>(robot.joints[k].segment)).getJoint().getInertia();
  return out;
}

/// Sets the rotor inertia of every moving joint (q order) and rebuilds the KDL chain; `values`
/// must hold one finite entry >= 0 per joint. On failure `robot` is unchanged and the message
/// ("rotor_inertia must be >= 0, got -0.100000 at joint 3", ...) is in `message`.
Status setRotorInertia(RobotChain& robot, const std::vector<double>& values, std::string& message);
/// The same for a tree: rebuilds its KDL::Tree in segment order (joint numbering unchanged).
Status setRotorInertia(RobotTree& robot, const std::vector<double>& values, std::string& message);

/// setRotorInertia from an array as a caller hands it over (array_arg.hpp). Checks its shape
/// first: Error::SizeMismatch with vectorMessage's "rotor_inertia must have shape (7,), got (6,)"
/// (or its non-finite message) in `message`, `robot` unchanged.
template <class Robot>
Status setRotorInertia(Robot& robot, const ArrayArg& values, std::string& message) {
  message = vectorMessage(values, "rotor_inertia", static_cast<long>(robot.joints.size()));
  if (!message.empty()) return Status(Error::SizeMismatch, message.c_str());
  return setRotorInertia(robot, std::vector<double>(values.data, values.data + values.size()), message);
}

/// A frame by name: a segment (its tip frame), a link merged into a segment (its pose in that
/// segment's tip frame) or the base (root_link, segment -1); segments first, then links, then the
/// base. False (out unchanged) if the name is none of them.
bool findFrame(const RobotChain& robot, const std::string& name, FrameRef& out);
/// The same on a tree.
bool findFrame(const RobotTree& robot, const std::string& name, FrameRef& out);

/// Index (q order) of the moving joint named `name`, -1 if none.
template <class Robot>
int findJoint(const Robot& robot, const std::string& name) {
  for (std::size_t k = 0; k < robot.joints.size(); ++k)
    if (robot.joints[k].name == name) return static_cast<int>(k);
  return -1;
}

/// The names of every segment, in segment order.
template <class Robot>
std::vector<std::string> segmentNames(const Robot& robot) {
  std::vector<std::string> out;
  for (int i = 0; i < segmentCount(robot); ++i) out.push_back(segmentName(robot, i));
  return out;
}

/// `names` as messages list them: up to 12, quoted and comma-separated ("'a', 'b'"), then
/// ", ... (N in all)" when there are more.
std::string nameList(const std::vector<std::string>& names);

/// findFrame with the message of a failure: Error::OutOfRange and, in `message`, "no segment or
/// link named 'x' (segments: 'a', 'b'; base: 'root')" (nameList's list; no base part when the
/// robot's root_link is empty). On success `out` is set and `message` is untouched.
Status findFrame(const RobotChain& robot, const std::string& name, FrameRef& out, std::string& message);
/// The same on a tree.
Status findFrame(const RobotTree& robot, const std::string& name, FrameRef& out, std::string& message);
/// findJoint with the message of a failure: Error::OutOfRange and "no joint named 'x' (joints:
/// 'j1', 'j2')" in `message`; on success `index` is the joint's index in q order.
Status findJoint(const RobotChain& robot, const std::string& name, int& index, std::string& message);
/// The same on a tree.
Status findJoint(const RobotTree& robot, const std::string& name, int& index, std::string& message);

/// The message of an int index that addresses none of `n` items of kind `what` ("segment" or
/// "joint"; `value` as the caller printed it): "segment index 9 out of range for 7 segments (valid
/// -7 .. 6; the base is addressed by its name only)", or for joints "joint index 9 out of range for
/// 7 joints (valid -7 .. 6)".
std::string indexRangeMessage(const std::string& what, const std::string& value, int n);
/// The message of an index argument that is neither a name nor an int (`type_name`: its type's
/// name): "a segment is named by a str (segment or link name) or an int index, got float", or for
/// joints "a joint is named by a str or an int index, got float".
std::string indexTypeMessage(const std::string& what, const std::string& type_name);

/// The names of every link of the description, in RobotChain::links / RobotTree::links order.
template <class Robot>
std::vector<std::string> linkNames(const Robot& robot) {
  std::vector<std::string> out;
  for (const LinkPlacement& l : robot.links) out.push_back(l.link);
  return out;
}

/// A chain or a tree, for code that reads either without knowing which (the Python Chain and
/// Tree's name lookups): each member calls the function of the same name above on the robot it
/// views. It holds a pointer: use it only while that robot lives (it is built per call, cheaply).
class RobotRef {
 public:
  RobotRef(const RobotChain& chain) : chain_(&chain) {}  ///< a view of `chain` (implicit)
  RobotRef(const RobotTree& tree) : tree_(&tree) {}      ///< a view of `tree` (implicit)
  /// The number of segments (the base excluded).
  int segmentCount() const { return tree_ ? vereshchagin::segmentCount(*tree_) : vereshchagin::segmentCount(*chain_); }
  const std::vector<JointInfo>& joints() const { return tree_ ? tree_->joints : chain_->joints; }  ///< q order
  /// findFrame on the robot, with its message.
  Status findFrame(const std::string& name, FrameRef& out, std::string& message) const {
    return tree_ ? vereshchagin::findFrame(*tree_, name, out, message)
                 : vereshchagin::findFrame(*chain_, name, out, message);
  }
  /// findJoint on the robot, with its message (`index`: q order).
  Status findJoint(const std::string& name, int& index, std::string& message) const {
    return tree_ ? vereshchagin::findJoint(*tree_, name, index, message)
                 : vereshchagin::findJoint(*chain_, name, index, message);
  }
  /// Model(robot, options): its segments in the robot's segment order (a tree's: robot_tree.hpp).
  Model model(const ModelOptions& options) const;

 private:
  const RobotChain* chain_ = nullptr;
  const RobotTree* tree_ = nullptr;
};

/// The serial chain from the tree's base to segment `tip` (0 <= tip < segmentCount): that path's
/// segments, their joints and the links placed on them or on the base, the base's root_link, the
/// tree's note about its root link and a note naming how many segments were left out.
RobotChain pathChain(const RobotTree& robot, int tip);

}  // namespace vereshchagin
