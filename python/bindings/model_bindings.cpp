// vereshchagin.Chain, vereshchagin.Tree and vereshchagin.Joint: what Chain and Tree share bound
// once (bindModel), then the members only one of them has. Conversion and argument messages only:
// the C++ library reads, checks, edits and records the robots (robot_access.hpp, robot_edit.hpp,
// robot_state.hpp); vereshchagin/_models.py lays out the pickle states.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "model_class.hpp"
#include "py_solver.hpp"  // inertiaCheckArg, the F64View helpers
#include "vereshchagin/base_state.hpp"
#include "vereshchagin/robot_edit.hpp"
#include "vereshchagin/robot_state.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace vsbind {

namespace {

using vereshchagin::JointSpec;

py::array array(const std::vector<double>& v) {
  return py::array_t<double>(py::cast(v));
}

// A function of vereshchagin/_models.py: _state (a model's StateRecords to its state), _records
// (back) or _urdf_text (from_urdf's source as a str).
py::object pyModels(const char* function) {
  return py::module_::import("vereshchagin._models").attr(function);
}

// A pickle state (layouts: vereshchagin/_models.py) back to a model. _records raises "<what>:
// unknown format", a malformed entry raises here, a bad record in the library ("Chain state: ...").
template <class M>
M modelFromState(const py::tuple& state) {
  const std::string what = std::is_same_v<M, PyTree> ? "Tree state" : "Chain state";
  const py::tuple records = pyModels("_records")(state, what);  // (StateRecords, inertia_check)
  vereshchagin::StateRecords r;
  try {
    r = records[0].cast<vereshchagin::StateRecords>();
  } catch (const py::cast_error&) {
    raise(what + ": malformed records (segments, joints and links must be lists of tuples of the pickled layout)");
  }
  M model;
  std::string message;
  if (!vereshchagin::robotFromState(r, model.robot, message)) raise(message);
  if constexpr (std::is_same_v<M, PyTree>)  // a floating base: (kind, inertia), checked by _records
    if (const auto b = records[2].cast<py::object>(); !b.is_none()) {
      const auto base = b.cast<std::pair<std::string, std::array<double, 13>>>();
      if (!vereshchagin::setBaseState(model.robot, base.first, base.second, message)) raise(what + ": " + message);
    }
  model.inertia_check = inertiaCheckArg(records[1].cast<std::string>(), what + ": ");
  return model;
}

// Chain.from_urdf / Tree.from_urdf: `source` is URDF XML text (str holding '<') or a readable file
// path (str or os.PathLike); `tip` is unused for a Tree. Raises SolverError otherwise.
template <class M>
M modelFromUrdf(O source, const std::string& root, const std::string& tip, const std::string& inertia_check,
                const std::string& base = "fixed") {
  M model;
  model.inertia_check = inertiaCheckArg(inertia_check, "");
  vereshchagin::UrdfOptions options{model.inertia_check};
  if (!vereshchagin::baseKindFromName(base, options.base))
    raise("base must be 'fixed', 'free' or 'planar', got " + base);
  const std::string text = pyModels("_urdf_text")(source).cast<std::string>();  // raises for another source
  std::string message;
  if (!vereshchagin::loadUrdf(text, root, tip, options, model.robot, message)) raise(message);
  return model;
}

// Sizes, names, the base, notes, joint records, masses, rotor inertia, indices, pickle and copies
// (repr, joint properties: vereshchagin/_models.py); Chain.n_joints's docstring: DOCS["Chain.n_joints"].
template <class M>
py::class_<M> bindModel(py::module_& mod, const char* name) {
  py::class_<M> cls(mod, name, doc(name));
  const auto docOf = [prefix = std::string(name) + "."](const char* member) { return doc(prefix + member); };
  const auto prop = [&](const char* member, auto get) { cls.def_property_readonly(member, get, docOf(member)); };
  prop("_joints", [](const M& m) { return vereshchagin::recordTuples(vereshchagin::robotRecord(m.robot)).joints; });
  prop("link_names", [](const M& m) { return vereshchagin::linkNames(m.robot); });
  prop("n_joints", [](const M& m) { return vereshchagin::jointCount(m.robot); });
  prop("n_segments", [](const M& m) { return vereshchagin::segmentCount(m.robot); });
  prop("segment_names", [](const M& m) { return vereshchagin::segmentNames(m.robot); });
  prop("root_link", [](const M& m) { return m.robot.root_link; });
  prop("notes", [](const M& m) { return m.robot.notes; });
  prop("inertia_check", [](const M& m) { return vereshchagin::inertiaCheckName(m.inertia_check); });
  prop("segment_masses", [](const M& m) { return array(vereshchagin::segmentMasses(m.robot)); });
  // rotor_inertia: one per joint in q order; the setter (shape (n_joints,), >= 0) rebuilds the robot.
  const auto setRotorInertia = [](M& m, O values) {
    std::string message;
    if (!vereshchagin::setRotorInertia(m.robot, asF64(values.ptr(), "rotor_inertia"), message)) raise(message);
    m.invalidateCompanions();
  };
  const auto rotorInertia = [](const M& m) { return array(vereshchagin::rotorInertia(m.robot)); };
  const auto state = [](O self) {
    const M& m = self.cast<const M&>();
    py::object base = py::none();  // a Tree's base: (kind, the 13 doubles of its inertia)
    if constexpr (std::is_same_v<M, PyTree>)
      base = py::make_tuple(vereshchagin::baseKindName(m.robot.base), vereshchagin::baseInertiaDoubles(m.robot));
    return py::tuple(pyModels("_state")(self, vereshchagin::stateRecords(m.robot), base));
  };
  const auto segmentIndex = [](const M& m, O which) { return m.resolveMoving(which.ptr(), "segment_index").segment; };
  const auto jointIndex = [](const M& m, O which) { return m.resolveJoint(which.ptr(), "joint_index"); };
  const auto copy = [](const M& m) { return m; };
  cls.def_property("rotor_inertia", rotorInertia, setRotorInertia, docOf("rotor_inertia"))
      .def("segment_index", segmentIndex, py::arg("name"), docOf("segment_index"))
      .def("joint_index", jointIndex, py::arg("name"), docOf("joint_index"))
      .def(py::pickle(state, &modelFromState<M>))
      .def("__copy__", copy)
      .def(
          "__deepcopy__", [](const M& m, const py::dict&) { return m; }, py::arg("memo"));
  return cls;
}

JointSpec axisJointArg(KDL::Joint::JointType type, O axis, O origin) {
  JointSpec j;
  const KDL::Vector o = origin.is_none() ? KDL::Vector::Zero() : vec3(origin, "origin");
  if (const vereshchagin::Status s = vereshchagin::axisJoint(type, vec3(axis, "axis"), o, j); !s) raise(s.message());
  return j;
}

JointSpec jointArg(O joint) {
  JointSpec j;
  if (py::isinstance<JointSpec>(joint)) return joint.cast<JointSpec>();
  if (!py::isinstance<py::str>(joint))
    raise("joint must be a joint-type string such as 'rot_z' or a vereshchagin.Joint");
  std::string message;
  if (!vereshchagin::jointFromName(joint.cast<std::string>(), j, message)) raise(message);
  return j;
}

void addSegment(PyChain& c, const std::string& name, O joint, O tip, O mass, O com, O inertia, O rotor,
                const std::string& joint_name, const std::string& inertia_check) {
  const std::string where = "segment '" + name + "': ";  // every message names segment and argument
  const vereshchagin::InertiaCheck check = inertiaCheckArg(inertia_check, where);
  vereshchagin::SegmentSpec spec;
  spec.name = name;
  spec.joint_name = joint_name;
  spec.mass = scalarArg(mass, (where + "mass").c_str());
  spec.rotor_inertia = scalarArg(rotor, (where + "rotor_inertia").c_str());
  spec.joint = jointArg(joint);
  if (!tip.is_none()) spec.tip = frameFrom4x4(tip, (where + "tip").c_str());
  if (!com.is_none()) spec.com = vec3(com, (where + "com").c_str());
  std::string message;
  if (!inertia.is_none() && !vereshchagin::inertiaFromArray(asF64(inertia.ptr(), (where + "inertia").c_str()),
                                                            where + "inertia", spec.inertia, message))
    raise(message);
  if (!vereshchagin::addSegment(c.robot, spec, check, message)) raise(message);
  c.invalidateCompanions();
  if (check == vereshchagin::InertiaCheck::JointSpace) c.inertia_check = check;
}

py::dict segmentSpec(const PyChain& c, O which) {
  const int segment = c.resolveMoving(which.ptr(), "segment").segment;
  const vereshchagin::SegmentSpec s = vereshchagin::segmentSpec(vereshchagin::segmentAt(c.robot, segment));
  const auto vec = [](const KDL::Vector& v) { return array({v.x(), v.y(), v.z()}); };
  py::array tip = newDoubles({4, 4});
  for (int k = 0; k < 16; ++k) doubles(tip)[k] = s.tip(k / 4, k % 4);
  return py::dict(py::arg("name") = s.name, py::arg("joint_type") = vereshchagin::jointTypeName(s.joint.type),
                  py::arg("axis") = s.joint.type == KDL::Joint::Fixed ? py::object(py::none()) : vec(s.joint.axis),
                  py::arg("origin") = vec(s.joint.origin), py::arg("joint_name") = s.joint_name, py::arg("tip") = tip,
                  py::arg("mass") = s.mass, py::arg("com") = vec(s.com),
                  py::arg("inertia") = py::cast(Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(s.inertia)),
                  py::arg("rotor_inertia") = s.rotor_inertia);
}

}  // namespace

void bindChain(py::module_& mod) {
  py::class_<JointSpec> joint(mod, "Joint", doc("Joint"));
  for (const auto& [name, type] : {std::pair{"revolute", KDL::Joint::RotAxis}, {"prismatic", KDL::Joint::TransAxis}})
    joint.def_static(
        name, [type = type](O axis, O origin) { return axisJointArg(type, axis, origin); }, py::arg("axis"),
        py::arg("origin") = py::none(), doc(std::string("Joint.") + name));
  const auto fixed = [] { return JointSpec(); };
  joint.def_static("fixed", fixed, doc("Joint.fixed")).def("__repr__", &vereshchagin::jointExpression);
  bindModel<PyChain>(mod, "Chain")
      .def(py::init<>())
      .def("add_segment", &addSegment, doc("Chain.add_segment"), py::arg("name"), py::arg("joint"),
           py::arg("tip") = py::none(), py::arg("mass") = 0.0, py::arg("com") = py::none(),
           py::arg("inertia") = py::none(), py::arg("rotor_inertia") = 0.0, py::arg("joint_name") = "",
           py::arg("inertia_check") = "physical")
      .def("segment_spec", &segmentSpec, py::arg("segment"), doc("Chain.segment_spec"))
      .def_static(
          "from_urdf",
          [](O s, const std::string& r, const std::string& t, const std::string& c) {
            return modelFromUrdf<PyChain>(s, r, t, c);
          },
          py::arg("source"), py::arg("root") = "", py::arg("tip") = "", py::arg("inertia_check") = "physical",
          doc("Chain.from_urdf"));
}

void bindTree(py::module_& mod) {
  const auto fromUrdf = [](O source, O root, const std::string& inertia_check, const std::string& base) {
    return modelFromUrdf<PyTree>(source, root.is_none() ? "" : root.cast<std::string>(), "", inertia_check, base);
  };
  const auto parent = [](const PyTree& t) { return py::array_t<std::int64_t>(py::cast(t.robot.parent)); };
  const auto chain = [](const PyTree& t, O tip) {
    PyChain c;
    c.robot = vereshchagin::pathChain(t.robot, t.resolveMoving(tip.ptr(), "tip").segment);
    c.inertia_check = t.inertia_check;
    return c;
  };
  bindModel<PyTree>(mod, "Tree")
      .def_static("from_urdf", fromUrdf, py::arg("source"), py::arg("root") = py::none(),
                  py::arg("inertia_check") = "physical", py::arg("base") = "fixed", doc("Tree.from_urdf"))
      .def_property_readonly(
          "base", [](const PyTree& t) { return vereshchagin::baseKindName(t.robot.base); }, doc("Tree.base"))
      .def_property_readonly(
          "base_name", [](const PyTree& t) { return t.robot.root_link; }, doc("Tree.base_name"))
      .def_property_readonly("parent", parent, doc("Tree.parent"))
      .def("chain", chain, py::arg("tip"), doc("Tree.chain"));
}

}  // namespace vsbind
