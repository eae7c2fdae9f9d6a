// Python Chain and Joint: a KDL::Chain built segment by segment from numpy inputs.
#pragma once

#include <string>
#include <vector>

#include <kdl/chain.hpp>

#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/robot_chain.hpp"

#include "addressing.hpp"
#include "common.hpp"
#include "companions.hpp"

namespace vsbind {

// A joint description before it is attached to a segment (name and rotor inertia come later).
struct JointSpec {
  KDL::Joint::JointType type = KDL::Joint::Fixed;
  KDL::Vector origin = KDL::Vector::Zero();
  KDL::Vector axis = KDL::Vector(0, 0, 1);
  bool has_axis = false;
  std::string repr() const {
    std::ostringstream s;
    if (type == KDL::Joint::Fixed) return "Joint.fixed()";
    s << (type == KDL::Joint::RotAxis ? "Joint.revolute(" : "Joint.prismatic(") << "axis=[" << axis.x() << ", "
      << axis.y() << ", " << axis.z() << "], origin=[" << origin.x() << ", " << origin.y() << ", " << origin.z()
      << "])";
    return s.str();
  }
};

inline JointSpec makeAxisJoint(KDL::Joint::JointType type, const py::handle& axis, const py::handle& origin) {
  JointSpec j;
  j.type = type;
  j.axis = vec3(axis, "axis");
  const double norm = j.axis.Norm();
  if (!(norm > 1e-12)) raise("axis must be a non-zero 3-vector");
  j.axis = j.axis / norm;
  j.origin = origin.is_none() ? KDL::Vector::Zero() : vec3(origin, "origin");
  j.has_axis = true;
  return j;
}

inline JointSpec jointFromString(const std::string& s) {
  static const std::pair<const char*, KDL::Joint::JointType> table[] = {
      {"rot_x", KDL::Joint::RotX},     {"rot_y", KDL::Joint::RotY},     {"rot_z", KDL::Joint::RotZ},
      {"trans_x", KDL::Joint::TransX}, {"trans_y", KDL::Joint::TransY}, {"trans_z", KDL::Joint::TransZ},
      {"fixed", KDL::Joint::Fixed}};
  for (const auto& e : table) {
    if (s == e.first) {
      JointSpec j;
      j.type = e.second;
      return j;
    }
  }
  raise("unknown joint type '" + s +
        "': use 'rot_x', 'rot_y', 'rot_z', 'trans_x', 'trans_y', 'trans_z', 'fixed', "
        "Joint.revolute(axis, origin) or Joint.prismatic(axis, origin)");
}

using vereshchagin::withRotorInertia;

// The value of a `rotor_inertia` setter: shape (n_joints,), finite, every entry >= 0.
inline Array rotorInertiaArg(const py::object& values, size_t n_joints) {
  Array a = vectorArg(values, "rotor_inertia", static_cast<py::ssize_t>(n_joints));
  for (py::ssize_t k = 0; k < a.size(); ++k)
    if (a.at(k) < 0.0)
      raise("rotor_inertia must be >= 0, got " + std::to_string(a.at(k)) + " at joint " + std::to_string(k));
  return a;
}

// The Python Chain: a RobotChain (KDL::Chain plus joint and link metadata), built segment by
// segment or from a URDF. Frames and joints are addressed by the rule of addressing.hpp.
struct PyChain : CompanionModel {
  vereshchagin::RobotChain robot;
  // The inertia check the model was built with: JointSpace once any part of it was accepted only
  // by that check (from_kdl, from_urdf or add_segment with inertia_check='joint_space'). A Solver
  // uses it unless told otherwise.
  vereshchagin::InertiaCheck inertia_check = vereshchagin::InertiaCheck::Physical;

  int segmentCount() const override { return static_cast<int>(robot.chain.getNrOfSegments()); }
  const std::string& segmentName(int index) const override {
    return robot.chain.getSegment(static_cast<unsigned int>(index)).getName();
  }
  const std::vector<vereshchagin::LinkPlacement>& linkPlacements() const override { return robot.links; }
  const std::vector<vereshchagin::JointInfo>& jointInfos() const override { return robot.joints; }
  const std::string& rootLink() const override { return robot.root_link; }

  static PyChain fromUrdf(const py::object& source, const std::string& root, const std::string& tip,
                          vereshchagin::InertiaCheck inertia_check);
  // Pickle state: every segment (joint, tip frame, inertia bit for bit), joint and link metadata.
  py::tuple getState() const;
  static PyChain fromState(const py::tuple& state);
  void addSegment(const std::string& name, const py::object& joint, const py::object& tip, const py::object& mass,
                  const py::object& com, const py::object& inertia, const py::object& rotor_inertia,
                  const std::string& joint_name, const std::string& inertia_check);
  py::array_t<double> rotorInertia() const;
  void setRotorInertia(const py::object& values);
  py::array fk(const py::object& q, const py::object& segment) const;
  py::array jacobian(const py::object& q, const py::object& segment) const;
  py::array twist(const py::object& q, const py::object& qd, const py::object& segment) const;

 protected:
  vereshchagin::Model buildModel() const override;
};

void bindChain(py::module_& mod);

}  // namespace vsbind
