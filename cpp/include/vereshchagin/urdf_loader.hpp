// URDF (parsed with urdfdom, no ROS) -> serial RobotChain from a root link to a tip link.
//
// Frames: the chain's base frame is the root link's frame. Each moving joint on the path starts a
// segment; the segment's rigid body is the joint's child link plus every link attached to it
// through fixed joints (on the path up to the next moving joint, and fixed side branches), with
// masses and inertias combined. The segment's tip frame is the frame of the last path link of
// that rigid group: the parent link of the next moving joint, or the tip link for the last
// segment. So constraints and wrenches on the last segment refer to the tip link's frame, and a
// gripper attached by fixed joints adds its mass to the last moving link.
//
// Joint axes may point in any direction (normalised); revolute, continuous and prismatic joints
// are supported on the path. Side branches that hang off the path through moving joints are
// lumped rigidly at joint position 0 (recorded in RobotChain::notes).
#pragma once

#include <string>

#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/robot_chain.hpp"

namespace vereshchagin {

struct UrdfResult {
  bool ok = false;
  std::string message;  // why loading failed (empty when ok)
  RobotChain robot;
};

struct UrdfOptions {
  // How each link's <inertial> is checked (inertia_check.hpp): Physical (default) rejects links
  // that are no rigid body (the message names the joint_space option); JointSpace accepts any
  // symmetric inertia with mass >= 0 (identified models) and leaves the check of the joint-space
  // inertia to the solver (whose SolverOptions::inertia_check must then be JointSpace too).
  InertiaCheck inertia_check = InertiaCheck::Physical;
};

// xml: the URDF document. root / tip: link names; empty root = the URDF's root link, empty tip =
// the single leaf below root (an error names the leaves when the tree branches).
UrdfResult chainFromUrdfString(const std::string& xml, const std::string& root = "", const std::string& tip = "",
                               const UrdfOptions& options = UrdfOptions());
UrdfResult chainFromUrdfFile(const std::string& path, const std::string& root = "", const std::string& tip = "",
                             const UrdfOptions& options = UrdfOptions());

}  // namespace vereshchagin
