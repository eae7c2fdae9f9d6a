// PyTree (tree_bindings.hpp): loading, pickle state, kinematics along a root-to-segment path and
// the extraction of one path as a Chain.
#include <algorithm>

#include <pybind11/stl.h>

#include "dynamics_common.hpp"
#include "model_state.hpp"
#include "py_solver.hpp"  // inertiaCheckArg
#include "tree_bindings.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace vsbind {
namespace {

// Appends s to `tree` under segment `parent` of `robot`'s segment order (-1: the root link).
// fromState and setRotorInertia rebuild a KDL::Tree this way in segment order: KDL numbers the
// joints (q_nr) in insertion order, so the joint order stays the segment order's.
void appendSegment(KDL::Tree& tree, const vereshchagin::RobotTree& robot, const KDL::Segment& s, int parent,
                   const char* context) {
  const std::string& hook = parent < 0 ? robot.root_link : robot.segment_names[static_cast<std::size_t>(parent)];
  if (!tree.addSegment(s, hook)) raise(std::string(context) + ": segment '" + s.getName() + "' cannot be added");
}

}  // namespace

PyTree PyTree::fromUrdf(const py::object& source, const std::string& root, vereshchagin::InertiaCheck inertia_check) {
  const UrdfSource src = urdfSourceArg(source);
  vereshchagin::UrdfOptions options;
  options.inertia_check = inertia_check;
  const vereshchagin::UrdfTreeResult r = src.is_text ? vereshchagin::treeFromUrdfString(src.text_or_path, root, options)
                                                     : vereshchagin::treeFromUrdfFile(src.text_or_path, root, options);
  if (!r.ok) raise(r.message);
  PyTree t;
  t.robot = r.robot;
  t.inertia_check = inertia_check;
  return t;
}

py::tuple PyTree::getState() const {
  py::list segments, joints, links;
  for (int i = 0; i < segmentCount(); ++i) segments.append(py::make_tuple(segmentState(segment(i)), robot.parent[i]));
  for (const auto& j : robot.joints) joints.append(jointInfoState(j));
  for (const auto& l : robot.links) links.append(linkState(l));
  return py::make_tuple(1, robot.root_link, segments, joints, links, py::cast(robot.notes),
                        vereshchagin::inertiaCheckName(inertia_check));
}

PyTree PyTree::fromState(const py::tuple& state) {
  if ((state.size() != 6 && state.size() != 7) || !py::isinstance<py::int_>(state[0]) ||
      state[0].cast<long long>() != 1)
    raise("Tree state: unknown format");
  PyTree t;
  t.robot.root_link = state[1].cast<std::string>();
  t.robot.tree = KDL::Tree(t.robot.root_link);
  std::vector<int> moving;
  for (const auto& item : stateList(state[2], "Tree state: segments")) {
    const std::string what = "Tree state: segment " + std::to_string(t.segmentCount());
    if (!py::isinstance<py::tuple>(item) || py::len(item) != 2) raise(what + " must be a pair (segment, parent)");
    const py::tuple entry = py::reinterpret_borrow<py::tuple>(item);
    const KDL::Segment s = segmentFromState(entry[0], what);
    const long long parent = stateInt(entry[1], -1, t.segmentCount() - 1, what + ": parent index");
    if (s.getJoint().getType() != KDL::Joint::Fixed) moving.push_back(t.segmentCount());
    appendSegment(t.robot.tree, t.robot, s, static_cast<int>(parent), "Tree state");
    t.robot.segment_names.push_back(s.getName());
    t.robot.parent.push_back(static_cast<int>(parent));
  }
  for (const auto& item : stateList(state[3], "Tree state: joints"))
    t.robot.joints.push_back(jointInfoFromState(item, "Tree state: joint record"));
  for (const auto& item : stateList(state[4], "Tree state: links"))
    t.robot.links.push_back(linkFromState(item, "Tree state: link record"));
  checkStateIndices(t.robot.joints, t.robot.links, moving, t.segmentCount(), "Tree state");
  t.robot.notes = state[5].cast<std::vector<std::string>>();
  if (state.size() == 7) t.inertia_check = inertiaCheckArg(state[6].cast<std::string>(), "Tree state: ");
  return t;
}

const KDL::Segment& PyTree::segment(int index) const {
  return robot.tree.getSegments().find(segmentName(index))->second.segment;
}

unsigned int PyTree::qIndex(int index) const {
  return GetTreeElementQNr(robot.tree.getSegments().find(segmentName(index))->second);
}

std::vector<int> PyTree::pathTo(int index) const {
  std::vector<int> path;
  for (int s = index; s >= 0; s = robot.parent[static_cast<std::size_t>(s)]) path.push_back(s);
  std::reverse(path.begin(), path.end());
  return path;
}

py::array_t<double> PyTree::rotorInertia() const {
  py::array_t<double> a(static_cast<py::ssize_t>(robot.joints.size()));
  for (std::size_t k = 0; k < robot.joints.size(); ++k)
    a.mutable_data()[k] = segment(static_cast<int>(robot.joints[k].segment)).getJoint().getInertia();
  return a;
}

void PyTree::setRotorInertia(const py::object& values) {
  const Array a = rotorInertiaArg(values, robot.joints.size());
  std::vector<double> rotor(static_cast<std::size_t>(segmentCount()), 0.0);  // per segment
  for (std::size_t k = 0; k < robot.joints.size(); ++k)
    rotor[robot.joints[k].segment] = a.at(static_cast<py::ssize_t>(k));
  KDL::Tree rebuilt(robot.root_link);
  for (int i = 0; i < segmentCount(); ++i) {
    const KDL::Segment& seg = segment(i);
    const KDL::Joint& j = seg.getJoint();
    const KDL::Joint joint =
        j.getType() == KDL::Joint::None ? j : withRotorInertia(j, rotor[static_cast<std::size_t>(i)]);
    appendSegment(rebuilt, robot, KDL::Segment(seg.getName(), joint, seg.getFrameToTip(), seg.getInertia()),
                  robot.parent[static_cast<std::size_t>(i)], "rotor_inertia");
  }
  vereshchagin::copyTree(rebuilt, robot.tree);  // KDL::Tree's assignment recurses per level
  invalidateCompanions();
}

py::array PyTree::fk(const py::object& q_obj, const py::object& which) const {
  return fkOf(*this, q_obj, resolveTarget(which.ptr(), "segment"));
}

py::array PyTree::jacobian(const py::object& q_obj, const py::object& which) const {
  return jacobianOf(*this, q_obj, resolveTarget(which.ptr(), "segment"));
}

py::array PyTree::twist(const py::object& q_obj, const py::object& qd_obj, const py::object& which) const {
  return twistOf(*this, q_obj, qd_obj, resolveTarget(which.ptr(), "segment"));
}

// The tree's Model: its segment order (preorder of the KDL::Tree's children) is the PyTree's.
vereshchagin::Model PyTree::buildModel() const {
  vereshchagin::ModelOptions options;
  options.inertia_check = inertia_check;
  vereshchagin::Model model(robot, options);
  if (model.segmentNames() != robot.segment_names)
    raise("internal error: the tree's C++ model orders its segments differently");
  return model;
}

PyChain PyTree::pathChain(const py::object& tip) const {
  const std::vector<int> path = pathTo(resolveMoving(tip.ptr(), "tip").segment);
  std::vector<int> chain_index(robot.segment_names.size(), -1);
  PyChain c;
  for (std::size_t k = 0; k < path.size(); ++k) {
    chain_index[static_cast<std::size_t>(path[k])] = static_cast<int>(k);
    c.robot.chain.addSegment(segment(path[k]));
  }
  std::vector<int> joint_of(robot.segment_names.size(), -1);  // one pass: linear in the tree's size
  for (std::size_t k = 0; k < robot.joints.size(); ++k) joint_of[robot.joints[k].segment] = static_cast<int>(k);
  for (int s : path) {
    const int j = joint_of[static_cast<std::size_t>(s)];
    if (j < 0) continue;
    vereshchagin::JointInfo info = robot.joints[static_cast<std::size_t>(j)];
    info.segment = static_cast<unsigned int>(chain_index[static_cast<std::size_t>(s)]);
    c.robot.joints.push_back(info);
  }
  for (const auto& l : robot.links) {
    if (l.segment >= 0 && chain_index[static_cast<std::size_t>(l.segment)] < 0) continue;
    c.robot.links.push_back(
        {l.link, l.segment < 0 ? -1 : chain_index[static_cast<std::size_t>(l.segment)], l.in_segment_tip});
  }
  c.robot.root_link = robot.root_link;
  c.inertia_check = inertia_check;
  for (const std::string& note : robot.notes)  // the base is the chain's base too
    if (note.rfind("root link '", 0) == 0) c.robot.notes.push_back(note);
  if (path.size() < robot.segment_names.size())
    c.robot.notes.push_back("extracted from a tree: the " + std::to_string(robot.segment_names.size() - path.size()) +
                            " segments off the path to '" + segmentName(path.back()) + "' are left out");
  return c;
}

}  // namespace vsbind
