// URDF -> RobotTree. See urdf_loader.hpp for the frame conventions and the segment order.
#include <algorithm>
#include <fstream>
#include <utility>

#include <urdf_model/model.h>

#include "urdf_parts.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace vereshchagin {

namespace {

using urdfparts::jointOrigin;
using urdfparts::LoadError;

// The links rigidly connected (through fixed joints) to a first link, in depth-first order with
// children sorted by joint name, and the moving joints that leave them (in the same order).
struct RigidGroup {
  std::vector<const urdf::Link*> links;
  std::vector<int> parent;           // index in `links` of each link's parent, -1 for the first
  std::vector<KDL::Frame> in_first;  // pose of each link in the first link's frame (q = 0)
  struct Exit {
    const urdf::Joint* joint;
    int from;  // index in `links` of the joint's parent link
  };
  std::vector<Exit> exits;

  // The link whose frame becomes the segment's tip frame: the deepest link that lies on the way
  // from the first link to every exit (to every leaf of the group when no moving joint leaves it).
  int tipIndex() const;
};

std::vector<const urdf::Link*> childrenByJointName(const urdf::Link& link) {
  std::vector<const urdf::Link*> children;
  for (const auto& c : link.child_links) children.push_back(c.get());
  std::sort(children.begin(), children.end(),
            [](const urdf::Link* a, const urdf::Link* b) { return a->parent_joint->name < b->parent_joint->name; });
  return children;
}

int RigidGroup::tipIndex() const {
  std::vector<int> ends;
  for (const Exit& e : exits) ends.push_back(e.from);
  if (ends.empty()) {
    std::vector<bool> has_child(links.size(), false);
    for (std::size_t i = 1; i < links.size(); ++i) has_child[static_cast<std::size_t>(parent[i])] = true;
    for (std::size_t i = 0; i < links.size(); ++i)
      if (!has_child[i]) ends.push_back(static_cast<int>(i));
  }
  // The lowest common ancestor of the ends: the deepest link whose subtree holds all of them.
  // Links are in preorder (parent[i] < i), so one backward pass sums the ends per subtree.
  std::vector<std::size_t> below(links.size(), 0);
  for (int e : ends) ++below[static_cast<std::size_t>(e)];
  for (std::size_t i = links.size() - 1; i > 0; --i) below[static_cast<std::size_t>(parent[i])] += below[i];
  std::vector<int> depth(links.size(), 0);
  int common = 0;
  for (std::size_t i = 1; i < links.size(); ++i) {
    depth[i] = depth[static_cast<std::size_t>(parent[i])] + 1;
    if (below[i] == ends.size() && depth[i] > depth[static_cast<std::size_t>(common)]) common = static_cast<int>(i);
  }
  return common;
}

class TreeBuilder {
 public:
  TreeBuilder(const urdf::ModelInterface& model, RobotTree& out, InertiaCheck check, BaseKind base)
      : model_(model), out_(out), check_(check), base_(base) {}

  void build(const std::string& root_name) {
    urdf::LinkConstSharedPtr root = model_.getLink(root_name);
    if (!root) throw LoadError("root link '" + root_name + "' not found in the URDF");
    out_.root_link = root_name;
    out_.tree = KDL::Tree(root_name);
    const std::string base_note = base_ == BaseKind::Fixed ? urdfparts::baseMassNote(*root) : std::string();
    if (!base_note.empty()) out_.notes.push_back(base_note);
    const RigidGroup base = collectGroup(*root);
    urdfparts::RigidBody body;  // the base: placements in the root frame, inertia below
    out_.base = base_;
    out_.base_inertia = KDL::RigidBodyInertia::Zero();
    for (std::size_t i = 0; i < base.links.size(); ++i) {
      urdfparts::foldLink(*base.links[i], base.in_first[i], check_, body, out_.links);
      if (base_ != BaseKind::Fixed)  // (a fixed base's links are not checked: their inertia is unused)
        out_.base_inertia = out_.base_inertia + base.in_first[i] * urdfparts::linkInertia(*base.links[i], check_);
    }
    std::vector<Pending> first;
    for (const RigidGroup::Exit& e : base.exits)
      first.push_back({e.joint, base.in_first[static_cast<std::size_t>(e.from)], -1});
    addSegments(std::move(first));
    if (out_.joints.empty()) throw LoadError("no moving joint below root link '" + root_name + "'");
  }

 private:
  RigidGroup collectGroup(const urdf::Link& first) {
    RigidGroup g;
    g.links.push_back(&first);
    g.parent.push_back(-1);
    g.in_first.push_back(KDL::Frame::Identity());
    visitChildren(0, g);
    return g;
  }

  // Depth-first preorder over the links below g.links[0] reached through fixed joints (children
  // by joint name), without recursion; moving joints leaving them become exits, in that order.
  void visitChildren(int first, RigidGroup& g) {
    std::vector<std::pair<const urdf::Link*, int>> stack;  // link, index of its parent in g.links
    const auto push = [&](int at) {
      const std::vector<const urdf::Link*> children = childrenByJointName(*g.links[static_cast<std::size_t>(at)]);
      for (auto c = children.rbegin(); c != children.rend(); ++c) stack.emplace_back(*c, at);
    };
    push(first);
    while (!stack.empty()) {
      const auto [child, at] = stack.back();
      stack.pop_back();
      const urdf::Joint& j = *child->parent_joint;
      urdfparts::requireSupported(j, "in the tree below '" + out_.root_link + "'",
                                  "; pick a sub-tree root below it (root='" + child->name + "')", true);
      if (urdfparts::isMoving(j)) {
        if (j.mimic)
          out_.notes.push_back("joint '" + j.name + "' mimics joint '" + j.mimic->joint_name +
                               "': modelled as an independent joint");
        g.exits.push_back({&j, at});
        continue;
      }
      g.links.push_back(child);
      g.parent.push_back(at);
      g.in_first.push_back(g.in_first[static_cast<std::size_t>(at)] * jointOrigin(j));
      push(static_cast<int>(g.links.size()) - 1);
    }
  }

  // A segment still to add: the moving joint, the pose of its parent link in the parent
  // segment's tip frame (identity: the tip link itself), and the parent segment's index (-1: the base).
  struct Pending {
    const urdf::Joint* joint;
    KDL::Frame above;
    int parent;
  };

  // The segments below the base, depth-first preorder (so the KDL q_nr equals the segment
  // index), without recursion: a stack of the segments still to add.
  void addSegments(std::vector<Pending> stack) {
    std::reverse(stack.begin(), stack.end());
    while (!stack.empty()) {
      const Pending p = stack.back();
      stack.pop_back();
      const std::size_t before = stack.size();
      addSegment(*p.joint, p.above * jointOrigin(*p.joint), p.parent, stack);
      std::reverse(stack.begin() + static_cast<std::ptrdiff_t>(before), stack.end());
    }
  }

  // The segment moved by joint `j` (its frame `origin` in the parent segment's tip frame); the
  // moving joints leaving its rigid body are appended to `next` in order.
  void addSegment(const urdf::Joint& j, const KDL::Frame& origin, int parent_index, std::vector<Pending>& next) {
    const RigidGroup g = collectGroup(*model_.getLink(j.child_link_name));
    const std::size_t tip = static_cast<std::size_t>(g.tipIndex());
    const KDL::Frame tip_inv = g.in_first[tip].Inverse();
    const int index = static_cast<int>(out_.segment_names.size());
    urdfparts::RigidBody body;
    body.segment = index;
    for (std::size_t i = 0; i < g.links.size(); ++i)
      urdfparts::foldLink(*g.links[i], tip_inv * g.in_first[i], check_, body, out_.links);
    const std::string name = g.links[tip]->name;
    const std::string hook = parent_index < 0 ? out_.root_link : out_.segment_names[parent_index];
    const KDL::Segment segment(name, urdfparts::kdlJoint(j, origin), origin * g.in_first[tip], body.inertia);
    if (!out_.tree.addSegment(segment, hook)) throw LoadError("segment '" + name + "' could not be added to the tree");
    out_.segment_names.push_back(name);
    out_.parent.push_back(parent_index);
    out_.joints.push_back(urdfparts::jointInfo(j, static_cast<unsigned int>(index)));
    for (const RigidGroup::Exit& e : g.exits) {
      const std::size_t from = static_cast<std::size_t>(e.from);
      // A joint on the tip link itself starts exactly at the tip frame (as in the chain loader).
      next.push_back({e.joint, from == tip ? KDL::Frame::Identity() : tip_inv * g.in_first[from], index});
    }
  }

  const urdf::ModelInterface& model_;
  RobotTree& out_;
  InertiaCheck check_;
  BaseKind base_;
};

UrdfTreeResult loadTree(const std::string& xml, const std::string& root, const UrdfOptions& options) {
  UrdfTreeResult result;
  urdf::ModelInterfaceSharedPtr model = urdfparts::parseModel(xml, result.message);
  if (!model) return result;
  try {
    TreeBuilder(*model, result.robot, options.inertia_check, options.base)
        .build(root.empty() ? model->getRoot()->name : root);
  } catch (const LoadError& e) {
    result.message = e.what();
    result.robot = RobotTree();
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace

UrdfTreeResult treeFromUrdfString(const std::string& xml, const std::string& root, const UrdfOptions& options) {
  return loadTree(xml, root, options);
}

UrdfTreeResult treeFromUrdfFile(const std::string& path, const std::string& root, const UrdfOptions& options) {
  UrdfTreeResult r;
  std::string xml;
  if (!urdfparts::readFile(path, xml, r.message)) return r;
  return loadTree(xml, root, options);
}

UrdfTreeResult treeFromUrdf(const std::string& source, const std::string& root, const UrdfOptions& options) {
  if (source.find('<') != std::string::npos) return treeFromUrdfString(source, root, options);
  if (std::ifstream(source)) return treeFromUrdfFile(source, root, options);
  UrdfTreeResult r;
  r.message = "URDF source is neither XML text nor a readable file: '" + source + "'";
  return r;
}

Status loadUrdf(const std::string& source, const std::string& root, const std::string& /*tip*/,
                const UrdfOptions& options, RobotTree& out, std::string& message) {
  auto r = treeFromUrdf(source, root, options);
  if (!r.ok) {
    message = std::move(r.message);
    return Status(Error::InvalidModel, message.c_str());
  }
  out = std::move(r.robot);
  return Status();
}

}  // namespace vereshchagin
