// Chain.segment_spec: one segment of the Python Chain described by the arguments of add_segment,
// so that a chain can be read back, copied or converted to another library (PyKDL: kdl_interop.py).
#include <pybind11/stl.h>

#include <Eigen/Dense>

#include "chain_bindings.hpp"

namespace vsbind {

namespace {

const char* jointTypeName(KDL::Joint::JointType type) {
  switch (type) {
    case KDL::Joint::RotX:
      return "rot_x";
    case KDL::Joint::RotY:
      return "rot_y";
    case KDL::Joint::RotZ:
      return "rot_z";
    case KDL::Joint::TransX:
      return "trans_x";
    case KDL::Joint::TransY:
      return "trans_y";
    case KDL::Joint::TransZ:
      return "trans_z";
    case KDL::Joint::RotAxis:
      return "revolute";
    case KDL::Joint::TransAxis:
      return "prismatic";
    default:
      return "fixed";
  }
}

py::array_t<double> vector3(const KDL::Vector& v) {
  return copyVector(v.data, 3);
}

// KDL keeps the rotational inertia about the tip origin; add_segment takes it about the centre of
// mass: I_com = I_tip - m (|c|^2 E - c c^T) (parallel-axis theorem).
py::array_t<double> inertiaAboutCom(const KDL::RigidBodyInertia& body) {
  const KDL::RotationalInertia about_tip = body.getRotationalInertia();
  const Eigen::Map<const Eigen::Matrix3d> I_tip(about_tip.data);
  const KDL::Vector c = body.getCOG();
  const Eigen::Vector3d cv(c.x(), c.y(), c.z());
  const Eigen::Matrix3d I_com =
      I_tip - body.getMass() * (cv.squaredNorm() * Eigen::Matrix3d::Identity() - cv * cv.transpose());
  py::array_t<double> out({3, 3});
  auto o = out.mutable_unchecked<2>();
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) o(r, k) = 0.5 * (I_com(r, k) + I_com(k, r));  // exactly symmetric
  return out;
}

py::dict segmentSpec(const PyChain& c, const py::object& which) {
  const int seg = c.resolveMoving(which.ptr(), "segment").segment;
  const KDL::Segment& s = c.robot.chain.getSegment(static_cast<unsigned int>(seg));
  const KDL::Joint& j = s.getJoint();
  const bool fixed = j.getType() == KDL::Joint::Fixed;
  const bool with_axis = j.getType() == KDL::Joint::RotAxis || j.getType() == KDL::Joint::TransAxis;
  py::dict d;
  d["name"] = s.getName();
  d["joint_type"] = jointTypeName(j.getType());
  d["axis"] = fixed ? py::object(py::none()) : py::object(vector3(j.JointAxis()));
  d["origin"] = with_axis ? vector3(j.JointOrigin()) : vector3(KDL::Vector::Zero());
  d["joint_name"] = j.getName();
  d["tip"] = homogeneous(s.getFrameToTip());
  d["mass"] = s.getInertia().getMass();
  d["com"] = vector3(s.getInertia().getCOG());
  d["inertia"] = inertiaAboutCom(s.getInertia());
  d["rotor_inertia"] = fixed ? 0.0 : j.getInertia();
  return d;
}

}  // namespace

void bindSegmentSpec(py::module_& mod) {
  auto chain = py::reinterpret_borrow<py::class_<PyChain>>(mod.attr("Chain"));
  chain.def("segment_spec", &segmentSpec, py::arg("segment"), doc("Chain.segment_spec"));
}

}  // namespace vsbind
