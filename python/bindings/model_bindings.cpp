// vereshchagin.Chain and vereshchagin.Tree: what they share bound once (bindModel), then the
// members only a Tree has. Conversion and argument messages only: the C++ library reads, checks
// and edits the robots (robot_access.hpp, robot_edit.hpp, robot_state.hpp, urdf_loader.hpp).
#include <pybind11/stl.h>

#include <functional>

#include "model_class.hpp"
#include "model_state.hpp"

namespace vsbind {

namespace {

using vereshchagin::JointInfo;

template <class M>
constexpr bool kIsTree = std::is_same_v<M, PyTree>;

py::array_t<double> array(const std::vector<double>& v) {
  return copyVector(v.data(), static_cast<py::ssize_t>(v.size()));
}

// A property of every joint in q order: a float64 array of f's doubles, or a list.
template <class M, class F>
auto eachJoint(F f) {
  return [f](const M& m) {
    std::vector<std::decay_t<decltype(f(JointInfo()))>> v;
    for (const JointInfo& j : m.robot.joints) v.push_back(f(j));
    if constexpr (std::is_same_v<decltype(v), std::vector<double>>)
      return array(v);
    else
      return v;
  };
}

// Sizes, names, the base, notes, joint data, masses, rotor inertia and the indices; docOf("lower")
// is DOCS["Chain.lower"] or DOCS["Tree.lower"].
template <class M, class Doc>
void bindNamesAndData(py::class_<M>& cls, const Doc& docOf) {
  const std::pair<const char*, double JointInfo::*> fields[] = {{"lower", &JointInfo::lower},
                                                                {"upper", &JointInfo::upper},
                                                                {"velocity_limit", &JointInfo::velocity_limit},
                                                                {"effort_limit", &JointInfo::effort_limit},
                                                                {"friction", &JointInfo::friction},
                                                                {"damping", &JointInfo::damping}};
  for (const auto& [name, field] : fields)
    cls.def_property_readonly(name, eachJoint<M>(std::mem_fn(field)), docOf(name));
  cls.def_property_readonly("joint_names", eachJoint<M>(std::mem_fn(&JointInfo::name)), docOf("joint_names"))
      .def_property_readonly("joint_types", eachJoint<M>(std::mem_fn(&JointInfo::type)), docOf("joint_types"))
      .def_property_readonly(
          "n_joints", [](const M& m) { return vereshchagin::jointCount(m.robot); }, docOf("n_joints"))
      .def_property_readonly("n_segments", &M::segmentCount, docOf("n_segments"))
      .def_property_readonly("segment_names", &M::segmentNames, docOf("segment_names"))
      .def_property_readonly(
          "link_names",
          [](const M& m) {
            std::vector<std::string> names;
            for (const auto& l : m.robot.links) names.push_back(l.link);
            return names;
          },
          docOf("link_names"))
      .def_property_readonly(
          "root_link", [](const M& m) { return m.robot.root_link; }, docOf("root_link"))
      .def_property_readonly(
          "notes", [](const M& m) { return m.robot.notes; }, docOf("notes"))
      .def_property_readonly(
          "inertia_check", [](const M& m) { return vereshchagin::inertiaCheckName(m.inertia_check); },
          docOf("inertia_check"))
      .def_property_readonly(
          "segment_masses", [](const M& m) { return array(vereshchagin::segmentMasses(m.robot)); },
          docOf("segment_masses"))
      .def_property("rotor_inertia", &M::rotorInertia, &M::setRotorInertia, docOf("rotor_inertia"))
      .def(
          "segment_index",
          [](const M& m, const py::object& which) { return m.resolveMoving(which.ptr(), "segment_index").segment; },
          py::arg("name"), docOf("segment_index"))
      .def(
          "joint_index", [](const M& m, const py::object& which) { return m.resolveJoint(which.ptr(), "joint_index"); },
          py::arg("name"), docOf("joint_index"));
}

// The frame of fk, jacobian and twist: a Chain's is optional (None: its last segment).
template <class M>
FrameTarget frameArg(const M& m, const py::object& which) {
  if constexpr (kIsTree<M>) return m.resolveTarget(which.ptr(), "segment");
  return m.resolveOptional(which, "segment");
}
template <class M>
auto segmentParameter() {
  if constexpr (kIsTree<M>)
    return py::arg("segment");
  else
    return py::arg("segment") = py::none();
}

// fk, jacobian and twist of a segment or link; pickle, copy and repr.
template <class M, class Doc>
void bindKinematicsAndCopies(py::class_<M>& cls, const Doc& docOf) {
  using Q = const py::object&;
  cls.def(
         "fk", [](const M& m, Q q, Q s) { return fkOf(m, q, frameArg(m, s)); }, py::arg("q"), segmentParameter<M>(),
         docOf("fk"))
      .def(
          "jacobian", [](const M& m, Q q, Q s) { return jacobianOf(m, q, frameArg(m, s)); }, py::arg("q"),
          segmentParameter<M>(), docOf("jacobian"))
      .def(
          "twist", [](const M& m, Q q, Q qd, Q s) { return twistOf(m, q, qd, frameArg(m, s)); }, py::arg("q"),
          py::arg("qd"), segmentParameter<M>(), docOf("twist"))
      .def(py::pickle(&modelState<M>, &modelFromState<M>))
      .def("__copy__", [](const M& m) { return m; })
      .def(
          "__deepcopy__", [](const M& m, const py::dict&) { return m; }, py::arg("memo"))
      .def("__repr__", [](const M& m) {
        return std::string(kIsTree<M> ? "<vereshchagin.Tree with " : "<vereshchagin.Chain with ") +
               std::to_string(m.segmentCount()) + " segments, " + std::to_string(vereshchagin::jointCount(m.robot)) +
               " joints" + (kIsTree<M> ? ", base '" + m.robot.root_link + "'>" : std::string(">"));
      });
}

PyChain pathChain(const PyTree& t, const py::object& tip) {
  PyChain c;
  c.robot = vereshchagin::pathChain(t.robot, t.resolveMoving(tip.ptr(), "tip").segment);
  c.inertia_check = t.inertia_check;
  return c;
}

}  // namespace

template <class M>
py::class_<M> bindModel(py::module_& mod, const char* name) {
  py::class_<M> cls(mod, name, doc(name));
  const std::string prefix = std::string(name) + ".";
  const auto docOf = [prefix](const char* member) { return doc(prefix + member); };
  bindNamesAndData(cls, docOf);
  bindKinematicsAndCopies(cls, docOf);
  return cls;
}
template py::class_<PyChain> bindModel<PyChain>(py::module_&, const char*);

void bindTree(py::module_& mod) {
  py::class_<PyTree> cls = bindModel<PyTree>(mod, "Tree");
  cls.def_static(
         "from_urdf",
         [](const py::object& source, const py::object& root, const std::string& inertia_check) {
           return modelFromUrdf<PyTree>(source, root.is_none() ? "" : root.cast<std::string>(), "", inertia_check);
         },
         py::arg("source"), py::arg("root") = py::none(), py::arg("inertia_check") = "physical", doc("Tree.from_urdf"))
      .def_property_readonly(
          "base_name", [](const PyTree& t) { return t.robot.root_link; }, doc("Tree.base_name"))
      .def_property_readonly(
          "parent",
          [](const PyTree& t) {
            py::array_t<std::int64_t> a(static_cast<py::ssize_t>(t.robot.parent.size()));
            std::copy(t.robot.parent.begin(), t.robot.parent.end(), a.mutable_data());
            return a;
          },
          doc("Tree.parent"))
      .def("chain", &pathChain, py::arg("tip"), doc("Tree.chain"));
}

}  // namespace vsbind
