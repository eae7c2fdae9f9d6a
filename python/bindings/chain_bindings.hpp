// Python Chain and Joint: a KDL::Chain built segment by segment from numpy inputs.
#pragma once

#include <string>
#include <vector>

#include <kdl/chain.hpp>

#include "common.hpp"

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
    s << (type == KDL::Joint::RotAxis ? "Joint.revolute(" : "Joint.prismatic(") << "axis=[" << axis.x()
      << ", " << axis.y() << ", " << axis.z() << "], origin=[" << origin.x() << ", " << origin.y()
      << ", " << origin.z() << "])";
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

// The Python Chain: a KDL::Chain built segment by segment.
struct PyChain {
  KDL::Chain chain;

  void addSegment(const std::string& name, const py::object& joint, const py::object& tip, double mass,
                  const py::object& com, const py::object& inertia, double rotor_inertia,
                  const std::string& joint_name) {
    JointSpec spec;
    if (py::isinstance<py::str>(joint)) {
      spec = jointFromString(joint.cast<std::string>());
    } else if (py::isinstance<JointSpec>(joint)) {
      spec = joint.cast<JointSpec>();
    } else {
      raise("joint must be a joint-type string such as 'rot_z' or a vereshchagin.Joint");
    }
    const KDL::Frame f_tip = tip.is_none() ? KDL::Frame::Identity() : frameFrom4x4(tip, "tip");
    if (!std::isfinite(mass) || mass < 0.0) raise("mass must be finite and >= 0, got " + std::to_string(mass));
    const KDL::Vector c = com.is_none() ? KDL::Vector::Zero() : vec3(com, "com");
    Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
    if (!inertia.is_none()) {
      Array a = toArray(inertia, "inertia");
      if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
        raise("inertia must be a 3x3 matrix (about the centre of mass, tip-frame axes), got shape " + shapeStr(a));
      requireFinite(a, "inertia");
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) I(r, k) = a.at(r, k);
    }
    const double scale = std::max(1.0, I.cwiseAbs().maxCoeff());
    if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) raise("inertia must be symmetric");
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(I, Eigen::EigenvaluesOnly);
    if (es.eigenvalues().minCoeff() < -1e-12 * scale)
      raise("inertia must be positive semi-definite (smallest eigenvalue " +
            std::to_string(es.eigenvalues().minCoeff()) + ")");
    if (!std::isfinite(rotor_inertia) || rotor_inertia < 0.0)
      raise("rotor_inertia must be finite and >= 0, got " + std::to_string(rotor_inertia));
    if (spec.type == KDL::Joint::Fixed && rotor_inertia != 0.0) raise("a fixed joint has no rotor inertia");
    const std::string jname = joint_name.empty() ? name + "_joint" : joint_name;
    KDL::Joint j = spec.has_axis ? KDL::Joint(jname, spec.origin, spec.axis, spec.type, 1.0, 0.0, rotor_inertia)
                                 : KDL::Joint(jname, spec.type, 1.0, 0.0, rotor_inertia);
    const KDL::RotationalInertia Ic(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
    chain.addSegment(KDL::Segment(name, j, f_tip, KDL::RigidBodyInertia(mass, c, Ic)));
  }

  std::vector<std::string> segmentNames() const {
    std::vector<std::string> out;
    for (unsigned int i = 0; i < chain.getNrOfSegments(); ++i) out.push_back(chain.getSegment(i).getName());
    return out;
  }
  std::vector<std::string> jointNames() const {
    std::vector<std::string> out;
    for (unsigned int i = 0; i < chain.getNrOfSegments(); ++i) {
      const KDL::Joint& j = chain.getSegment(i).getJoint();
      if (j.getType() != KDL::Joint::Fixed) out.push_back(j.getName());
    }
    return out;
  }
};

void bindChain(py::module_& mod);

}  // namespace vsbind
