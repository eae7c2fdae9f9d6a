// A RobotChain built segment by segment, and a segment read back (robot_edit.hpp).
#include "vereshchagin/robot_edit.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

namespace vereshchagin {

namespace {

bool finite(const KDL::Vector& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The inertia checks of addSegment: "" if the body passes, else why (after `where`).
std::string inertiaFault(const SegmentSpec& spec, InertiaCheck check) {
  const Eigen::Matrix3d& I = spec.inertia;
  if (!std::isfinite(spec.mass) || spec.mass < 0.0) return "mass must be finite and >= 0, got " + str(spec.mass);
  if (!finite(spec.com)) return "com must be finite";
  if (!I.allFinite()) return "inertia must be finite";
  const double scale = std::max(1.0, I.cwiseAbs().maxCoeff());
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) return "inertia must be symmetric";
  if (check != InertiaCheck::Physical) return "";
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(I, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d m = es.eigenvalues();  // ascending
  if (m(0) < -1e-12 * scale)
    return "inertia must be positive semi-definite (smallest eigenvalue " + std::to_string(m(0)) +
           "); identified models with such inertias: inertia_check='joint_space'";
  if (m(0) + m(1) < m(2) - 1e-6 * std::abs(m(2)))
    return "inertia's principal moments " + str(m(0)) + ", " + str(m(1)) + ", " + str(m(2)) +
           " violate the triangle inequality I1 + I2 >= I3 (no rigid body has them); "
           "identified models: inertia_check='joint_space'";
  return "";
}

// Every check of addSegment: "" if `spec` may be appended with joint name `jname`, else the message.
std::string segmentFault(const RobotChain& robot, const SegmentSpec& spec, const std::string& jname,
                         InertiaCheck check) {
  const std::string where = "segment '" + spec.name + "': ";
  if (spec.name.empty()) return "name: a segment needs a non-empty name";
  for (unsigned int i = 0; i < robot.chain.getNrOfSegments(); ++i)
    if (robot.chain.getSegment(i).getName() == spec.name)
      return "name: a segment named '" + spec.name + "' already exists (names must be unique)";
  for (const JointInfo& j : robot.joints)
    if (j.name == jname)
      return where + "joint_name: a joint named '" + jname + "' already exists (names must be unique)";
  if (const std::string fault = inertiaFault(spec, check); !fault.empty()) return where + fault;
  if (!std::isfinite(spec.rotor_inertia) || spec.rotor_inertia < 0.0)
    return where + "rotor_inertia must be finite and >= 0, got " + str(spec.rotor_inertia);
  if (spec.joint.type == KDL::Joint::Fixed && spec.rotor_inertia != 0.0)
    return where + "rotor_inertia: a fixed joint has none";
  return "";
}

bool isAxisType(KDL::Joint::JointType type) {
  return type == KDL::Joint::RotAxis || type == KDL::Joint::TransAxis;
}

}  // namespace

bool jointFromName(const std::string& name, JointSpec& out) {
  static const std::pair<const char*, KDL::Joint::JointType> table[] = {
      {"rot_x", KDL::Joint::RotX},     {"rot_y", KDL::Joint::RotY},     {"rot_z", KDL::Joint::RotZ},
      {"trans_x", KDL::Joint::TransX}, {"trans_y", KDL::Joint::TransY}, {"trans_z", KDL::Joint::TransZ},
      {"fixed", KDL::Joint::Fixed}};
  for (const auto& entry : table) {
    if (name == entry.first) {
      out = JointSpec();
      out.type = entry.second;
      return true;
    }
  }
  return false;
}

Status jointFromName(const std::string& name, JointSpec& out, std::string& message) {
  if (jointFromName(name, out)) return Status();
  message = "unknown joint type '" + name +
            "': use 'rot_x', 'rot_y', 'rot_z', 'trans_x', 'trans_y', 'trans_z', 'fixed', "
            "Joint.revolute(axis, origin) or Joint.prismatic(axis, origin)";
  return Status(Error::OutOfRange, message.c_str());
}

std::string jointExpression(const JointSpec& j) {
  if (j.type == KDL::Joint::Fixed) return "Joint.fixed()";
  std::ostringstream s;
  s << (j.type == KDL::Joint::RotAxis ? "Joint.revolute(" : "Joint.prismatic(") << "axis=[" << j.axis.x() << ", "
    << j.axis.y() << ", " << j.axis.z() << "], origin=[" << j.origin.x() << ", " << j.origin.y() << ", " << j.origin.z()
    << "])";
  return s.str();
}

Status axisJoint(KDL::Joint::JointType type, const KDL::Vector& axis, const KDL::Vector& origin, JointSpec& out) {
  const double norm = axis.Norm();
  if (!finite(axis) || !(norm > 1e-12)) return Status(Error::OutOfRange, "axis must be a non-zero 3-vector");
  if (!finite(origin)) return Status(Error::OutOfRange, "origin must be finite");
  out.type = type;
  out.axis = axis / norm;
  out.origin = origin;
  return Status();
}

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

Status inertiaFromArray(const ArrayArg& a, const std::string& name, Eigen::Matrix3d& out, std::string& message) {
  if (a.ndim != 2 || a.shape[0] != 3 || a.shape[1] != 3) {
    message = name + " must be a 3x3 matrix (about the centre of mass, tip-frame axes), got shape " + a.shapeString();
    return Status(Error::SizeMismatch, message.c_str());
  }
  if (message = nonfiniteMessage(a, name.c_str()); !message.empty())
    return Status(Error::NonfiniteInput, message.c_str());
  out = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(a.data);
  return Status();
}

Status addSegment(RobotChain& robot, const SegmentSpec& spec, InertiaCheck check, std::string& message) {
  const std::string jname = spec.joint_name.empty() ? spec.name + "_joint" : spec.joint_name;
  message = segmentFault(robot, spec, jname, check);
  if (!message.empty()) return Status(Error::InvalidModel, message.c_str());
  const JointSpec& js = spec.joint;
  const KDL::Joint joint = isAxisType(js.type)
                               ? KDL::Joint(jname, js.origin, js.axis, js.type, 1.0, 0.0, spec.rotor_inertia)
                               : KDL::Joint(jname, js.type, 1.0, 0.0, spec.rotor_inertia);
  const Eigen::Matrix3d& I = spec.inertia;
  const KDL::RotationalInertia I_com(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
  const unsigned int seg = robot.chain.getNrOfSegments();
  robot.chain.addSegment(KDL::Segment(spec.name, joint, spec.tip, KDL::RigidBodyInertia(spec.mass, spec.com, I_com)));
  robot.links.push_back({spec.name, static_cast<int>(seg), KDL::Frame::Identity()});
  if (js.type != KDL::Joint::Fixed) {
    JointInfo info;
    info.name = jname;
    const bool prismatic = js.type == KDL::Joint::TransX || js.type == KDL::Joint::TransY ||
                           js.type == KDL::Joint::TransZ || js.type == KDL::Joint::TransAxis;
    info.type = prismatic ? "prismatic" : "continuous";
    info.segment = seg;
    robot.joints.push_back(info);
  }
  message.clear();
  return Status();
}

SegmentSpec segmentSpec(const KDL::Segment& segment) {
  const KDL::Joint& j = segment.getJoint();
  const KDL::RigidBodyInertia& body = segment.getInertia();
  SegmentSpec spec;
  spec.name = segment.getName();
  spec.joint_name = j.getName();
  spec.joint.type = j.getType();
  spec.joint.axis = j.JointAxis();
  spec.joint.origin = isAxisType(j.getType()) ? j.JointOrigin() : KDL::Vector::Zero();
  spec.tip = segment.getFrameToTip();
  spec.mass = body.getMass();
  spec.com = body.getCOG();
  const KDL::RotationalInertia about_tip = body.getRotationalInertia();
  const Eigen::Map<const Eigen::Matrix3d> I_tip(about_tip.data);
  const Eigen::Vector3d c(spec.com.x(), spec.com.y(), spec.com.z());
  const Eigen::Matrix3d I_com = I_tip - spec.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  spec.inertia = 0.5 * (I_com + I_com.transpose());  // exactly symmetric
  spec.rotor_inertia = j.getType() == KDL::Joint::Fixed ? 0.0 : j.getInertia();
  return spec;
}

}  // namespace vereshchagin
