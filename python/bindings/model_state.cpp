// Pickle states of Chain and Tree as tuples of robot_state.hpp's records (model_state.hpp), and
// from_urdf.
#include "model_state.hpp"

#include <pybind11/stl.h>

#include <array>
#include <fstream>
#include <limits>

#include "py_solver.hpp"  // inertiaCheckArg
#include "vereshchagin/robot_state.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace vsbind {

namespace {

constexpr long long kLo = std::numeric_limits<long long>::min(), kHi = std::numeric_limits<long long>::max();

// A state record: a tuple of exactly n entries, read in order as the types asked for.
class Entries {
 public:
  Entries(const py::handle& obj, std::size_t n, std::string what) : what_(std::move(what)) {
    if (!py::isinstance<py::tuple>(obj) || py::len(obj) != n)
      raise(what_ + " must be a tuple of " + std::to_string(n) + " entries");
    t_ = py::reinterpret_borrow<py::tuple>(obj);
  }
  std::string str() { return t_[k_++].cast<std::string>(); }
  double num() { return t_[k_++].cast<double>(); }
  long long integer(const char* entry) { return stateInt(t_[k_++], kLo, kHi, what_ + entry); }
  template <std::size_t N>
  std::array<double, N> doubles(const char* entry) {
    Entries e(t_[k_++], N, what_ + entry);
    std::array<double, N> out{};
    for (double& x : out) x = e.num();
    return out;
  }

 private:
  std::string what_;
  py::tuple t_;
  std::size_t k_ = 0;
};

py::list stateList(const py::handle& obj, const std::string& what) {
  if (!py::isinstance<py::list>(obj)) raise(what + " must be a list");
  return py::reinterpret_borrow<py::list>(obj);
}

template <std::size_t N>
py::tuple toTuple(const std::array<double, N>& a) {
  py::tuple t(N);
  for (std::size_t k = 0; k < N; ++k) t[k] = a[k];
  return t;
}

py::tuple segmentState(const vereshchagin::SegmentRecord& s) {
  return py::make_tuple(s.name, s.joint_name, s.joint_type, toTuple(s.origin), toTuple(s.axis), s.rotor_inertia,
                        s.damping, s.stiffness, toTuple(s.tip), toTuple(s.inertia));
}

// The records of a state tuple (model_state.hpp gives both layouts).
vereshchagin::RobotRecord recordFrom(const py::tuple& state, bool tree, const std::string& what) {
  vereshchagin::RobotRecord r;
  r.root_link = state[tree ? 1 : 4].cast<std::string>();
  for (const auto& item : stateList(state[tree ? 2 : 1], what + ": segments")) {
    const std::string which = what + ": segment " + std::to_string(r.segments.size());
    if (tree && (!py::isinstance<py::tuple>(item) || py::len(item) != 2))
      raise(which + " must be a pair (segment, parent)");
    Entries e(tree ? py::object(item[py::int_(0)]) : py::reinterpret_borrow<py::object>(item), 10, which);
    r.segments.push_back({e.str(), e.str(), e.integer(" joint type"), e.doubles<3>(" joint origin"),
                          e.doubles<3>(" joint axis"), e.num(), e.num(), e.num(), e.doubles<12>(" tip frame"),
                          e.doubles<13>(" inertia")});  // braced lists evaluate left to right
    if (tree) r.segments.back().parent = stateInt(py::object(item[py::int_(1)]), kLo, kHi, which + ": parent index");
  }
  for (const auto& item : stateList(state[tree ? 3 : 2], what + ": joints")) {
    Entries e(item, 9, what + ": joint record");
    r.joints.push_back(
        {{e.str(), e.str(), e.num(), e.num(), e.num(), e.num(), e.num(), e.num()}, e.integer(" segment")});
  }
  for (const auto& item : stateList(state[tree ? 4 : 3], what + ": links")) {
    Entries e(item, 3, what + ": link record");
    r.links.push_back({e.str(), e.integer(" segment"), e.doubles<12>(" frame")});
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
  const vereshchagin::RobotRecord r = vereshchagin::robotRecord(model.robot);
  py::list segments, joints, links;
  for (const auto& s : r.segments)
    segments.append(tree ? py::object(py::make_tuple(segmentState(s), s.parent)) : py::object(segmentState(s)));
  for (const auto& [j, segment] : r.joints)
    joints.append(py::make_tuple(j.name, j.type, j.lower, j.upper, j.velocity_limit, j.effort_limit, j.friction,
                                 j.damping, segment));
  for (const auto& l : r.links) links.append(py::make_tuple(l.link, l.segment, toTuple(l.frame)));
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
  if (state.size() == 7) model.inertia_check = inertiaCheckArg(state[6].cast<std::string>(), what + ": ");
  return model;
}

template py::tuple modelState(const PyChain&);
template py::tuple modelState(const PyTree&);
template PyChain modelFromState(const py::tuple&);
template PyTree modelFromState(const py::tuple&);

template <class Model>
Model modelFromUrdf(const py::object& source, const std::string& root, const std::string& tip,
                    const std::string& inertia_check) {
  vereshchagin::UrdfOptions options;
  options.inertia_check = inertiaCheckArg(inertia_check, "");
  if (!py::isinstance<py::str>(source) && !py::hasattr(source, "__fspath__"))
    raise("source must be URDF XML text or a file path");
  const std::string text = py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>();
  const bool is_text = text.find('<') != std::string::npos;
  if (!is_text && !std::ifstream(text)) raise("URDF source is neither XML text nor a readable file: '" + text + "'");
  Model model;
  model.inertia_check = options.inertia_check;
  const auto r = [&] {
    if constexpr (std::is_same_v<Model, PyTree>)
      return is_text ? vereshchagin::treeFromUrdfString(text, root, options)
                     : vereshchagin::treeFromUrdfFile(text, root, options);
    else
      return is_text ? vereshchagin::chainFromUrdfString(text, root, tip, options)
                     : vereshchagin::chainFromUrdfFile(text, root, tip, options);
  }();
  if (!r.ok) raise(r.message);
  model.robot = r.robot;
  return model;
}

template PyChain modelFromUrdf(const py::object&, const std::string&, const std::string&, const std::string&);
template PyTree modelFromUrdf(const py::object&, const std::string&, const std::string&, const std::string&);

}  // namespace vsbind
