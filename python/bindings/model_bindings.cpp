// vereshchagin.Chain and vereshchagin.Tree: what they share bound once (bindModel), then the
// members of each. Conversion and argument messages only: the C++ library checks and edits the
// robots (robot_access.hpp, robot_edit.hpp, robot_state.hpp, urdf_loader.hpp).
#include <pybind11/stl.h>

#include <type_traits>

#include "dynamics_common.hpp"
#include "model_state.hpp"
#include "tree_bindings.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace vsbind {

namespace {

template <class M>
constexpr bool kIsTree = std::is_same_v<M, PyTree>;

// The frame argument of fk, jacobian and twist: a Chain's defaults to its last segment.
template <class M>
FrameTarget frameArg(const M& m, const py::object& which) {
  if constexpr (kIsTree<M>) return m.resolveTarget(which.ptr(), "segment");
  return m.resolveOptional(which, "segment");
}

template <class M, class Get>
auto doubles(Get get) {
  return [get](const M& m) {
    const std::vector<double> v = get(m);
    return copyVector(v.data(), static_cast<py::ssize_t>(v.size()));
  };
}

// The joints' names, types, limits, friction and damping, in q order; docOf("lower") is the
// docstring DOCS["Chain.lower"] or DOCS["Tree.lower"].
template <class M, class Doc>
void bindJointData(py::class_<M>& cls, const Doc& docOf) {
  using vereshchagin::JointInfo;
  const auto field = [](double JointInfo::*f) {
    return doubles<M>([f](const M& m) {
      std::vector<double> v;
      for (const JointInfo& j : m.robot.joints) v.push_back(j.*f);
      return v;
    });
  };
  const auto strings = [](std::string (*get)(const JointInfo&)) {
    return [get](const M& m) {
      std::vector<std::string> v;
      for (const JointInfo& j : m.robot.joints) v.push_back(get(j));
      return v;
    };
  };
  cls.def_property_readonly("joint_names", strings([](const JointInfo& j) { return j.name; }), docOf("joint_names"))
      .def_property_readonly("joint_types", strings([](const JointInfo& j) { return j.type; }), docOf("joint_types"))
      .def_property_readonly("lower", field(&JointInfo::lower), docOf("lower"))
      .def_property_readonly("upper", field(&JointInfo::upper), docOf("upper"))
      .def_property_readonly("velocity_limit", field(&JointInfo::velocity_limit), docOf("velocity_limit"))
      .def_property_readonly("effort_limit", field(&JointInfo::effort_limit), docOf("effort_limit"))
      .def_property_readonly("friction", field(&JointInfo::friction), docOf("friction"))
      .def_property_readonly("damping", field(&JointInfo::damping), docOf("damping"));
}

// Sizes, names, the base, notes, the inertia check, masses, rotor inertia and the indices.
template <class M, class Doc>
void bindNames(py::class_<M>& cls, const Doc& docOf) {
  cls.def_property_readonly(
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
      .def_property_readonly("segment_masses",
                             doubles<M>([](const M& m) { return vereshchagin::segmentMasses(m.robot); }),
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

// The frame parameter of fk, jacobian and twist: optional on a Chain.
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
  const auto segment = segmentParameter<M>();
  cls.def(
         "fk", [](const M& m, const py::object& q, const py::object& s) { return fkOf(m, q, frameArg(m, s)); },
         py::arg("q"), segment, docOf("fk"))
      .def(
          "jacobian",
          [](const M& m, const py::object& q, const py::object& s) { return jacobianOf(m, q, frameArg(m, s)); },
          py::arg("q"), segment, docOf("jacobian"))
      .def(
          "twist",
          [](const M& m, const py::object& q, const py::object& qd, const py::object& s) {
            return twistOf(m, q, qd, frameArg(m, s));
          },
          py::arg("q"), py::arg("qd"), segment, docOf("twist"))
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

}  // namespace

template <class M>
py::class_<M> bindModel(py::module_& mod, const char* name) {
  py::class_<M> cls(mod, name, doc(name));
  const std::string prefix = std::string(name) + ".";
  const auto docOf = [prefix](const char* member) { return doc(prefix + member); };
  bindJointData(cls, docOf);
  bindNames(cls, docOf);
  bindKinematicsAndCopies(cls, docOf);
  return cls;
}
template py::class_<PyChain> bindModel<PyChain>(py::module_&, const char*);

void bindTree(py::module_& mod) {
  py::class_<PyTree> cls = bindModel<PyTree>(mod, "Tree");
  cls.def_static(
         "from_urdf",
         [](const py::object& source, const py::object& root, const std::string& check) {
           vereshchagin::UrdfOptions options;
           options.inertia_check = modelCheckArg(check, "");
           const UrdfSource src = urdfSourceArg(source);
           const std::string root_name = root.is_none() ? std::string() : root.cast<std::string>();
           const vereshchagin::UrdfTreeResult r =
               src.is_text ? vereshchagin::treeFromUrdfString(src.text_or_path, root_name, options)
                           : vereshchagin::treeFromUrdfFile(src.text_or_path, root_name, options);
           if (!r.ok) raise(r.message);
           PyTree t;
           t.robot = r.robot;
           t.inertia_check = options.inertia_check;
           return t;
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
      .def(
          "chain",
          [](const PyTree& t, const py::object& tip) {
            PyChain c;
            c.robot = vereshchagin::pathChain(t.robot, t.resolveMoving(tip.ptr(), "tip").segment);
            c.inertia_check = t.inertia_check;
            return c;
          },
          py::arg("tip"), doc("Tree.chain"));
  bindTreeDynamics(cls);
}

}  // namespace vsbind
