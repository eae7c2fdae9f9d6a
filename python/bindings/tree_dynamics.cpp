// Dynamics companions of the Python Tree, in the conventions of Chain's (dynamics_bindings.cpp)
// and of the hybrid solver: physical gravity in the base frame, external wrenches in base-frame
// axes with the moment about each segment's tip origin, applied ON the segment BY the
// environment, joints in q order. The algorithms are the C++ library's (dynamics.hpp).
#include <pybind11/stl.h>

#include "companions.hpp"
#include "dynamics_common.hpp"
#include "tree_bindings.hpp"

namespace vsbind {

namespace {

py::array inverseDynamics(const PyTree& t, const py::object& q, const py::object& qd, const py::object& qdd,
                          const py::object& f_ext, const py::object& gravity) {
  return inverseDynamicsOf(t, q, qd, qdd, f_ext, gravity);
}

py::array massMatrix(const PyTree& t, const py::object& q) {
  return massMatrixOf(t, q);
}

py::array gravityTorques(const PyTree& t, const py::object& q, const py::object& gravity) {
  return gravityTorquesOf(t, q, gravity);
}

py::array coriolisTorques(const PyTree& t, const py::object& q, const py::object& qd) {
  return coriolisTorquesOf(t, q, qd);
}

// The classical acceleration of a frame's origin at qdd = 0 without gravity (zeros for the base).
py::array jacobianDotTimesQd(const PyTree& t, const py::object& q, const py::object& qd, const py::object& segment) {
  return jacobianDotTimesQdOf(t, q, qd, t.resolveTarget(segment.ptr(), "segment"));
}

py::array fkAll(const PyTree& t, const py::object& q) {
  return fkAllOf(t, q);
}

}  // namespace

void bindTreeDynamics(py::class_<PyTree>& cls) {
  cls.def("inverse_dynamics", &inverseDynamics, py::arg("q"), py::arg("qd"), py::arg("qdd"),
          py::arg("f_ext") = py::none(), py::arg("gravity") = kEarthGravity, doc("Tree.inverse_dynamics"))
      .def("mass_matrix", &massMatrix, py::arg("q"), doc("Tree.mass_matrix"))
      .def("gravity_torques", &gravityTorques, py::arg("q"), py::arg("gravity") = kEarthGravity,
           doc("Tree.gravity_torques"))
      .def("coriolis_torques", &coriolisTorques, py::arg("q"), py::arg("qd"), doc("Tree.coriolis_torques"))
      .def("jacobian_dot_times_qd", &jacobianDotTimesQd, py::arg("q"), py::arg("qd"), py::arg("segment"),
           doc("Tree.jacobian_dot_times_qd"))
      .def("fk_all", &fkAll, py::arg("q"), doc("Tree.fk_all"))
      .def_property("rotor_inertia", &PyTree::rotorInertia, &PyTree::setRotorInertia, doc("Tree.rotor_inertia"));
}

}  // namespace vsbind
