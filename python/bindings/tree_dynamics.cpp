// Dynamics companions of the Python Tree, in the conventions of Chain's (dynamics_bindings.cpp)
// and of the hybrid solver: physical gravity in the base frame, external wrenches in base-frame
// axes with the moment about each segment's tip origin, applied ON the segment BY the
// environment, joints in q order. The sweeps are tree_sweeps.hpp's.
#include <pybind11/stl.h>

#include <vector>

#include "dynamics_common.hpp"
#include "dynamics_docs.hpp"
#include "tree_bindings.hpp"
#include "tree_sweeps.hpp"

namespace vsbind {

namespace {

unsigned int jointCount(const PyTree& t) {
  return t.robot.tree.getNrOfJoints();
}

// Our f_ext (n_segments, 6) -> per segment the same wrench about the base origin (the sweeps'
// reference point): moment_O = moment_tip + p_tip x force.
std::vector<KDL::Wrench> externalWrenches(const py::object& f_ext, const PyTree& t, const TreePlacement& at) {
  const int ns = t.segmentCount();
  std::vector<KDL::Wrench> out(static_cast<std::size_t>(ns), KDL::Wrench::Zero());
  const auto rows = externalWrenchRows(f_ext, t, [&at](int s) { return at.tip[static_cast<std::size_t>(s)].M; });
  if (rows.empty()) return out;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const KDL::Vector force(rows[i](0), rows[i](1), rows[i](2));
    const KDL::Vector moment(rows[i](3), rows[i](4), rows[i](5));
    out[i] = KDL::Wrench(force, moment + at.tip[i].p * force);
  }
  return out;
}

py::array_t<double> inverseDynamics(const PyTree& t, const py::object& q_obj, const py::object& qd_obj,
                                    const py::object& qdd_obj, const py::object& f_ext, const py::object& gravity) {
  const unsigned int n = jointCount(t);
  const KDL::JntArray q = jntArrayArg(q_obj, "q", n);
  const KDL::JntArray qd = jntArrayArg(qd_obj, "qd", n);
  const KDL::JntArray qdd = jntArrayArg(qdd_obj, "qdd", n);
  const KDL::Vector g = vec3(gravity, "gravity");
  const TreePlacement at = placeTree(t, q);
  const std::vector<KDL::Wrench> wrenches = externalWrenches(f_ext, t, at);
  return jointTorques(treeInverseDynamics(t, at, qd, qdd, wrenches, g), "inverse_dynamics");
}

py::array_t<double> massMatrix(const PyTree& t, const py::object& q_obj) {
  const TreePlacement at = placeTree(t, jntArrayArg(q_obj, "q", jointCount(t)));
  return jointMatrix(treeMassMatrix(t, at), "mass_matrix");
}

py::array_t<double> gravityTorques(const PyTree& t, const py::object& q_obj, const py::object& gravity) {
  const unsigned int n = jointCount(t);
  const TreePlacement at = placeTree(t, jntArrayArg(q_obj, "q", n));
  const KDL::Vector g = vec3(gravity, "gravity");
  const KDL::JntArray zero(n);
  const std::vector<KDL::Wrench> none(static_cast<std::size_t>(t.segmentCount()), KDL::Wrench::Zero());
  return jointTorques(treeInverseDynamics(t, at, zero, zero, none, g), "gravity_torques");
}

py::array_t<double> coriolisTorques(const PyTree& t, const py::object& q_obj, const py::object& qd_obj) {
  const unsigned int n = jointCount(t);
  const KDL::JntArray q = jntArrayArg(q_obj, "q", n);
  const KDL::JntArray qd = jntArrayArg(qd_obj, "qd", n);
  const TreePlacement at = placeTree(t, q);
  const std::vector<KDL::Wrench> none(static_cast<std::size_t>(t.segmentCount()), KDL::Wrench::Zero());
  return jointTorques(treeInverseDynamics(t, at, qd, KDL::JntArray(n), none, KDL::Vector::Zero()), "coriolis_torques");
}

// The classical acceleration of a frame's origin at qdd = 0 without gravity: for the body point
// at p, d/dt(v_O + w x p) = a_O + dw x p + w x v_p (a_O: the base-origin spatial acceleration).
py::array_t<double> jacobianDotTimesQd(const PyTree& t, const py::object& q_obj, const py::object& qd_obj,
                                       const py::object& segment) {
  const unsigned int n = jointCount(t);
  const KDL::JntArray q = jntArrayArg(q_obj, "q", n);
  const KDL::JntArray qd = jntArrayArg(qd_obj, "qd", n);
  const PyTree::Target target = t.resolveTarget(segment.ptr(), "segment");
  py::array_t<double> out(6);
  std::fill(out.mutable_data(), out.mutable_data() + 6, 0.0);
  if (target.segment < 0) return out;  // a base link does not move
  const TreePlacement at = placeTree(t, q);
  std::vector<KDL::Twist> v, a;
  treeMotion(t, at, qd, KDL::JntArray(n), KDL::Twist::Zero(), v, a);
  const auto k = static_cast<std::size_t>(target.segment);
  const KDL::Vector p = at.tip[k] * target.link_in_tip.p;
  const KDL::Vector w = v[k].rot;
  const KDL::Vector v_p = v[k].vel + w * p;
  const KDL::Vector lin = a[k].vel + a[k].rot * p + w * v_p;
  const double values[6] = {lin.x(), lin.y(), lin.z(), a[k].rot.x(), a[k].rot.y(), a[k].rot.z()};
  requireFiniteResult(values, 6, "jacobian_dot_times_qd");
  std::copy(values, values + 6, out.mutable_data());
  return out;
}

py::array_t<double> fkAll(const PyTree& t, const py::object& q_obj) {
  const TreePlacement at = placeTree(t, jntArrayArg(q_obj, "q", jointCount(t)));
  return homogeneousStack(at.tip);
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
