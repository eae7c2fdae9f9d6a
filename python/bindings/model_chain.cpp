// The members only vereshchagin.Chain has (add_segment, segment_spec, from_urdf(root, tip)) and
// vereshchagin.Joint, the joint argument of add_segment; the checks are the C++ library's
// (robot_edit.hpp).
#include <pybind11/eigen.h>

#include <sstream>

#include "model_state.hpp"
#include "py_solver.hpp"  // inertiaCheckArg
#include "vereshchagin/robot_edit.hpp"

namespace vsbind {

namespace {

using vereshchagin::JointSpec;

std::string jointRepr(const JointSpec& j) {
  if (j.type == KDL::Joint::Fixed) return "Joint.fixed()";
  std::ostringstream s;
  s << (j.type == KDL::Joint::RotAxis ? "Joint.revolute(" : "Joint.prismatic(") << "axis=[" << j.axis.x() << ", "
    << j.axis.y() << ", " << j.axis.z() << "], origin=[" << j.origin.x() << ", " << j.origin.y() << ", " << j.origin.z()
    << "])";
  return s.str();
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
  if (!vereshchagin::jointFromName(joint.cast<std::string>(), j))
    raise("unknown joint type '" + joint.cast<std::string>() +
          "': use 'rot_x', 'rot_y', 'rot_z', 'trans_x', 'trans_y', 'trans_z', 'fixed', "
          "Joint.revolute(axis, origin) or Joint.prismatic(axis, origin)");
  return j;
}

Eigen::Matrix3d inertiaArg(O inertia, const std::string& name) {
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  if (inertia.is_none()) return I;
  const F64View a = asF64(inertia.ptr(), name.c_str());
  if (a.ndim != 2 || a.shape[0] != 3 || a.shape[1] != 3)
    raise(name + " must be a 3x3 matrix (about the centre of mass, tip-frame axes), got shape " + a.shapeString());
  requireFiniteView(a, name.c_str());
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) I(r, k) = a.data[3 * r + k];
  return I;
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
  spec.inertia = inertiaArg(inertia, where + "inertia");
  std::string message;
  if (!vereshchagin::addSegment(c.robot, spec, check, message)) raise(message);
  c.invalidateCompanions();
  if (check == vereshchagin::InertiaCheck::JointSpace) c.inertia_check = check;
}

py::dict segmentSpec(const PyChain& c, O which) {
  const int segment = c.resolveMoving(which.ptr(), "segment").segment;
  const vereshchagin::SegmentSpec s = vereshchagin::segmentSpec(vereshchagin::segmentAt(c.robot, segment));
  const auto vec = [](const double* v) { return py::array_t<double>(3, v); };
  return py::dict(
      py::arg("name") = s.name, py::arg("joint_type") = vereshchagin::jointTypeName(s.joint.type),
      py::arg("axis") = s.joint.type == KDL::Joint::Fixed ? py::object(py::none()) : py::object(vec(s.joint.axis.data)),
      py::arg("origin") = vec(s.joint.origin.data), py::arg("joint_name") = s.joint_name,
      py::arg("tip") = py::cast(vereshchagin::homogeneous(s.tip)), py::arg("mass") = s.mass,
      py::arg("com") = vec(s.com.data),
      py::arg("inertia") = py::cast(Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(s.inertia)),
      py::arg("rotor_inertia") = s.rotor_inertia);
}

void bindJoint(py::module_& mod) {
  py::class_<JointSpec> cls(mod, "Joint", doc("Joint"));
  for (const auto& [name, type] : {std::pair{"revolute", KDL::Joint::RotAxis}, {"prismatic", KDL::Joint::TransAxis}})
    cls.def_static(
        name, [type = type](O axis, O origin) { return axisJointArg(type, axis, origin); }, py::arg("axis"),
        py::arg("origin") = py::none(), doc(std::string("Joint.") + name));
  cls.def_static(
         "fixed", [] { return JointSpec(); }, doc("Joint.fixed"))
      .def("__repr__", &jointRepr);
}

}  // namespace

void bindChain(py::module_& mod) {
  bindJoint(mod);
  bindModel<PyChain>(mod, "Chain")
      .def(py::init<>())
      .def("add_segment", &addSegment, doc("Chain.add_segment"), py::arg("name"), py::arg("joint"),
           py::arg("tip") = py::none(), py::arg("mass") = 0.0, py::arg("com") = py::none(),
           py::arg("inertia") = py::none(), py::arg("rotor_inertia") = 0.0, py::arg("joint_name") = "",
           py::arg("inertia_check") = "physical")
      .def("segment_spec", &segmentSpec, py::arg("segment"), doc("Chain.segment_spec"))
      .def_static("from_urdf", &modelFromUrdf<PyChain>, py::arg("source"), py::arg("root") = "", py::arg("tip") = "",
                  py::arg("inertia_check") = "physical", doc("Chain.from_urdf"));
}

}  // namespace vsbind
