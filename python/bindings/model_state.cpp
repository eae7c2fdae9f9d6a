// Pickle states of Chain and Tree as tuples of robot_state.hpp's records (model_state.hpp), and
// the URDF source argument.
#include "model_state.hpp"

#include <pybind11/stl.h>

#include <array>
#include <fstream>
#include <limits>
#include <type_traits>

#include "vereshchagin/robot_state.hpp"

namespace vsbind {

namespace {

using vereshchagin::RobotRecord;
constexpr long long kLo = std::numeric_limits<long long>::min(), kHi = std::numeric_limits<long long>::max();

// A state record: a tuple of exactly n entries.
py::tuple record(const py::handle& obj, std::size_t n, const std::string& what) {
  if (!py::isinstance<py::tuple>(obj) || py::len(obj) != n)
    raise(what + " must be a tuple of " + std::to_string(n) + " entries");
  return py::reinterpret_borrow<py::tuple>(obj);
}

py::list stateList(const py::handle& obj, const std::string& what) {
  if (!py::isinstance<py::list>(obj)) raise(what + " must be a list");
  return py::reinterpret_borrow<py::list>(obj);
}

template <std::size_t N>
py::tuple doublesState(const std::array<double, N>& a) {
  py::tuple t(N);
  for (std::size_t k = 0; k < N; ++k) t[k] = a[k];
  return t;
}

template <std::size_t N>
std::array<double, N> doublesFrom(const py::handle& obj, const std::string& what) {
  const py::tuple t = record(obj, N, what);
  std::array<double, N> out{};
  for (std::size_t k = 0; k < N; ++k) out[k] = t[k].cast<double>();
  return out;
}

py::tuple segmentState(const vereshchagin::SegmentRecord& s) {
  return py::make_tuple(s.name, s.joint_name, s.joint_type, doublesState(s.origin), doublesState(s.axis),
                        s.rotor_inertia, s.damping, s.stiffness, doublesState(s.tip), doublesState(s.inertia));
}

vereshchagin::SegmentRecord segmentFrom(const py::handle& obj, const std::string& what) {
  const py::tuple t = record(obj, 10, what);
  vereshchagin::SegmentRecord s;
  s.name = t[0].cast<std::string>();
  s.joint_name = t[1].cast<std::string>();
  s.joint_type = stateInt(t[2], kLo, kHi, what + " joint type");
  s.origin = doublesFrom<3>(t[3], what + " joint origin");
  s.axis = doublesFrom<3>(t[4], what + " joint axis");
  s.rotor_inertia = t[5].cast<double>();
  s.damping = t[6].cast<double>();
  s.stiffness = t[7].cast<double>();
  s.tip = doublesFrom<12>(t[8], what + " tip frame");
  s.inertia = doublesFrom<13>(t[9], what + " inertia");
  return s;
}

py::tuple jointState(const vereshchagin::JointRecord& r) {
  const vereshchagin::JointInfo& j = r.info;
  return py::make_tuple(j.name, j.type, j.lower, j.upper, j.velocity_limit, j.effort_limit, j.friction, j.damping,
                        r.segment);
}

vereshchagin::JointRecord jointFrom(const py::handle& obj, const std::string& what) {
  const py::tuple t = record(obj, 9, what);
  vereshchagin::JointRecord r;
  vereshchagin::JointInfo& j = r.info;
  j.name = t[0].cast<std::string>();
  j.type = t[1].cast<std::string>();
  double* values[] = {&j.lower, &j.upper, &j.velocity_limit, &j.effort_limit, &j.friction, &j.damping};
  for (std::size_t k = 0; k < 6; ++k) *values[k] = t[2 + k].cast<double>();
  r.segment = stateInt(t[8], kLo, kHi, what + " segment");
  return r;
}

// The records of a state tuple (see model_state.hpp for both layouts).
RobotRecord recordFrom(const py::tuple& state, bool tree, const std::string& what) {
  RobotRecord r;
  r.root_link = state[tree ? 1 : 4].cast<std::string>();
  for (const auto& item : stateList(state[tree ? 2 : 1], what + ": segments")) {
    const std::string which = what + ": segment " + std::to_string(r.segments.size());
    if (!tree) {
      r.segments.push_back(segmentFrom(item, which));
      continue;
    }
    if (!py::isinstance<py::tuple>(item) || py::len(item) != 2) raise(which + " must be a pair (segment, parent)");
    const py::tuple entry = py::reinterpret_borrow<py::tuple>(item);
    r.segments.push_back(segmentFrom(entry[0], which));
    r.segments.back().parent = stateInt(entry[1], kLo, kHi, which + ": parent index");
  }
  for (const auto& item : stateList(state[tree ? 3 : 2], what + ": joints"))
    r.joints.push_back(jointFrom(item, what + ": joint record"));
  for (const auto& item : stateList(state[tree ? 4 : 3], what + ": links")) {
    const py::tuple t = record(item, 3, what + ": link record");
    r.links.push_back({t[0].cast<std::string>(), stateInt(t[1], kLo, kHi, what + ": link record segment"),
                       doublesFrom<12>(t[2], what + ": link record frame")});
  }
  r.notes = state[5].cast<std::vector<std::string>>();
  return r;
}

}  // namespace

long long stateInt(const py::handle& obj, long long lo, long long hi, const std::string& what) {
  if (PyBool_Check(obj.ptr()) || !PyLong_Check(obj.ptr())) raise(what + " must be an int");
  const std::optional<long long> v = intWithin(obj.ptr(), lo, hi);
  if (!v) raise(what + " is out of range (" + std::to_string(lo) + " .. " + std::to_string(hi) + ")");
  return *v;
}

template <class Model>
py::tuple modelState(const Model& model) {
  constexpr bool tree = std::is_same_v<Model, PyTree>;
  const RobotRecord r = vereshchagin::robotRecord(model.robot);
  py::list segments, joints, links;
  for (const auto& s : r.segments)
    segments.append(tree ? py::object(py::make_tuple(segmentState(s), s.parent)) : py::object(segmentState(s)));
  for (const auto& j : r.joints) joints.append(jointState(j));
  for (const auto& l : r.links) links.append(py::make_tuple(l.link, l.segment, doublesState(l.frame)));
  const char* check = vereshchagin::inertiaCheckName(model.inertia_check);
  if (tree) return py::make_tuple(1, r.root_link, segments, joints, links, py::cast(r.notes), check);
  return py::make_tuple(1, segments, joints, links, r.root_link, py::cast(r.notes), check);
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
  if (!vereshchagin::robotFromRecord(recordFrom(state, tree, what), model.robot, message)) raise(message);
  if (state.size() == 7) model.inertia_check = modelCheckArg(state[6].cast<std::string>(), what + ": ");
  return model;
}

template py::tuple modelState(const PyChain&);
template py::tuple modelState(const PyTree&);
template PyChain modelFromState(const py::tuple&);
template PyTree modelFromState(const py::tuple&);

UrdfSource urdfSourceArg(const py::object& source) {
  if (!py::isinstance<py::str>(source) && !py::hasattr(source, "__fspath__"))
    raise("source must be URDF XML text or a file path");
  UrdfSource out;
  out.text_or_path = py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>();
  out.is_text = out.text_or_path.find('<') != std::string::npos;
  if (!out.is_text) {
    std::ifstream probe(out.text_or_path);
    if (!probe) raise("URDF source is neither XML text nor a readable file: '" + out.text_or_path + "'");
  }
  return out;
}

}  // namespace vsbind
