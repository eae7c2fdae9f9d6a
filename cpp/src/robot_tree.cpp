// Segment order of a KDL::Tree (robot_tree.hpp): depth-first preorder, children in stored order.
#include "vereshchagin/robot_tree.hpp"

namespace vereshchagin {

namespace {

void visit(KDL::SegmentMap::const_iterator element, int parent_index,
           std::vector<KDL::SegmentMap::const_iterator>& order, std::vector<int>& parent) {
  for (const KDL::SegmentMap::const_iterator& child : GetTreeElementChildren(element->second)) {
    const int index = static_cast<int>(order.size());
    order.push_back(child);
    parent.push_back(parent_index);
    visit(child, index, order, parent);
  }
}

}  // namespace

void treeSegmentOrder(const KDL::Tree& tree, std::vector<KDL::SegmentMap::const_iterator>& order,
                      std::vector<int>& parent) {
  order.clear();
  parent.clear();
  visit(tree.getRootSegment(), -1, order, parent);
}

}  // namespace vereshchagin
