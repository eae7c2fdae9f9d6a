// URDF -> RobotChain. See urdf_loader.hpp for the frame conventions.
#include "vereshchagin/urdf_loader.hpp"

#include <cmath>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Dense>

#include "model_validation.hpp"

namespace vereshchagin {

namespace {

struct LoadError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Collects urdfdom's console messages instead of printing them.
class CaptureHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      if (!messages.empty()) messages += "; ";
      messages += text;
    }
  }
  std::string messages;  // error-level messages only
};

std::mutex& parserMutex() {
  static std::mutex m;
  return m;
}

urdf::ModelInterfaceSharedPtr parse(const std::string& xml, std::string& messages) {
  std::lock_guard<std::mutex> lock(parserMutex());
  CaptureHandler handler;
  console_bridge::useOutputHandler(&handler);
  const console_bridge::LogLevel previous = console_bridge::getLogLevel();
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_WARN);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    handler.messages += e.what();
    model.reset();
  }
  console_bridge::restorePreviousOutputHandler();
  console_bridge::setLogLevel(previous);
  messages = handler.messages;
  return model;
}

KDL::Frame toFrame(const urdf::Pose& p) {
  double x, y, z, w;
  p.rotation.getQuaternion(x, y, z, w);
  return KDL::Frame(KDL::Rotation::Quaternion(x, y, z, w), KDL::Vector(p.position.x, p.position.y, p.position.z));
}

bool finitePose(const urdf::Pose& p) {
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) && std::isfinite(p.position.z) &&
         std::isfinite(p.rotation.x) && std::isfinite(p.rotation.y) && std::isfinite(p.rotation.z) &&
         std::isfinite(p.rotation.w);
}

// The joint's origin, validated.
KDL::Frame jointOrigin(const urdf::Joint& j) {
  if (!finitePose(j.parent_to_joint_origin_transform))
    throw LoadError("joint '" + j.name + "': <origin> xyz / rpy must be finite");
  return toFrame(j.parent_to_joint_origin_transform);
}

bool isMoving(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS || j.type == urdf::Joint::PRISMATIC;
}

const char* typeName(int type) {
  switch (type) {
    case urdf::Joint::REVOLUTE:
      return "revolute";
    case urdf::Joint::CONTINUOUS:
      return "continuous";
    case urdf::Joint::PRISMATIC:
      return "prismatic";
    case urdf::Joint::FLOATING:
      return "floating";
    case urdf::Joint::PLANAR:
      return "planar";
    case urdf::Joint::FIXED:
      return "fixed";
    default:
      return "unknown";
  }
}

// The link's own inertia in its link frame (zero if it has none), validated as `check` says.
KDL::RigidBodyInertia linkInertia(const urdf::Link& link, InertiaCheck check) {
  if (!link.inertial) return KDL::RigidBodyInertia::Zero();
  const urdf::Inertial& in = *link.inertial;
  Eigen::Matrix3d I;  // about the centre of mass, inertial-frame axes
  I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  if (!finitePose(in.origin)) throw LoadError("link '" + link.name + "': <inertial> origin must be finite");
  char buf[320];
  if (const char* why = detail::inertiaProblem(in.mass, I, check, buf, sizeof buf))
    throw LoadError("link '" + link.name + "': " + why);
  const KDL::Frame T = toFrame(in.origin);  // inertial frame in the link frame
  // Rotate the tensor to link axes: R I R^T.
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = T.M(r, c);
  const Eigen::Matrix3d Il = R * I * R.transpose();
  return KDL::RigidBodyInertia(in.mass, T.p,
                               KDL::RotationalInertia(Il(0, 0), Il(1, 1), Il(2, 2), Il(0, 1), Il(0, 2), Il(1, 2)));
}

// All leaves of the subtree below `link`.
void collectLeaves(const urdf::Link& link, std::vector<std::string>& leaves) {
  if (link.child_links.empty()) leaves.push_back(link.name);
  for (const auto& c : link.child_links) collectLeaves(*c, leaves);
}

class Builder {
 public:
  Builder(const urdf::ModelInterface& model, RobotChain& out, InertiaCheck check)
      : model_(model), out_(out), check_(check) {}

  void build(const std::string& root_name, const std::string& tip_name_in) {
    urdf::LinkConstSharedPtr root = model_.getLink(root_name);
    if (!root) throw LoadError("root link '" + root_name + "' not found in the URDF");
    std::string tip_name = tip_name_in;
    if (tip_name.empty()) {
      std::vector<std::string> leaves;
      collectLeaves(*root, leaves);
      if (leaves.size() != 1) {
        std::string list;
        for (const auto& l : leaves) list += (list.empty() ? "" : ", ") + l;
        throw LoadError("the tree below '" + root_name + "' branches (leaves: " + list + "); give the tip link");
      }
      tip_name = leaves.front();
    }
    urdf::LinkConstSharedPtr tip = model_.getLink(tip_name);
    if (!tip) throw LoadError("tip link '" + tip_name + "' not found in the URDF");

    // Path root -> tip, as links.
    std::vector<urdf::LinkConstSharedPtr> path;
    for (urdf::LinkConstSharedPtr l = tip; l; l = l->getParent()) {
      path.insert(path.begin(), l);
      if (l->name == root_name) break;
    }
    if (path.front()->name != root_name)
      throw LoadError("tip link '" + tip_name + "' is not below root link '" + root_name + "'");
    out_.root_link = root_name;

    for (size_t k = 1; k < path.size(); ++k) {
      const urdf::Joint& j = *path[k]->parent_joint;
      if (!isMoving(j) && j.type != urdf::Joint::FIXED)
        throw LoadError(std::string("joint '") + j.name + "' on the path is " + typeName(j.type) +
                        "; only revolute, continuous, prismatic and fixed joints are supported");
      if (j.mimic && isMoving(j))
        throw LoadError("joint '" + j.name + "' on the path mimics joint '" + j.mimic->joint_name +
                        "'; mimic joints are not supported");
    }

    // Walk the path: fixed joints accumulate, each moving joint starts a segment.
    KDL::Frame prev_tip_to_link = KDL::Frame::Identity();  // current path link in the previous tip frame
    // Base group: path links before the first moving joint (and their fixed side branches).
    size_t first_moving = path.size();
    for (size_t i = 1; i < path.size(); ++i) {
      if (isMoving(*path[i]->parent_joint)) {
        first_moving = i;
        break;
      }
    }
    if (first_moving == path.size())
      throw LoadError("no moving joint between '" + root_name + "' and '" + tip_name + "'");
    for (size_t i = 0; i < first_moving; ++i) {
      if (i > 0) prev_tip_to_link = prev_tip_to_link * jointOrigin(*path[i]->parent_joint);
      out_.links.push_back({path[i]->name, -1, prev_tip_to_link});
      // Side branches of the base: fixed to the world, recorded for their frames only.
      for (const auto& child : path[i]->child_links) {
        if (i + 1 < path.size() && child->name == path[i + 1]->name) continue;
        placeBaseSubtree(*child, prev_tip_to_link * jointOrigin(*child->parent_joint));
      }
    }
    size_t k = first_moving;
    while (k < path.size()) {
      const urdf::Joint& j = *path[k]->parent_joint;
      // Group: child link plus following path links reached through fixed joints.
      size_t end = k + 1;
      while (end < path.size() && !isMoving(*path[end]->parent_joint)) ++end;
      const size_t tip_index = end - 1;
      // Poses of the group's path links in the child link (joint) frame at q = 0.
      std::vector<KDL::Frame> in_child(end - k);
      in_child[0] = KDL::Frame::Identity();
      for (size_t i = k + 1; i < end; ++i) in_child[i - k] = in_child[i - k - 1] * jointOrigin(*path[i]->parent_joint);
      const KDL::Frame child_to_tip = in_child[tip_index - k];
      const KDL::Frame tip_inv = child_to_tip.Inverse();

      const int seg_index = static_cast<int>(out_.chain.getNrOfSegments());
      KDL::RigidBodyInertia inertia = KDL::RigidBodyInertia::Zero();
      for (size_t i = k; i < end; ++i) {
        const KDL::Frame link_in_tip = tip_inv * in_child[i - k];
        out_.links.push_back({path[i]->name, seg_index, link_in_tip});
        inertia = inertia + link_in_tip * linkInertia(*path[i], check_);
        // Side branches of this path link.
        for (const auto& child : path[i]->child_links) {
          if (i + 1 < end && child->name == path[i + 1]->name) continue;
          if (i + 1 == end && end < path.size() && child->name == path[end]->name) continue;
          lumpSubtree(*child, link_in_tip * jointOrigin(*child->parent_joint), seg_index, inertia);
        }
      }

      // Joint in the previous tip frame.
      const KDL::Frame origin = prev_tip_to_link * jointOrigin(j);
      KDL::Vector axis(j.axis.x, j.axis.y, j.axis.z);
      const double norm = axis.Norm();
      if (!(norm > 1e-12) || !std::isfinite(norm)) throw LoadError("joint '" + j.name + "' has a zero or invalid axis");
      axis = origin.M * (axis / norm);
      const KDL::Joint::JointType type = j.type == urdf::Joint::PRISMATIC ? KDL::Joint::TransAxis : KDL::Joint::RotAxis;
      const double damping = j.dynamics ? j.dynamics->damping : 0.0;
      KDL::Joint kj(j.name, origin.p, axis, type, 1.0, 0.0, 0.0, 0.0, 0.0);
      out_.chain.addSegment(KDL::Segment(path[tip_index]->name, kj, origin * child_to_tip, inertia));

      JointInfo info;
      info.name = j.name;
      info.type = typeName(j.type);
      info.segment = static_cast<unsigned int>(seg_index);
      if (j.limits) {
        if (j.type != urdf::Joint::CONTINUOUS) {
          info.lower = j.limits->lower;
          info.upper = j.limits->upper;
        }
        if (j.limits->velocity > 0.0) info.velocity_limit = j.limits->velocity;
        if (j.limits->effort > 0.0) info.effort_limit = j.limits->effort;
        if (j.limits->velocity < 0.0 || j.limits->effort < 0.0)
          throw LoadError("joint '" + j.name + "': negative velocity or effort limit");
      }
      if (j.dynamics) {
        info.friction = j.dynamics->friction;
        info.damping = damping;
      }
      if (!(info.lower <= info.upper)) throw LoadError("joint '" + j.name + "': lower limit above upper limit");
      if (!(info.friction >= 0.0) || !std::isfinite(info.friction))
        throw LoadError("joint '" + j.name + "': friction must be finite and >= 0");
      if (!(info.damping >= 0.0) || !std::isfinite(info.damping))
        throw LoadError("joint '" + j.name + "': damping must be finite and >= 0");
      out_.joints.push_back(info);

      prev_tip_to_link = KDL::Frame::Identity();
      k = end;
    }
  }

 private:
  // Fold a side branch (rooted at `link`, whose frame is `pose` in the segment tip frame) into
  // the segment's inertia, rigidly at joint positions 0.
  void lumpSubtree(const urdf::Link& link, const KDL::Frame& pose, int seg, KDL::RigidBodyInertia& inertia) {
    const urdf::Joint& j = *link.parent_joint;
    if (j.type == urdf::Joint::FLOATING || j.type == urdf::Joint::PLANAR)
      throw LoadError(std::string("joint '") + j.name + "' (" + typeName(j.type) +
                      ") attaches a side branch to the chain; floating and planar joints are not supported");
    if (isMoving(j))
      out_.notes.push_back("side branch through moving joint '" + j.name +
                           "' lumped rigidly at position 0 into segment " + std::to_string(seg));
    out_.links.push_back({link.name, seg, pose});
    inertia = inertia + pose * linkInertia(link, check_);
    for (const auto& child : link.child_links)
      lumpSubtree(*child, pose * jointOrigin(*child->parent_joint), seg, inertia);
  }

  // Links hanging off the base (at joint positions 0): frames only, their inertia is irrelevant.
  void placeBaseSubtree(const urdf::Link& link, const KDL::Frame& pose) {
    out_.links.push_back({link.name, -1, pose});
    for (const auto& child : link.child_links) placeBaseSubtree(*child, pose * jointOrigin(*child->parent_joint));
  }

  const urdf::ModelInterface& model_;
  RobotChain& out_;
  InertiaCheck check_;
};

// urdfdom accepts some documents whose joints make a link its own ancestor (e.g. a joint whose
// parent and child are the same link): every recursive walk below would then never end.
void checkAcyclic(const urdf::ModelInterface& model) {
  for (const auto& entry : model.joints_) {
    const urdf::Joint& j = *entry.second;
    if (j.parent_link_name == j.child_link_name)
      throw LoadError("joint '" + j.name + "' connects link '" + j.child_link_name + "' to itself");
  }
  const std::size_t n = model.links_.size();
  for (const auto& entry : model.links_) {
    std::size_t steps = 0;
    for (urdf::LinkConstSharedPtr l = entry.second; l; l = l->getParent())
      if (++steps > n + 1) throw LoadError("the links form a cycle through link '" + entry.first + "'");
    for (const auto& child : entry.second->child_links)
      if (!child || !child->parent_joint) throw LoadError("link '" + entry.first + "' has a child without a joint");
  }
}

UrdfResult load(const std::string& xml, const std::string& root, const std::string& tip, const UrdfOptions& options) {
  UrdfResult result;
  std::string messages;
  urdf::ModelInterfaceSharedPtr model = parse(xml, messages);
  // urdfdom returns a model even when it could not read some values (they silently become 0):
  // any error it reported fails the load.
  if (!model || !messages.empty()) {
    result.message = "malformed URDF" + (messages.empty() ? std::string() : ": " + messages);
    return result;
  }
  try {
    checkAcyclic(*model);
    Builder(*model, result.robot, options.inertia_check).build(root.empty() ? model->getRoot()->name : root, tip);
  } catch (const LoadError& e) {
    result.message = e.what();
    result.robot = RobotChain();
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace

UrdfResult chainFromUrdfString(const std::string& xml, const std::string& root, const std::string& tip,
                               const UrdfOptions& options) {
  return load(xml, root, tip, options);
}

UrdfResult chainFromUrdfFile(const std::string& path, const std::string& root, const std::string& tip,
                             const UrdfOptions& options) {
  std::ifstream in(path);
  if (!in) {
    UrdfResult r;
    r.message = "cannot read URDF file '" + path + "'";
    return r;
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return load(ss.str(), root, tip, options);
}

}  // namespace vereshchagin
