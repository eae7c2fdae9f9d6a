// Building blocks shared by the URDF chain and tree loaders: parsing (a size pre-scan, then
// urdfdom, no ROS), validated frames, inertias and joints, the folding of links into one
// segment's rigid body, a walk over a subtree without recursion, and the note on the base's mass.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <urdf_model/model.h>
#include <urdf_world/types.h>
#include <kdl/frames.hpp>
#include <kdl/joint.hpp>
#include <kdl/rigidbodyinertia.hpp>

#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/robot_chain.hpp"

namespace vereshchagin {
namespace urdfparts {

// Thrown by the builders; the loaders turn it into result.message.
struct LoadError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Documents refused before urdfdom sees them (urdf_loader.hpp): urdfdom's XML reader recurses
// once per element nesting level, and releasing a parsed model once per link of its deepest path.
constexpr int kMaxXmlDepth = 1000;  // element nesting levels
constexpr int kMaxLinks = 50000;    // <link> elements of the <robot>
// Checks the document's nesting depth and link count in one linear scan; false with `message`.
bool prescan(const std::string& xml, std::string& message);

// Parses and checks a URDF document (prescan, urdfdom's error messages included, cycles
// rejected). Returns the model, or null with `message` set. Releasing the returned pointer takes
// the link tree apart without recursion.
urdf::ModelInterfaceSharedPtr parseModel(const std::string& xml, std::string& message);
// The file's text; false (message set: missing, a directory, unreadable) when it cannot be read.
bool readFile(const std::string& path, std::string& text, std::string& message);

// The joint's <origin> (child link frame in the parent link frame at q = 0), validated finite.
KDL::Frame jointOrigin(const urdf::Joint& j);
// Revolute, continuous or prismatic.
bool isMoving(const urdf::Joint& j);
// "revolute", "continuous", "prismatic", "fixed", "floating", "planar" or "unknown".
const char* typeName(int urdf_joint_type);
// The link's own inertia in its link frame (zero if it has no <inertial>), validated by `check`.
KDL::RigidBodyInertia linkInertia(const urdf::Link& link, InertiaCheck check);

// The KDL joint of a moving URDF joint whose frame (the child link frame at q = 0) is `origin`
// in the parent segment's tip frame: RotAxis / TransAxis through origin.p along the normalised
// URDF axis (rotated into the tip frame). Throws for a zero or non-finite axis.
KDL::Joint kdlJoint(const urdf::Joint& j, const KDL::Frame& origin);
// Limits, velocity / effort limits, friction and damping of a moving joint, validated.
JointInfo jointInfo(const urdf::Joint& j, unsigned int segment);
// Throws unless `j` is revolute, continuous, prismatic or fixed (and, unless allow_mimic, no
// moving mimic joint); `where` follows the joint's name (e.g. "on the path"), `advice` ends the
// message.
void requireSupported(const urdf::Joint& j, const std::string& where, const std::string& advice, bool allow_mimic);

// One segment's rigid body being assembled: every link folded into it is placed (pose in the
// segment's tip frame) and its inertia added, expressed in the tip frame.
struct RigidBody {
  int segment = -1;  // -1: the base (placements only, inertia ignored)
  KDL::RigidBodyInertia inertia = KDL::RigidBodyInertia::Zero();
};
void foldLink(const urdf::Link& link, const KDL::Frame& in_tip, InertiaCheck check, RigidBody& body,
              std::vector<LinkPlacement>& links);

// Calls visit(link, pose) for `top` and every link below it, depth-first preorder with the
// children in the order urdfdom stores them, without recursion (any depth). pose: the link's
// frame in the frame that `above` (the pose of top's parent link) is expressed in, at q = 0.
template <class Visit>
void walkSubtree(const urdf::Link& top, const KDL::Frame& above, Visit visit) {
  std::vector<std::pair<const urdf::Link*, KDL::Frame>> stack{{&top, above}};
  while (!stack.empty()) {
    const urdf::Link* link = stack.back().first;
    const KDL::Frame pose = stack.back().second * jointOrigin(*link->parent_joint);
    stack.pop_back();
    visit(*link, pose);
    for (auto c = link->child_links.rbegin(); c != link->child_links.rend(); ++c) stack.emplace_back(c->get(), pose);
  }
}

// The note a loader adds when the root link (with the links fixed to it) carries mass that the
// fixed base leaves out of the dynamics; empty when it carries none.
std::string baseMassNote(const urdf::Link& root);

}  // namespace urdfparts
}  // namespace vereshchagin
