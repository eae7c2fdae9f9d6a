// Segment order of a KDL::Tree (robot_tree.hpp): depth-first preorder, children in stored order;
// copies of a tree and of a RobotTree, all without recursion.
#include "vereshchagin/robot_tree.hpp"

#include <utility>

namespace vereshchagin {

void treeSegmentOrder(const KDL::Tree& tree, std::vector<KDL::SegmentMap::const_iterator>& order,
                      std::vector<int>& parent) {
  order.clear();
  parent.clear();
  std::vector<std::pair<KDL::SegmentMap::const_iterator, int>> stack;  // element, parent index
  const auto push = [&stack](KDL::SegmentMap::const_iterator element, int index) {
    const std::vector<KDL::SegmentMap::const_iterator>& children = GetTreeElementChildren(element->second);
    for (auto c = children.rbegin(); c != children.rend(); ++c) stack.emplace_back(*c, index);
  };
  push(tree.getRootSegment(), -1);
  while (!stack.empty()) {
    const auto [element, p] = stack.back();
    stack.pop_back();
    const int index = static_cast<int>(order.size());
    order.push_back(element);
    parent.push_back(p);
    push(element, index);
  }
}

void copyTree(const KDL::Tree& from, KDL::Tree& to) {
  if (&from == &to) return;
  std::vector<KDL::SegmentMap::const_iterator> order;
  std::vector<int> parent;
  treeSegmentOrder(from, order, parent);
  const std::string root = from.getRootSegment()->first;
  to = KDL::Tree(root);  // a root-only tree: KDL's assignment has nothing to recurse into
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::string& hook = parent[i] < 0 ? root : order[static_cast<std::size_t>(parent[i])]->first;
    to.addSegment(GetTreeElementSegment(order[i]->second), hook);
  }
}

RobotTree::RobotTree(const RobotTree& other)
    : segment_names(other.segment_names),
      parent(other.parent),
      joints(other.joints),
      links(other.links),
      root_link(other.root_link),
      notes(other.notes),
      base(other.base),
      base_inertia(other.base_inertia) {
  copyTree(other.tree, tree);
}

RobotTree::RobotTree(RobotTree&& other)
    : segment_names(std::move(other.segment_names)),
      parent(std::move(other.parent)),
      joints(std::move(other.joints)),
      links(std::move(other.links)),
      root_link(std::move(other.root_link)),
      notes(std::move(other.notes)),
      base(other.base),
      base_inertia(other.base_inertia) {
  copyTree(other.tree, tree);  // KDL::Tree cannot be moved
}

RobotTree& RobotTree::operator=(const RobotTree& other) {
  if (this == &other) return *this;
  copyTree(other.tree, tree);
  segment_names = other.segment_names;
  parent = other.parent;
  joints = other.joints;
  links = other.links;
  root_link = other.root_link;
  notes = other.notes;
  base = other.base;
  base_inertia = other.base_inertia;
  return *this;
}

RobotTree& RobotTree::operator=(RobotTree&& other) {
  if (this == &other) return *this;
  copyTree(other.tree, tree);
  segment_names = std::move(other.segment_names);
  parent = std::move(other.parent);
  joints = std::move(other.joints);
  links = std::move(other.links);
  root_link = std::move(other.root_link);
  notes = std::move(other.notes);
  base = other.base;
  base_inertia = other.base_inertia;
  return *this;
}

}  // namespace vereshchagin
