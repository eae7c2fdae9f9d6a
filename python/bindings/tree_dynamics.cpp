// Dynamics companions of the Python Tree, in the conventions of Chain's (dynamics_bindings.cpp)
// and of the hybrid solver: physical gravity in the base frame, external wrenches in base-frame
// axes with the moment about each segment's tip origin, applied ON the segment BY the
// environment, joints in q order. The algorithms are the C++ library's (dynamics.hpp).
#include <pybind11/stl.h>

#include "companions.hpp"
#include "dynamics_common.hpp"
#include "dynamics_docs.hpp"
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
          py::arg("f_ext") = py::none(), py::arg("gravity") = kEarthGravity,
          docs::inverseDynamicsDoc("recursive Newton-Euler over the tree", ",\n    in q order (:attr:`joint_names`)",
                                   "; rows in\n    segment order, :attr:`segment_names`", ", in q order")
              .c_str())
      .def("mass_matrix", &massMatrix, py::arg("q"),
           docs::massMatrixDoc("composite rigid bodies over the tree",
                               "\n    Rows and columns in q order; the entries of two joints on different branches "
                               "(neither on\n    the other's path to the base) are zero.")
               .c_str())
      .def("gravity_torques", &gravityTorques, py::arg("q"), py::arg("gravity") = kEarthGravity,
           docs::gravityTorquesDoc("tree", "").c_str())
      .def("coriolis_torques", &coriolisTorques, py::arg("q"), py::arg("qd"), docs::coriolisTorquesDoc("").c_str())
      .def("jacobian_dot_times_qd", &jacobianDotTimesQd, py::arg("q"), py::arg("qd"), py::arg("segment"),
           docs::jacobianDotDoc("jacobian_dot_times_qd(q, qd, segment)",
                                "Only the joints on the frame's path to the base contribute.",
                                "segment : str or int\n"
                                "    As in :meth:`fk`: a segment name or index (negative from the end), a merged "
                                "link's name, or\n    the base link's name (zeros). Required: a tree has no last "
                                "segment.\n")
               .c_str())
      .def("fk_all", &fkAll, py::arg("q"), docs::fkAllDoc(", in segment order").c_str())
      .def_property("rotor_inertia", &PyTree::rotorInertia, &PyTree::setRotorInertia,
                    "ndarray (n,): motor rotor inertia reflected to each joint, kg m^2 or kg, q order (settable; "
                    "added to the joint's articulated inertia; a Solver built afterwards uses it, one built before "
                    "keeps its own copy).");
}

}  // namespace vsbind
