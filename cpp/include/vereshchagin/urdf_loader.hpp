/// @file
/// URDF (parsed with urdfdom, no ROS) -> serial RobotChain from a root link to a tip link, or the
/// whole RobotTree below a root link.
///
/// Chains:
/// Frames: the chain's base frame is the root link's frame. Each moving joint on the path starts a
/// segment; the segment's rigid body is the joint's child link plus every link attached to it
/// through fixed joints (on the path up to the next moving joint, and fixed side branches), with
/// masses and inertias combined. The segment's tip frame is the frame of the last path link of
/// that rigid group: the parent link of the next moving joint, or the tip link for the last
/// segment. So constraints and wrenches on the last segment refer to the tip link's frame, and a
/// gripper attached by fixed joints adds its mass to the last moving link.
///
/// Trees: fixed joints are merged the same way. Each moving joint below the root starts a
/// segment whose rigid body is its child link plus every link attached to it through fixed joints
/// (masses and inertias combined); moving joints leaving that group start child segments. The
/// segment's tip frame is the frame of the group's deepest link that lies on the way to every
/// moving joint leaving the group (to every leaf of the group when none leaves it): the parent
/// link of the single next moving joint, or the leaf link, exactly as for a chain. So each
/// root-to-leaf path without side branches gives the same segments as chainFromUrdf(root, leaf).
/// The root link and the links fixed to it form the base (LinkPlacement::segment -1, poses in the
/// root frame). Segment order: depth-first preorder from the root; at every link the children are
/// visited in the alphabetical order of their joints' names (the order urdfdom stores them),
/// links fixed to a segment's body searched depth-first in that order too. The KDL::Tree is built
/// in that order, so its q_nr equals the segment index and RobotTree::joints[k].segment == k.
/// Floating and planar joints anywhere below the root are rejected (the message names the joint
/// and suggests a sub-tree root below it, root=...). Mimic joints (e.g. the second finger of a
/// gripper) become independent joints, each recorded in RobotTree::notes (a chain rejects them).
///
/// Joint axes may point in any direction (normalised); revolute, continuous and prismatic joints
/// are supported on the path. Side branches that hang off the path through moving joints are
/// lumped rigidly at joint position 0 (recorded in RobotChain::notes).
///
/// The base: the root link is welded to the world, so the mass and inertia of the root link and of
/// the links fixed to it enter no result. When they carry mass (e.g. the trunk of a quadruped or
/// humanoid), notes says so with the mass in kg and the root link's name; a floating base is not
/// supported yet.
///
/// Size: the loaders walk the links without recursion, so a path of any length loads (a
/// 20000-link chain in about a second). Documents are refused before urdfdom parses them when they
/// have more than 50000 `<link>` elements (urdfdom releases a model recursively along its links) or
/// XML elements nested more than 1000 levels deep (its XML reader recurses per level).
/// File paths: a missing file, a directory or an unreadable file is an error that says which.
#pragma once

#include <string>

#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/robot_chain.hpp"
#include "vereshchagin/robot_tree.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// The result of chainFromUrdfString() / chainFromUrdfFile().
struct UrdfResult {
  bool ok = false;      ///< whether loading succeeded
  std::string message;  ///< why loading failed (empty when ok)
  RobotChain robot;     ///< the chain (when ok)
};

/// The result of treeFromUrdfString() / treeFromUrdfFile().
struct UrdfTreeResult {
  bool ok = false;      ///< whether loading succeeded
  std::string message;  ///< why loading failed (empty when ok)
  RobotTree robot;      ///< the tree (when ok)
};

/// Options of the URDF loaders.
struct UrdfOptions {
  /// How each link's `<inertial>` is checked (inertia_check.hpp): Physical (default) rejects links
  /// that are no rigid body (the message names the joint_space option); JointSpace accepts any
  /// symmetric inertia with mass >= 0 (identified models) and leaves the check of the joint-space
  /// inertia to the solver (whose SolverOptions::inertia_check must then be JointSpace too).
  InertiaCheck inertia_check = InertiaCheck::Physical;
  /// The base of a tree load (RobotTree::base; chains ignore it): Fixed (default) welds the root
  /// link to the world; FreeFlyer or Planar keep the root link and the links fixed to it as the
  /// floating base body (RobotTree::base_inertia), without the note on the dropped base mass.
  BaseKind base = BaseKind::Fixed;
};

/// xml: the URDF document. root / tip: link names; empty root = the URDF's root link, empty tip =
/// the single leaf below root (an error names the leaves when the tree branches).
UrdfResult chainFromUrdfString(const std::string& xml, const std::string& root = "", const std::string& tip = "",
                               const UrdfOptions& options = UrdfOptions());
/// The same from the URDF file at path (errors say whether it is missing, a directory or unreadable).
UrdfResult chainFromUrdfFile(const std::string& path, const std::string& root = "", const std::string& tip = "",
                             const UrdfOptions& options = UrdfOptions());

/// `source` is either URDF XML text (it holds a '<': chainFromUrdfString) or a file path
/// (chainFromUrdfFile); a path that cannot be opened fails with "URDF source is neither XML text
/// nor a readable file: '<source>'".
UrdfResult chainFromUrdf(const std::string& source, const std::string& root = "", const std::string& tip = "",
                         const UrdfOptions& options = UrdfOptions());

/// xml: the URDF document; root: a link name, empty = the URDF's root link. The tree holds every
/// link below root (see above for fixed-joint merging, segment order and joint order).
UrdfTreeResult treeFromUrdfString(const std::string& xml, const std::string& root = "",
                                  const UrdfOptions& options = UrdfOptions());
/// The same from the URDF file at path (errors say whether it is missing, a directory or unreadable).
UrdfTreeResult treeFromUrdfFile(const std::string& path, const std::string& root = "",
                                const UrdfOptions& options = UrdfOptions());
/// The same from URDF XML text or a file path, told apart as chainFromUrdf does.
UrdfTreeResult treeFromUrdf(const std::string& source, const std::string& root = "",
                            const UrdfOptions& options = UrdfOptions());

/// chainFromUrdf(source, root, tip, options) into `out`, moved. On failure Error::InvalidModel
/// with the result's message in `message`, and `out` unchanged.
Status loadUrdf(const std::string& source, const std::string& root, const std::string& tip, const UrdfOptions& options,
                RobotChain& out, std::string& message);
/// treeFromUrdf(source, root, options) into `out` (`tip` is unused), as the chain's.
Status loadUrdf(const std::string& source, const std::string& root, const std::string& tip, const UrdfOptions& options,
                RobotTree& out, std::string& message);

}  // namespace vereshchagin
