// Recursive dynamics sweeps over a Tree's parent array (segment order, parent[i] < i), written
// from the spatial-vector equations (Featherstone, "Rigid Body Dynamics Algorithms", 2008, ch. 5
// and 6) in one fixed frame: every twist, acceleration, wrench and inertia below has base-frame
// axes and its reference point at the base origin, so nothing is transformed between links.
// Spatial vectors are KDL's [linear; angular] (Twist: velocity of the body point at the base
// origin and angular velocity; Wrench: force and moment about the base origin).
#pragma once

#include <vector>

#include <Eigen/Dense>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

#include "tree_bindings.hpp"

namespace vsbind {

// Position-level quantities of every segment at one q (the first sweep of every companion).
struct TreePlacement {
  std::vector<KDL::Frame> tip;   // tip frame of each segment in the base frame
  std::vector<KDL::Twist> axis;  // unit joint twist S_i per unit qd (zero for a fixed joint)
  std::vector<int> q_index;      // index of each segment's joint in q (-1: a fixed joint)
};

// Tip frames and joint twists of every segment of `tree` at joint positions q.
TreePlacement placeTree(const PyTree& tree, const KDL::JntArray& q);

// Velocity v_i and acceleration a_i of every segment (base-origin twists) for joint rates qd, qdd
// with the base accelerated by `base_acc` (use [-gravity; 0] to include gravity).
void treeMotion(const PyTree& tree, const TreePlacement& at, const KDL::JntArray& qd, const KDL::JntArray& qdd,
                const KDL::Twist& base_acc, std::vector<KDL::Twist>& v, std::vector<KDL::Twist>& a);

// Inverse dynamics (recursive Newton-Euler): tau_j = S_i . f_i + rotor_j qdd_j, f_i the wrench
// segment i's joint transmits (its body's rate of momentum minus f_ext[i], plus its children's
// f). f_ext: per segment, the wrench ON it BY the environment, base axes, about the base origin.
KDL::JntArray treeInverseDynamics(const PyTree& tree, const TreePlacement& at, const KDL::JntArray& qd,
                                  const KDL::JntArray& qdd, const std::vector<KDL::Wrench>& f_ext,
                                  const KDL::Vector& gravity);

// Joint-space mass matrix by composite rigid bodies: H_jk = S_j . (Ic_i S_k) for j the joint of
// segment i and k a joint on its path to the base (Ic_i: segment i and everything below it),
// rotor inertia on the diagonal.
Eigen::MatrixXd treeMassMatrix(const PyTree& tree, const TreePlacement& at);

}  // namespace vsbind
