// Pickle states of Chain and Tree as tuples of robot_state.hpp's records (read by pybind11's STL
// casters; the C++ library checks the records), and from_urdf's source argument.
#include <pybind11/stl.h>

#include <tuple>

#include "model_class.hpp"
#include "py_solver.hpp"  // inertiaCheckArg
#include "vereshchagin/robot_state.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace vsbind {

namespace {

using vereshchagin::RobotRecord;
using Frame12 = std::array<double, 12>;
using SegmentState = std::tuple<std::string, std::string, long long, std::array<double, 3>, std::array<double, 3>,
                                double, double, double, Frame12, std::array<double, 13>>;
using JointState = std::tuple<std::string, std::string, double, double, double, double, double, double, long long>;
using LinkState = std::tuple<std::string, long long, Frame12>;
// A state's segments, joints and links: a Tree's segments are (segment, parent index) pairs.
template <bool tree>
using Records = std::tuple<std::vector<std::conditional_t<tree, std::pair<SegmentState, long long>, SegmentState>>,
                           std::vector<JointState>, std::vector<LinkState>>;

SegmentState segmentState(const vereshchagin::SegmentRecord& s) {
  return {s.name,          s.joint_name, s.joint_type, s.origin, s.axis,
          s.rotor_inertia, s.damping,    s.stiffness,  s.tip,    s.inertia};
}

void addSegment(RobotRecord& r, const SegmentState& s, long long parent) {
  r.segments.push_back(std::apply([&](const auto&... x) { return vereshchagin::SegmentRecord{x..., parent}; }, s));
}

// The records of a state (model_class.hpp gives both layouts); a malformed entry raises naming `what`.
template <bool tree>
RobotRecord recordFrom(const py::tuple& state, const std::string& what) {
  RobotRecord r;
  Records<tree> records;
  try {
    records = py::make_tuple(state[tree ? 2 : 1], state[tree ? 3 : 2], state[tree ? 4 : 3]).cast<Records<tree>>();
    r.root_link = state[tree ? 1 : 4].template cast<std::string>();
    r.notes = state[5].template cast<std::vector<std::string>>();
  } catch (const py::cast_error&) {
    raise(what + ": malformed records (segments, joints and links must be lists of tuples of the pickled layout)");
  }
  for (const auto& s : std::get<0>(records)) {
    if constexpr (tree)
      addSegment(r, s.first, s.second);
    else
      addSegment(r, s, -1);  // a chain's parent field is unused
  }
  for (const auto& [name, type, lower, upper, velocity, effort, friction, damping, segment] : std::get<1>(records))
    r.joints.push_back({{name, type, lower, upper, velocity, effort, friction, damping}, segment});
  for (const auto& [link, segment, frame] : std::get<2>(records)) r.links.push_back({link, segment, frame});
  return r;
}

}  // namespace

template <class Model>
py::tuple modelState(const Model& model) {
  constexpr bool tree = std::is_same_v<Model, PyTree>;
  const RobotRecord r = vereshchagin::robotRecord(model.robot);
  Records<tree> records;
  for (const auto& s : r.segments) {
    if constexpr (tree)
      std::get<0>(records).emplace_back(segmentState(s), s.parent);
    else
      std::get<0>(records).push_back(segmentState(s));
  }
  for (const auto& [j, segment] : r.joints)
    std::get<1>(records).emplace_back(j.name, j.type, j.lower, j.upper, j.velocity_limit, j.effort_limit, j.friction,
                                      j.damping, segment);
  for (const auto& l : r.links) std::get<2>(records).emplace_back(l.link, l.segment, l.frame);
  const py::tuple t = py::cast(records);  // segments, joints, links
  const char* check = vereshchagin::inertiaCheckName(model.inertia_check);
  if (tree) return py::make_tuple(1, r.root_link, t[0], t[1], t[2], r.notes, check);
  return py::make_tuple(1, t[0], t[1], t[2], r.root_link, r.notes, check);
}

template <class Model>
Model modelFromState(const py::tuple& state) {
  constexpr bool tree = std::is_same_v<Model, PyTree>;
  const std::string what = tree ? "Tree state" : "Chain state";
  if ((state.size() != 6 && state.size() != 7) || !py::isinstance<py::int_>(state[0]) ||
      state[0].cast<long long>() != 1)
    raise(what + ": unknown format");
  Model model;
  std::string message;
  if (!vereshchagin::robotFromRecord(recordFrom<tree>(state, what), model.robot, message)) raise(message);
  if (state.size() == 7) model.inertia_check = inertiaCheckArg(state[6].cast<std::string>(), what + ": ");
  return model;
}

template <class Model>
Model modelFromUrdf(const py::object& source, const std::string& root, const std::string& tip,
                    const std::string& inertia_check) {
  const vereshchagin::UrdfOptions options{inertiaCheckArg(inertia_check, "")};
  if (!py::isinstance<py::str>(source) && !py::hasattr(source, "__fspath__"))
    raise("source must be URDF XML text or a file path");
  const std::string text = py::str(py::module_::import("os").attr("fspath")(source));
  auto r = [&] {
    if constexpr (std::is_same_v<Model, PyTree>)
      return vereshchagin::treeFromUrdf(text, root, options);
    else
      return vereshchagin::chainFromUrdf(text, root, tip, options);
  }();
  if (!r.ok) raise(r.message);
  Model model;
  model.robot = std::move(r.robot);
  model.inertia_check = options.inertia_check;
  return model;
}

template py::tuple modelState(const PyChain&);
template py::tuple modelState(const PyTree&);
template PyChain modelFromState(const py::tuple&);
template PyTree modelFromState(const py::tuple&);
template PyChain modelFromUrdf(const py::object&, const std::string&, const std::string&, const std::string&);
template PyTree modelFromUrdf(const py::object&, const std::string&, const std::string&, const std::string&);

}  // namespace vsbind
