/// @file
/// Acceleration-constrained hybrid dynamics of a KDL::Tree (Popov-Vereshchagin algorithm on a
/// parent array): the tree face of HdSolver (hd_solver.hpp, where the math, frames, signs, units
/// and outputs are stated).
///
/// The solver's robot is the sub-tree below a root segment (default: the tree's root, KDL's
/// virtual segment "root" or whatever the tree was built with). The root segment itself is the
/// base: it is not a solver segment, its frame is the base frame and root_acc is its acceleration.
///
/// Segment order: depth-first preorder from the root, children in the order the tree lists them
/// (KDL's insertion order): segment i's parent parent(i) < i (-1: attached to the base), and the
/// subtree of i is the index range [i, i + size). f_ext has one column per segment in this order,
/// link accelerations one column per segment after the base's column 0.
/// Joint order: the moving joints in the segment order (fixed joints have no index), which is the
/// q_nr order KDL's tree solvers (TreeIdSolver_RNE, TreeJntToJacSolver, TreeFkSolverPos_recursive)
/// use: they keep a copy of the tree, and copying a KDL::Tree numbers q_nr depth-first in this
/// order. A tree built by adding segments in depth-first order (as kdl_parser does from URDF) has
/// these q_nr already; a tree built in another order has other q_nr in the original object but
/// not in its copies. jointNames() lists the order; for a sub-tree root, the joints below it.
/// Constraint columns act on segments by this segment order (segmentIndex(name) finds one); the
/// solve() overload without `segments` puts them on the last segment of the preorder (the last
/// leaf), which is rarely meant for a tree: pass `segments`.
#pragma once

#include <string>
#include <vector>

#include <kdl/tree.hpp>

#include "vereshchagin/hd_solver.hpp"

namespace vereshchagin {

/// The hybrid dynamics solver of a KDL::Tree (see the top of this file and hd_solver.hpp).
class TreeHdSolver : public HdSolver {
 public:
  /// The segments are copied. root_segment: name of the segment that serves as the base (empty: the
  /// tree's root). An unknown root name, a root without moving joints below it or invalid
  /// parameters give modelError() E_INVALID_MODEL with the reason in errorMessage().
  TreeHdSolver(const KDL::Tree& tree, const KDL::Twist& root_acc, const SolverOptions& options = SolverOptions(),
               const std::string& root_segment = std::string());

  /// Names of the moving joints in q order (n_joints).
  const std::vector<std::string>& jointNames() const;
  /// Names of the segments in the solver's segment order (n_segments).
  const std::vector<std::string>& segmentNames() const;
  /// Parent segment index of every segment (-1: the base), in the segment order.
  const std::vector<int>& parent() const;
  /// Index of the named segment in the segment order, or -1 if it is not a solver segment.
  int segmentIndex(const std::string& name) const;
  /// Name of the base (root) segment.
  const std::string& rootName() const { return root_name_; }

 private:
  std::string root_name_;
};

}  // namespace vereshchagin
