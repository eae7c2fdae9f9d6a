// Shared URDF building blocks (urdf_parts.hpp).
#include "urdf_parts.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <unordered_map>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Dense>

#include "model_validation.hpp"

namespace vereshchagin {
namespace urdfparts {

namespace {

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

// urdfdom accepts some documents whose joints make a link its own ancestor (e.g. a joint whose
// parent and child are the same link): every walk down the tree would then never end. Linear:
// each link's way up is walked once, stopping at a link already known to reach the root.
void checkAcyclic(const urdf::ModelInterface& model) {
  for (const auto& entry : model.joints_) {
    const urdf::Joint& j = *entry.second;
    if (j.parent_link_name == j.child_link_name)
      throw LoadError("joint '" + j.name + "' connects link '" + j.child_link_name + "' to itself");
  }
  enum class State { Open, OnWay, Done };
  std::unordered_map<const urdf::Link*, State> state;
  for (const auto& entry : model.links_) state[entry.second.get()] = State::Open;
  std::vector<const urdf::Link*> way;
  for (const auto& entry : model.links_) {
    way.clear();
    for (urdf::LinkConstSharedPtr l = entry.second; l && state[l.get()] != State::Done; l = l->getParent()) {
      if (state[l.get()] == State::OnWay) throw LoadError("the links form a cycle through link '" + l->name + "'");
      state[l.get()] = State::OnWay;
      way.push_back(l.get());
    }
    for (const urdf::Link* l : way) state[l] = State::Done;
    for (const auto& child : entry.second->child_links)
      if (!child || !child->parent_joint) throw LoadError("link '" + entry.first + "' has a child without a joint");
  }
}

// Every link holds its children: releasing the root would release its whole path below it one
// nested destructor call per link. Emptying the child lists first releases the links one by one.
void unlinkTree(urdf::ModelInterface& model) {
  for (auto& entry : model.links_) {
    entry.second->child_links.clear();
    entry.second->child_joints.clear();
  }
  model.root_link_.reset();
}

// The same model, whose release unlinks the tree first (urdf::ModelInterfaceSharedPtr either way).
urdf::ModelInterfaceSharedPtr guarded(urdf::ModelInterfaceSharedPtr model) {
  if (!model) return model;
  urdf::ModelInterface* raw = model.get();
  return urdf::ModelInterfaceSharedPtr(raw, [owner = std::move(model)](urdf::ModelInterface* m) mutable {
    unlinkTree(*m);
    owner.reset();
  });
}

// The name of the element whose tag starts at xml[i] ('<'), up to whitespace, '/' or '>'.
std::string tagName(const std::string& xml, std::size_t i) {
  std::size_t e = i + 1;
  while (e < xml.size() && !std::isspace(static_cast<unsigned char>(xml[e])) && xml[e] != '/' && xml[e] != '>') ++e;
  return xml.substr(i + 1, e - i - 1);
}

// The index just past the '>' that ends the tag starting at xml[i], quoted attribute values
// skipped (they may hold '>'); xml.size() when it does not end. `self_closing`: "/>".
std::size_t tagEnd(const std::string& xml, std::size_t i, bool& self_closing) {
  char quote = 0;
  for (std::size_t k = i + 1; k < xml.size(); ++k) {
    const char c = xml[k];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '>') {
      self_closing = xml[k - 1] == '/';
      return k + 1;
    }
  }
  return xml.size();
}

// Where the markup starting at xml[i] ends when it is a comment, CDATA, processing instruction
// or declaration (no element); 0 otherwise.
std::size_t skipNonElement(const std::string& xml, std::size_t i) {
  static const std::pair<const char*, const char*> kinds[] = {
      {"<!--", "-->"}, {"<![CDATA[", "]]>"}, {"<?", "?>"}, {"<!", ">"}};
  for (const auto& kind : kinds) {
    if (xml.compare(i, std::strlen(kind.first), kind.first) != 0) continue;
    const std::size_t end = xml.find(kind.second, i + std::strlen(kind.first));
    return end == std::string::npos ? xml.size() : end + std::strlen(kind.second);
  }
  return 0;
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

}  // namespace

bool prescan(const std::string& xml, std::string& message) {
  int depth = 0, links = 0;
  std::size_t i = xml.find('<');
  while (i != std::string::npos && i < xml.size()) {
    std::size_t next = skipNonElement(xml, i);
    if (next == 0) {
      bool self_closing = false;
      next = tagEnd(xml, i, self_closing);
      if (i + 1 < xml.size() && xml[i + 1] == '/') {
        --depth;
      } else {
        if (depth == 1 && tagName(xml, i) == "link" && ++links > kMaxLinks) {
          message = "the URDF has more than " + std::to_string(kMaxLinks) +
                    " links; documents this large are refused (urdfdom releases a model recursively along its "
                    "links, which overflows the stack on very long paths)";
          return false;
        }
        if (!self_closing && ++depth > kMaxXmlDepth) {
          message = "the URDF's XML elements are nested more than " + std::to_string(kMaxXmlDepth) +
                    " levels deep; documents this deep are refused (urdfdom's XML reader recurses per level)";
          return false;
        }
      }
    }
    i = xml.find('<', next);
  }
  return true;
}

urdf::ModelInterfaceSharedPtr parseModel(const std::string& xml, std::string& message) {
  if (!prescan(xml, message)) return nullptr;
  std::string messages;
  urdf::ModelInterfaceSharedPtr model = guarded(parse(xml, messages));
  // urdfdom returns a model even when it could not read some values (they silently become 0):
  // any error it reported fails the load.
  if (!model || !messages.empty()) {
    message = "malformed URDF" + (messages.empty() ? std::string() : ": " + messages);
    return nullptr;
  }
  try {
    checkAcyclic(*model);
  } catch (const LoadError& e) {
    message = e.what();
    return nullptr;
  }
  return model;
}

bool readFile(const std::string& path, std::string& text, std::string& message) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found) {
    message = "URDF file '" + path + "' does not exist";
    return false;
  }
  if (status.type() == std::filesystem::file_type::directory) {
    message = "URDF path '" + path + "' is a directory, not a file";
    return false;
  }
  errno = 0;
  std::ifstream in(path);
  if (!in) {
    const int err = errno;
    message = "cannot read URDF file '" + path + "'" + (err ? std::string(": ") + std::strerror(err) : std::string());
    return false;
  }
  std::stringstream ss;
  ss << in.rdbuf();
  text = ss.str();
  return true;
}

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

KDL::Joint kdlJoint(const urdf::Joint& j, const KDL::Frame& origin) {
  KDL::Vector axis(j.axis.x, j.axis.y, j.axis.z);
  const double norm = axis.Norm();
  if (!(norm > 1e-12) || !std::isfinite(norm)) throw LoadError("joint '" + j.name + "' has a zero or invalid axis");
  axis = origin.M * (axis / norm);
  const KDL::Joint::JointType type = j.type == urdf::Joint::PRISMATIC ? KDL::Joint::TransAxis : KDL::Joint::RotAxis;
  return KDL::Joint(j.name, origin.p, axis, type, 1.0, 0.0, 0.0, 0.0, 0.0);
}

JointInfo jointInfo(const urdf::Joint& j, unsigned int segment) {
  JointInfo info;
  info.name = j.name;
  info.type = typeName(j.type);
  info.segment = segment;
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
    info.damping = j.dynamics->damping;
  }
  if (!(info.lower <= info.upper)) throw LoadError("joint '" + j.name + "': lower limit above upper limit");
  if (!(info.friction >= 0.0) || !std::isfinite(info.friction))
    throw LoadError("joint '" + j.name + "': friction must be finite and >= 0");
  if (!(info.damping >= 0.0) || !std::isfinite(info.damping))
    throw LoadError("joint '" + j.name + "': damping must be finite and >= 0");
  return info;
}

void requireSupported(const urdf::Joint& j, const std::string& where, const std::string& advice, bool allow_mimic) {
  if (!isMoving(j) && j.type != urdf::Joint::FIXED)
    throw LoadError(std::string("joint '") + j.name + "' " + where + " is " + typeName(j.type) +
                    "; only revolute, continuous, prismatic and fixed joints are supported" + advice);
  if (j.mimic && isMoving(j) && !allow_mimic)
    throw LoadError("joint '" + j.name + "' " + where + " mimics joint '" + j.mimic->joint_name +
                    "'; mimic joints are not supported" + advice);
}

void foldLink(const urdf::Link& link, const KDL::Frame& in_tip, InertiaCheck check, RigidBody& body,
              std::vector<LinkPlacement>& links) {
  links.push_back({link.name, body.segment, in_tip});
  if (body.segment >= 0) body.inertia = body.inertia + in_tip * linkInertia(link, check);
}

std::string baseMassNote(const urdf::Link& root) {
  double mass = 0.0;
  std::size_t massive = 0;  // links with mass in the base group
  std::vector<const urdf::Link*> stack{&root};
  while (!stack.empty()) {
    const urdf::Link* link = stack.back();
    stack.pop_back();
    if (link->inertial && link->inertial->mass > 0.0) {
      mass += link->inertial->mass;
      ++massive;
    }
    for (const auto& child : link->child_links)
      if (child->parent_joint->type == urdf::Joint::FIXED) stack.push_back(child.get());
  }
  if (!(mass > 0.0)) return std::string();
  char kg[32];
  std::snprintf(kg, sizeof kg, "%.6g kg", mass);
  const bool only_root = massive == 1 && root.inertial && root.inertial->mass > 0.0;
  return "root link '" + root.name + "' carries " + kg + (only_root ? "" : " (with the links fixed to it)") +
         ": the root link is welded to the world, so its mass and inertia do not enter the dynamics. That is right "
         "for a robot bolted down at this link (an arm on a table); for a free-moving robot (a quadruped or "
         "humanoid base) the results are those of the robot with its base held still, as a floating base "
         "(base=\"free\") is not supported yet.";
}

}  // namespace urdfparts
}  // namespace vereshchagin
