// Building blocks shared by the URDF chain and tree loaders: parsing (urdfdom, no ROS), validated
// frames, inertias and joints, and the folding of links into one segment's rigid body.
#pragma once

#include <stdexcept>
#include <string>
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

// Parses and checks a URDF document (urdfdom's error messages included, cycles rejected).
// Returns the model, or null with `message` set.
urdf::ModelInterfaceSharedPtr parseModel(const std::string& xml, std::string& message);
// The file's text; false (message set) when it cannot be read.
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

}  // namespace urdfparts
}  // namespace vereshchagin
