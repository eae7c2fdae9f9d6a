// URDF -> RobotChain. See urdf_loader.hpp for the frame conventions.
#include "vereshchagin/urdf_loader.hpp"

#include <algorithm>
#include <fstream>
#include <utility>

#include <urdf_model/model.h>

#include "urdf_parts.hpp"

namespace vereshchagin {

namespace {

using urdfparts::foldLink;
using urdfparts::isMoving;
using urdfparts::jointOrigin;
using urdfparts::LoadError;
using urdfparts::RigidBody;

// All leaves of the subtree below `top`, depth-first preorder, without recursion.
std::vector<std::string> collectLeaves(const urdf::Link& top) {
  std::vector<std::string> leaves;
  std::vector<const urdf::Link*> stack{&top};
  while (!stack.empty()) {
    const urdf::Link* link = stack.back();
    stack.pop_back();
    if (link->child_links.empty()) leaves.push_back(link->name);
    for (auto c = link->child_links.rbegin(); c != link->child_links.rend(); ++c) stack.push_back(c->get());
  }
  return leaves;
}

class Builder {
 public:
  Builder(const urdf::ModelInterface& model, RobotChain& out, InertiaCheck check)
      : model_(model), out_(out), check_(check) {}

  void build(const std::string& root_name, const std::string& tip_name) {
    const std::vector<urdf::LinkConstSharedPtr> path = pathTo(root_name, tip_name);
    out_.root_link = root_name;
    const std::string base_note = urdfparts::baseMassNote(*path.front());
    if (!base_note.empty()) out_.notes.push_back(base_note);
    for (size_t k = 1; k < path.size(); ++k)
      urdfparts::requireSupported(*path[k]->parent_joint, "on the path", "", false);

    // Walk the path: fixed joints accumulate, each moving joint starts a segment.
    size_t first_moving = path.size();
    for (size_t i = 1; i < path.size(); ++i) {
      if (isMoving(*path[i]->parent_joint)) {
        first_moving = i;
        break;
      }
    }
    if (first_moving == path.size())
      throw LoadError("no moving joint between '" + root_name + "' and '" + path.back()->name + "'");
    KDL::Frame prev_tip_to_link = placeBase(path, first_moving);  // current path link in the previous tip frame
    size_t k = first_moving;
    while (k < path.size()) {
      // Group: child link plus following path links reached through fixed joints.
      size_t end = k + 1;
      while (end < path.size() && !isMoving(*path[end]->parent_joint)) ++end;
      addSegment(path, k, end, prev_tip_to_link);
      prev_tip_to_link = KDL::Frame::Identity();
      k = end;
    }
  }

 private:
  // The links from root to tip (an empty tip: the single leaf below root).
  std::vector<urdf::LinkConstSharedPtr> pathTo(const std::string& root_name, const std::string& tip_name_in) const {
    urdf::LinkConstSharedPtr root = model_.getLink(root_name);
    if (!root) throw LoadError("root link '" + root_name + "' not found in the URDF");
    std::string tip_name = tip_name_in;
    if (tip_name.empty()) {
      const std::vector<std::string> leaves = collectLeaves(*root);
      if (leaves.size() != 1) {
        std::string list;
        for (const auto& l : leaves) list += (list.empty() ? "" : ", ") + l;
        throw LoadError("the tree below '" + root_name + "' branches (leaves: " + list + "); give the tip link");
      }
      tip_name = leaves.front();
    }
    urdf::LinkConstSharedPtr tip = model_.getLink(tip_name);
    if (!tip) throw LoadError("tip link '" + tip_name + "' not found in the URDF");
    std::vector<urdf::LinkConstSharedPtr> path;
    for (urdf::LinkConstSharedPtr l = tip; l; l = l->getParent()) {
      path.push_back(l);
      if (l->name == root_name) break;
    }
    std::reverse(path.begin(), path.end());
    if (path.front()->name != root_name)
      throw LoadError("tip link '" + tip_name + "' is not below root link '" + root_name + "'");
    return path;
  }

  // Base group: path links before the first moving joint (and their side branches), placed in
  // the root frame. Returns the pose of the first moving joint's parent link in the root frame.
  KDL::Frame placeBase(const std::vector<urdf::LinkConstSharedPtr>& path, size_t first_moving) {
    KDL::Frame link_in_root = KDL::Frame::Identity();
    for (size_t i = 0; i < first_moving; ++i) {
      if (i > 0) link_in_root = link_in_root * jointOrigin(*path[i]->parent_joint);
      out_.links.push_back({path[i]->name, -1, link_in_root});
      // Side branches of the base: fixed to the world, recorded for their frames only.
      for (const auto& child : path[i]->child_links) {
        if (i + 1 < path.size() && child->name == path[i + 1]->name) continue;
        placeBaseSubtree(*child, link_in_root);
      }
    }
    return link_in_root;
  }

  // The segment of path[k]'s moving joint: path links k .. end - 1 and their side branches
  // merged; its tip frame is path[end - 1]'s. `prev_tip_to_link`: path[k - 1] in the previous
  // segment's tip frame.
  void addSegment(const std::vector<urdf::LinkConstSharedPtr>& path, size_t k, size_t end,
                  const KDL::Frame& prev_tip_to_link) {
    const urdf::Joint& j = *path[k]->parent_joint;
    const size_t tip_index = end - 1;
    // Poses of the group's path links in the child link (joint) frame at q = 0.
    std::vector<KDL::Frame> in_child(end - k);
    in_child[0] = KDL::Frame::Identity();
    for (size_t i = k + 1; i < end; ++i) in_child[i - k] = in_child[i - k - 1] * jointOrigin(*path[i]->parent_joint);
    const KDL::Frame child_to_tip = in_child[tip_index - k];
    const KDL::Frame tip_inv = child_to_tip.Inverse();

    const int seg_index = static_cast<int>(out_.chain.getNrOfSegments());
    RigidBody body;
    body.segment = seg_index;
    for (size_t i = k; i < end; ++i) {
      const KDL::Frame link_in_tip = tip_inv * in_child[i - k];
      foldLink(*path[i], link_in_tip, check_, body, out_.links);
      // Side branches of this path link.
      for (const auto& child : path[i]->child_links) {
        if (i + 1 < end && child->name == path[i + 1]->name) continue;
        if (i + 1 == end && end < path.size() && child->name == path[end]->name) continue;
        lumpSubtree(*child, link_in_tip, body);
      }
    }
    // Joint in the previous tip frame.
    const KDL::Frame origin = prev_tip_to_link * jointOrigin(j);
    const KDL::Joint kj = urdfparts::kdlJoint(j, origin);
    out_.chain.addSegment(KDL::Segment(path[tip_index]->name, kj, origin * child_to_tip, body.inertia));
    out_.joints.push_back(urdfparts::jointInfo(j, static_cast<unsigned int>(seg_index)));
  }

  // Fold a side branch (rooted at `top`, whose parent link's frame is `above` in the segment tip
  // frame) into the segment's rigid body, rigidly at joint positions 0.
  void lumpSubtree(const urdf::Link& top, const KDL::Frame& above, RigidBody& body) {
    urdfparts::walkSubtree(top, above, [&](const urdf::Link& link, const KDL::Frame& pose) {
      const urdf::Joint& j = *link.parent_joint;
      if (j.type == urdf::Joint::FLOATING || j.type == urdf::Joint::PLANAR)
        throw LoadError(std::string("joint '") + j.name + "' (" + urdfparts::typeName(j.type) +
                        ") attaches a side branch to the chain; floating and planar joints are not supported");
      if (isMoving(j))
        out_.notes.push_back("side branch through moving joint '" + j.name +
                             "' lumped rigidly at position 0 into segment " + std::to_string(body.segment));
      foldLink(link, pose, check_, body, out_.links);
    });
  }

  // Links hanging off the base (at joint positions 0; `above`: the pose of top's parent link in
  // the root frame): frames only, their inertia is irrelevant.
  void placeBaseSubtree(const urdf::Link& top, const KDL::Frame& above) {
    urdfparts::walkSubtree(top, above, [&](const urdf::Link& link, const KDL::Frame& pose) {
      out_.links.push_back({link.name, -1, pose});
    });
  }

  const urdf::ModelInterface& model_;
  RobotChain& out_;
  InertiaCheck check_;
};

UrdfResult load(const std::string& xml, const std::string& root, const std::string& tip, const UrdfOptions& options) {
  UrdfResult result;
  urdf::ModelInterfaceSharedPtr model = urdfparts::parseModel(xml, result.message);
  if (!model) return result;
  try {
    Builder(*model, result.robot, options.inertia_check).build(root.empty() ? model->getRoot()->name : root, tip);
  } catch (const LoadError& e) {
    result.message = e.what();
    result.robot = RobotChain();
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace

UrdfResult chainFromUrdfString(const std::string& xml, const std::string& root, const std::string& tip,
                               const UrdfOptions& options) {
  return load(xml, root, tip, options);
}

UrdfResult chainFromUrdfFile(const std::string& path, const std::string& root, const std::string& tip,
                             const UrdfOptions& options) {
  UrdfResult r;
  std::string xml;
  if (!urdfparts::readFile(path, xml, r.message)) return r;
  return load(xml, root, tip, options);
}

UrdfResult chainFromUrdf(const std::string& source, const std::string& root, const std::string& tip,
                         const UrdfOptions& options) {
  if (source.find('<') != std::string::npos) return chainFromUrdfString(source, root, tip, options);
  if (std::ifstream(source)) return chainFromUrdfFile(source, root, tip, options);
  UrdfResult r;
  r.message = "URDF source is neither XML text nor a readable file: '" + source + "'";
  return r;
}

Status loadUrdf(const std::string& source, const std::string& root, const std::string& tip, const UrdfOptions& options,
                RobotChain& out, std::string& message) {
  auto r = chainFromUrdf(source, root, tip, options);
  if (!r.ok) {
    message = std::move(r.message);
    return Status(Error::InvalidModel, message.c_str());
  }
  out = std::move(r.robot);
  return Status();
}

}  // namespace vereshchagin
