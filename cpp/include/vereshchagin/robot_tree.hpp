/// @file
/// A KDL::Tree together with what a robot description says about its joints and links.
///
/// Segment order (the index of a segment everywhere in this library): depth-first preorder from
/// the tree's root, children visited in the order the KDL::TreeElement stores them (their
/// insertion order), the root segment itself (the base) excluded. parent[i] < i for every
/// segment i, -1 for the children of the base; a chain is the tree with parent[i] = i - 1.
///
/// Joint order (q): KDL's q_nr. treeFromUrdf* (urdf_loader.hpp) inserts the segments in the
/// segment order above and gives every segment a moving joint, so q_nr == segment index there.
#pragma once

#include <string>
#include <vector>

#include <kdl/tree.hpp>

#include "vereshchagin/base_kind.hpp"
#include "vereshchagin/robot_chain.hpp"  // JointInfo, LinkPlacement

namespace vereshchagin {

/// Copies and moves rebuild `tree` without recursion (copyTree below): KDL::Tree's own copy
/// recurses once per segment of the deepest path and overflows the stack on very deep trees.
struct RobotTree {
  RobotTree() = default;
  RobotTree(const RobotTree& other);             ///< copies, `tree` without recursion
  RobotTree(RobotTree&& other);                  ///< moves, `tree` rebuilt without recursion
  RobotTree& operator=(const RobotTree& other);  ///< copies, `tree` without recursion
  RobotTree& operator=(RobotTree&& other);       ///< moves, `tree` rebuilt without recursion
  ~RobotTree() = default;

  KDL::Tree tree;                          ///< root segment named root_link (the base frame)
  std::vector<std::string> segment_names;  ///< segment order (see above), root excluded
  std::vector<int> parent;                 ///< per segment: index of the parent segment, -1 = the base
  std::vector<JointInfo> joints;           ///< one per moving joint, in q_nr order; .segment = its segment index
  std::vector<LinkPlacement> links;        ///< every link folded into a segment or into the base (segment -1)
  std::string root_link;                   ///< the base frame
  std::vector<std::string> notes;          ///< approximations made while building
  /// How the base moves (base_kind.hpp); a URDF load's UrdfOptions::base. Model(RobotTree) uses it
  /// unless ModelOptions::base says otherwise.
  BaseKind base = BaseKind::Fixed;
  /// Inertia of the root link and of the links fixed to it, about the root frame's origin in root
  /// axes (kg, m, kg m^2): the floating base body of a URDF load (unused on a fixed base).
  KDL::RigidBodyInertia base_inertia = KDL::RigidBodyInertia::Zero();
};

/// The segments of `tree` in segment order (root excluded) and their parent indices (-1: the
/// root). Allocates; call once per model, not per solve.
void treeSegmentOrder(const KDL::Tree& tree, std::vector<KDL::SegmentMap::const_iterator>& order,
                      std::vector<int>& parent);

/// to = a copy of from, built without recursion (any depth): the same segments under the same
/// root, inserted in segment order, so q_nr is numbered depth-first exactly as KDL's own copy
/// numbers it. Use it instead of KDL::Tree's copy constructor or assignment for deep trees.
void copyTree(const KDL::Tree& from, KDL::Tree& to);

}  // namespace vereshchagin
