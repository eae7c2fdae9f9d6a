#include "chain_bindings.hpp"

#include <pybind11/stl.h>

namespace vsbind {

void bindChain(py::module_& mod) {
  py::class_<JointSpec>(mod, "Joint")
      .def_static("revolute", [](const py::object& axis, const py::object& origin) {
        return makeAxisJoint(KDL::Joint::RotAxis, axis, origin); }, py::arg("axis"), py::arg("origin") = py::none())
      .def_static("prismatic", [](const py::object& axis, const py::object& origin) {
        return makeAxisJoint(KDL::Joint::TransAxis, axis, origin); }, py::arg("axis"), py::arg("origin") = py::none())
      .def_static("fixed", []() { return JointSpec(); })
      .def("__repr__", &JointSpec::repr);

  py::class_<PyChain>(mod, "Chain")
      .def(py::init<>())
      .def("add_segment", &PyChain::addSegment, R"doc(Append a segment (a joint followed by a rigid body).

Parameters
----------
name : str
    Segment (link) name.
joint : str or Joint
    'rot_x', 'rot_y', 'rot_z', 'trans_x', 'trans_y', 'trans_z' (about / along the axes of the
    segment's root frame, i.e. the previous segment's tip frame), 'fixed', or
    Joint.revolute(axis, origin) (rotation about the line through ``origin`` along ``axis``) /
    Joint.prismatic(axis) (translation along ``axis``), in the root frame.
tip : array_like, shape (4, 4), optional
    Pose of the segment's tip frame in its root frame when the joint is at 0 (KDL convention).
mass : float
    kg, >= 0.
com : array_like, shape (3,), optional
    Centre of mass in the tip frame, m.
inertia : array_like, shape (3, 3), optional
    Rotational inertia about the centre of mass, tip-frame axes, kg m^2 (symmetric PSD).
rotor_inertia : float
    Motor rotor inertia reflected to the joint (kg m^2 or kg), added to the joint's inertia.
joint_name : str, optional
    Defaults to ``name + '_joint'``.
)doc", py::arg("name"), py::arg("joint"), py::arg("tip") = py::none(),
           py::arg("mass") = 0.0, py::arg("com") = py::none(), py::arg("inertia") = py::none(),
           py::arg("rotor_inertia") = 0.0, py::arg("joint_name") = "")
      .def_property_readonly("n_joints", [](const PyChain& c) { return c.chain.getNrOfJoints(); })
      .def_property_readonly("n_segments", [](const PyChain& c) { return c.chain.getNrOfSegments(); })
      .def_property_readonly("segment_names", &PyChain::segmentNames)
      .def_property_readonly("joint_names", &PyChain::jointNames)
      .def("__repr__", [](const PyChain& c) {
        return "<vereshchagin.Chain with " + std::to_string(c.chain.getNrOfSegments()) + " segments, " +
               std::to_string(c.chain.getNrOfJoints()) + " joints>";
      });

}

}  // namespace vsbind
