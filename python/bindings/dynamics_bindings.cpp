// Dynamics companions of the Python Chain, in the conventions of the hybrid solver: physical
// gravity in the base frame, external wrenches in base-frame axes with the moment about each
// segment's tip origin, applied ON the segment BY the environment. The algorithms are the C++
// library's (dynamics.hpp, kinematics.hpp) through companions.hpp.
#include <pybind11/stl.h>

#include "chain_bindings.hpp"
#include "companions.hpp"
#include "dynamics_common.hpp"

namespace vsbind {

namespace {

py::array inverseDynamics(const PyChain& c, const py::object& q, const py::object& qd, const py::object& qdd,
                          const py::object& f_ext, const py::object& gravity) {
  return inverseDynamicsOf(c, q, qd, qdd, f_ext, gravity);
}

py::array massMatrix(const PyChain& c, const py::object& q) {
  return massMatrixOf(c, q);
}

py::array gravityTorques(const PyChain& c, const py::object& q, const py::object& gravity) {
  return gravityTorquesOf(c, q, gravity);
}

py::array coriolisTorques(const PyChain& c, const py::object& q, const py::object& qd) {
  return coriolisTorquesOf(c, q, qd);
}

// d/dt(J) qd of the (6, n) base-axes Jacobian of a segment tip or merged link origin: [classical
// linear acceleration of that point; angular acceleration] at qdd = 0, gravity not included.
py::array jacobianDotTimesQd(const PyChain& c, const py::object& q, const py::object& qd, const py::object& segment) {
  return jacobianDotTimesQdOf(c, q, qd, c.resolveOptional(segment, "segment"));
}

py::array fkAll(const PyChain& c, const py::object& q) {
  return fkAllOf(c, q);
}

}  // namespace

void bindDynamics(py::module_& mod) {
  bindTaskHelpers(mod);
  mod.def(
      "_task_beta",
      [](const PyChain& c, const py::object& q, const py::object& qd, const py::object& alpha,
         const py::object& a_desired, const py::object& gravity) {
        return taskBeta(c, c.resolveOptional(py::none(), "segment"), q, qd, alpha, a_desired, gravity);
      },
      py::arg("chain"), py::arg("q"), py::arg("qd"), py::arg("alpha"), py::arg("a_desired"), py::arg("gravity"),
      doc("_core._task_beta"));
  auto chain = py::reinterpret_borrow<py::class_<PyChain>>(mod.attr("Chain"));
  chain.def("inverse_dynamics", &inverseDynamics, py::arg("q"), py::arg("qd"), py::arg("qdd"),
            py::arg("f_ext") = py::none(), py::arg("gravity") = kEarthGravity, doc("Chain.inverse_dynamics"));
  chain.def("mass_matrix", &massMatrix, py::arg("q"), doc("Chain.mass_matrix"));
  chain.def("gravity_torques", &gravityTorques, py::arg("q"), py::arg("gravity") = kEarthGravity,
            doc("Chain.gravity_torques"));
  chain.def("coriolis_torques", &coriolisTorques, py::arg("q"), py::arg("qd"), doc("Chain.coriolis_torques"));
  chain.def("jacobian_dot_times_qd", &jacobianDotTimesQd, py::arg("q"), py::arg("qd"), py::arg("segment") = py::none(),
            doc("Chain.jacobian_dot_times_qd"));
  chain.def("fk_all", &fkAll, py::arg("q"), doc("Chain.fk_all"));
}

}  // namespace vsbind
