// vereshchagin.Chain and vereshchagin.Tree: what they share bound once (bindModel), then the
// members only a Tree has. Conversion and argument messages only: the C++ library reads, checks
// and edits the robots (robot_access.hpp, robot_edit.hpp, robot_state.hpp, urdf_loader.hpp).
#include <pybind11/stl.h>

#include "model_class.hpp"
#include "model_state.hpp"

namespace vsbind {

namespace {

using vereshchagin::JointInfo;

py::array_t<double> array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// A property of every joint (in q order) or link: a float64 array of doubles, or a list.
template <class M, class T, class Item>
auto each(T Item::*field) {
  return [field](const M& m) {
    std::vector<T> v;
    if constexpr (std::is_same_v<Item, JointInfo>)
      for (const JointInfo& j : m.robot.joints) v.push_back(j.*field);
    else
      for (const Item& l : m.robot.links) v.push_back(l.*field);
    if constexpr (std::is_same_v<T, double>)
      return array(v);
    else
      return v;
  };
}

std::string repr(const PyChain& c) {
  return "<vereshchagin.Chain with " + std::to_string(c.segmentCount()) + " segments, " +
         std::to_string(vereshchagin::jointCount(c.robot)) + " joints>";
}
std::string repr(const PyTree& t) {
  return "<vereshchagin.Tree with " + std::to_string(t.segmentCount()) + " segments, " +
         std::to_string(vereshchagin::jointCount(t.robot)) + " joints, base '" + t.robot.root_link + "'>";
}

PyChain pathChain(const PyTree& t, const py::object& tip) {
  PyChain c;
  c.robot = vereshchagin::pathChain(t.robot, t.resolveMoving(tip.ptr(), "tip").segment);
  c.inertia_check = t.inertia_check;
  return c;
}

}  // namespace

// Sizes, names, the base, notes, joint data, masses, rotor inertia, the indices, pickle, copies
// and repr; the docstring of Chain.lower is DOCS["Chain.lower"].
template <class M>
py::class_<M> bindModel(py::module_& mod, const char* name) {
  py::class_<M> cls(mod, name, doc(name));
  const auto docOf = [prefix = std::string(name) + "."](const char* member) { return doc(prefix + member); };
  const auto prop = [&](const char* member, auto get) { cls.def_property_readonly(member, get, docOf(member)); };
  const char* names[] = {"lower", "upper", "velocity_limit", "effort_limit", "friction", "damping"};
  double JointInfo::*fields[] = {&JointInfo::lower,        &JointInfo::upper,    &JointInfo::velocity_limit,
                                 &JointInfo::effort_limit, &JointInfo::friction, &JointInfo::damping};
  for (int k = 0; k < 6; ++k) prop(names[k], each<M>(fields[k]));
  prop("joint_names", each<M>(&JointInfo::name));
  prop("joint_types", each<M>(&JointInfo::type));
  prop("link_names", each<M>(&vereshchagin::LinkPlacement::link));
  prop("n_joints", [](const M& m) { return vereshchagin::jointCount(m.robot); });
  prop("n_segments", &M::segmentCount);
  prop("segment_names", &M::segmentNames);
  prop("root_link", [](const M& m) { return m.robot.root_link; });
  prop("notes", [](const M& m) { return m.robot.notes; });
  prop("inertia_check", [](const M& m) { return vereshchagin::inertiaCheckName(m.inertia_check); });
  prop("segment_masses", [](const M& m) { return array(vereshchagin::segmentMasses(m.robot)); });
  // rotor_inertia: one per joint in q order; the setter (shape (n_joints,), >= 0) rebuilds the robot.
  const auto setRotorInertia = [](M& m, O values) {
    const F64View a = vectorView(values.ptr(), "rotor_inertia", static_cast<py::ssize_t>(m.robot.joints.size()));
    std::string message;
    if (!vereshchagin::setRotorInertia(m.robot, std::vector<double>(a.data, a.data + a.size()), message))
      raise(message);
    m.invalidateCompanions();
  };
  cls.def_property(
         "rotor_inertia", [](const M& m) { return array(vereshchagin::rotorInertia(m.robot)); }, setRotorInertia,
         docOf("rotor_inertia"))
      .def(
          "segment_index", [](const M& m, O which) { return m.resolveMoving(which.ptr(), "segment_index").segment; },
          py::arg("name"), docOf("segment_index"))
      .def(
          "joint_index", [](const M& m, O which) { return m.resolveJoint(which.ptr(), "joint_index"); },
          py::arg("name"), docOf("joint_index"))
      .def(py::pickle(&modelState<M>, &modelFromState<M>))
      .def("__copy__", [](const M& m) { return m; })
      .def(
          "__deepcopy__", [](const M& m, const py::dict&) { return m; }, py::arg("memo"))
      .def("__repr__", [](const M& m) { return repr(m); });
  return cls;
}
template py::class_<PyChain> bindModel<PyChain>(py::module_&, const char*);

void bindTree(py::module_& mod) {
  const auto fromUrdf = [](O source, O root, const std::string& inertia_check) {
    return modelFromUrdf<PyTree>(source, root.is_none() ? "" : root.cast<std::string>(), "", inertia_check);
  };
  const auto parent = [](const PyTree& t) {
    py::array_t<std::int64_t> a(static_cast<py::ssize_t>(t.robot.parent.size()));
    std::copy(t.robot.parent.begin(), t.robot.parent.end(), a.mutable_data());
    return a;
  };
  bindModel<PyTree>(mod, "Tree")
      .def_static("from_urdf", fromUrdf, py::arg("source"), py::arg("root") = py::none(),
                  py::arg("inertia_check") = "physical", doc("Tree.from_urdf"))
      .def_property_readonly(
          "base_name", [](const PyTree& t) { return t.robot.root_link; }, doc("Tree.base_name"))
      .def_property_readonly("parent", parent, doc("Tree.parent"))
      .def("chain", &pathChain, py::arg("tip"), doc("Tree.chain"));
}

}  // namespace vsbind
