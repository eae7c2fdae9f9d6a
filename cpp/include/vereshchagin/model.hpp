/// @file
/// The robot of every solve: an immutable kinematic tree (a chain is the tree whose segment i has
/// parent i - 1), built once from a KDL::Chain, a KDL::Tree or a URDF load, validated, and shared.
///
/// Model / Data / Input (the layers are drawn in docs/architecture.md):
///  * Model (this header): what does not change while the robot runs: segments, parents, joint
///    order, names, merged links, the inertia check. Copying a Model copies a shared pointer to
///    the same immutable robot: one Model serves any number of Data objects and threads.
///  * Data (data.hpp): one per thread: the workspace and the results of the last solve.
///  * SolveInput (input.hpp): everything one solve reads (state, constraints, wrenches, torques,
///    friction, gravity).
///  * solve(model, data, input) (data.hpp) runs the Popov-Vereshchagin sweeps on them; the
///    companions (dynamics.hpp) and kinematics (kinematics.hpp) take a Model too.
///
/// Segment order: depth-first preorder from the base; segment i's parent parent(i) < i (-1: the
/// base), the subtree of i is a contiguous index range. For a chain, the chain's order. Joint
/// order: the moving joints in segment order (KDL's q_nr order for trees; the chain's order for
/// chains). Frames, signs and units of every quantity: hd_solver.hpp.
///
/// Addressing by name, on chains as on trees: a segment by its name; a link merged into a segment
/// by fixed joints (URDF loads keep where each link went) by the link's name, as its segment and
/// its pose in that segment's tip frame; the base by its own name (segment -1).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/segment.hpp>
#include <kdl/tree.hpp>

#include "vereshchagin/base_kind.hpp"
#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/robot_chain.hpp"
#include "vereshchagin/robot_tree.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

namespace detail {
struct ModelImpl;
struct ModelAccess;
}  // namespace detail

/// Options of a Model.
struct ModelOptions {
  /// Which inertial parameters the robot may have (inertia_check.hpp).
  InertiaCheck inertia_check = InertiaCheck::Physical;
  /// How the base moves (base_kind.hpp: the state layout). Fixed (default): welded to the world,
  /// every result as before. For a RobotTree whose `base` is not Fixed (a URDF load with a
  /// floating base), Fixed here means "the tree's own base kind".
  BaseKind base = BaseKind::Fixed;
  /// Inertia of the floating base body: mass (kg), centre of mass and rotational inertia (kg m^2)
  /// about the base frame's origin, in base axes. Added to the root link's (a RobotTree's
  /// base_inertia: the URDF root link and the links fixed to it); the only source of the base's
  /// inertia for KDL chains and trees (a KDL::Tree's root segment has none). Ignored on a fixed
  /// base.
  KDL::RigidBodyInertia base_inertia = KDL::RigidBodyInertia::Zero();
};

/// A named frame resolved on a model: the segment whose rigid body it moves with (-1: the base)
/// and its pose in that segment's tip frame (identity for a segment's own tip frame).
struct FrameRef {
  int segment = -1;                            ///< the segment (-1: the base)
  KDL::Frame in_tip = KDL::Frame::Identity();  ///< the frame's pose in the segment's tip frame
};

/// The robot: an immutable, shared kinematic tree (see the top of this file).
class Model {
 public:
  /// An empty model: status() is Error::InvalidModel.
  Model();
  /// The chain's segments, copied. Never throws for a bad robot: status() says why.
  explicit Model(const KDL::Chain& chain, const ModelOptions& options = ModelOptions());
  /// The sub-tree below root_segment (empty: the tree's root), which serves as the base.
  explicit Model(const KDL::Tree& tree, const std::string& root_segment = std::string(),
                 const ModelOptions& options = ModelOptions());
  /// A URDF load (urdf_loader.hpp): the same, plus the names of merged links and joint data.
  explicit Model(const RobotChain& robot, const ModelOptions& options = ModelOptions());
  /// The same for a tree load.
  explicit Model(const RobotTree& robot, const ModelOptions& options = ModelOptions());

  /// Error::None for a valid robot, else Error::InvalidModel and why.
  Status status() const noexcept;
  const ModelOptions& options() const noexcept;  ///< the options given to the constructor

  unsigned int nrOfJoints() const noexcept;  ///< number of moving joints (n_joints)
  /// Entries of q: n_joints + 7 (free-flyer), + 4 (planar), + 0 (fixed). Layout: base_kind.hpp.
  unsigned int nq() const noexcept;
  /// Entries of q_dot, qdd, ff_torques and tau_command: n_joints + 6, + 3 or + 0 (base_kind.hpp).
  unsigned int nv() const noexcept;
  /// How the base moves: options().base, or a RobotTree's own base kind.
  BaseKind baseKind() const noexcept;
  unsigned int nrOfSegments() const noexcept;  ///< number of segments (n_segments)
  /// parent(i) == i - 1 for every segment.
  bool isChain() const noexcept;

  /// Segment i (tip-frame inertia, joint, pose at q = 0) in the segment order; i < nrOfSegments().
  const KDL::Segment& segment(int i) const;
  const std::vector<KDL::Segment>& segments() const noexcept;  ///< every segment, see segment()
  /// Parent of every segment (-1: the base).
  const std::vector<int>& parents() const noexcept;
  /// Joint index of every segment (-1: a fixed joint), and segment of every joint.
  const std::vector<int>& jointOfSegment() const noexcept;
  const std::vector<int>& segmentOfJoint() const noexcept;  ///< see jointOfSegment()

  const std::vector<std::string>& segmentNames() const noexcept;  ///< in the segment order
  const std::vector<std::string>& jointNames() const noexcept;    ///< in the joint order
  /// The base frame's name: the tree's root segment, a URDF's root link, "base" for a chain.
  const std::string& baseName() const noexcept;
  /// Joint data of a URDF load (limits, friction, ...), one per joint; empty for KDL sources.
  const std::vector<JointInfo>& jointInfos() const noexcept;
  /// Every link of a URDF load and where it went; for KDL sources one entry per segment.
  const std::vector<LinkPlacement>& links() const noexcept;

  /// Segment index by name, -1 if none.
  [[nodiscard]] int segmentIndex(const std::string& name) const noexcept;
  /// Joint index by name, -1 if none.
  [[nodiscard]] int jointIndex(const std::string& name) const noexcept;
  /// A segment, a merged link or the base by name; false if the name is none of them.
  [[nodiscard]] bool findFrame(const std::string& name, FrameRef& out) const noexcept;

  /// True if both refer to the same immutable robot (copies of one Model).
  bool sameAs(const Model& other) const noexcept { return impl_ == other.impl_; }
  const detail::ModelImpl& impl() const noexcept { return *impl_; }  ///< the implementation (internal)

 private:
  friend struct detail::ModelAccess;
  explicit Model(std::shared_ptr<const detail::ModelImpl> impl) : impl_(std::move(impl)) {}
  std::shared_ptr<const detail::ModelImpl> impl_;
};

}  // namespace vereshchagin
