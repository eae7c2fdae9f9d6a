// TreeHdSolver: a KDL::Tree below a root segment as HdCore's model source (depth-first
// preorder, parent array, joints in preorder = the q_nr order of KDL's tree solvers). Conventions in
// tree_hd_solver.hpp.
#include "vereshchagin/tree_hd_solver.hpp"

#include <algorithm>
#include <utility>

#include "hd_core.hpp"
#include "vereshchagin/model.hpp"

namespace vereshchagin {

namespace {

using Element = KDL::SegmentMap::const_iterator;

// Depth-first preorder below `root` (children in the tree's order), without recursion.
void preorder(Element root, std::vector<Element>& order, std::vector<int>& parent) {
  std::vector<std::pair<Element, int>> stack;  // element, parent index
  const auto& top = GetTreeElementChildren(root->second);
  for (auto it = top.rbegin(); it != top.rend(); ++it) stack.emplace_back(*it, -1);
  while (!stack.empty()) {
    const auto [element, p] = stack.back();
    stack.pop_back();
    const int index = static_cast<int>(order.size());
    order.push_back(element);
    parent.push_back(p);
    const auto& children = GetTreeElementChildren(element->second);
    for (auto it = children.rbegin(); it != children.rend(); ++it) stack.emplace_back(*it, index);
  }
}

}  // namespace

namespace detail {

ModelSource treeModelSource(const KDL::Tree& tree, const std::string& root_name) {
  detail::ModelSource src;
  const std::string name = root_name.empty() ? tree.getRootSegment()->first : root_name;
  const auto root = tree.getSegment(name);
  if (root == tree.getSegments().end()) {
    src.problem = "the tree has no segment '" + name + "' to use as the root";
    return src;
  }
  std::vector<Element> order;
  preorder(root, order, src.parent);
  if (order.empty()) {
    src.problem = "the tree has no segments below the root '" + name + "'";
    return src;
  }
  // Joint indices: the moving joints in preorder, which is the q_nr order of a copy of the tree
  // (KDL's tree solvers keep a copy, and a copy numbers q_nr depth-first).
  int joint = 0;
  for (const Element& element : order) {
    const KDL::Segment& seg = GetTreeElementSegment(element->second);
    src.segments.push_back(seg);
    src.joint.push_back(seg.getJoint().getType() == KDL::Joint::Fixed ? -1 : joint++);
  }
  return src;
}

}  // namespace detail

TreeHdSolver::TreeHdSolver(const KDL::Tree& tree, const KDL::Twist& root_acc, const SolverOptions& options,
                           const std::string& root_segment)
    : HdSolver(Model(tree, root_segment, ModelOptions{options.inertia_check}), root_acc, options),
      root_name_(root_segment) {
  if (root_name_.empty()) root_name_ = tree.getRootSegment()->first;
}

const std::vector<std::string>& TreeHdSolver::jointNames() const {
  return model().jointNames();
}
const std::vector<std::string>& TreeHdSolver::segmentNames() const {
  return model().segmentNames();
}
const std::vector<int>& TreeHdSolver::parent() const {
  return model().parents();
}
int TreeHdSolver::segmentIndex(const std::string& name) const {
  return model().segmentIndex(name);
}

}  // namespace vereshchagin
