/// @file
/// Building a RobotChain segment by segment, with the checks of a rigid body, and reading a
/// segment back as the description that built it (the Python Chain.add_segment / segment_spec).
///
/// Frames: a joint's axis and origin are in the parent segment's tip frame (the base frame for
/// the first segment); a segment's tip frame is given in its joint frame at q = 0; its centre of
/// mass and rotational inertia are in tip-frame axes. Units: m, kg, kg m^2 (rotor inertia: kg m^2
/// for revolute joints, kg for prismatic ones).
#pragma once

#include <string>

#include <Eigen/Core>
#include <kdl/frames.hpp>
#include <kdl/joint.hpp>
#include <kdl/segment.hpp>

#include "vereshchagin/array_arg.hpp"
#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/robot_chain.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// A joint before it is attached to a segment (its name and rotor inertia come with the segment).
struct JointSpec {
  /// RotX, RotY, RotZ, TransX, TransY, TransZ (axis and origin unused), RotAxis, TransAxis or Fixed.
  KDL::Joint::JointType type = KDL::Joint::Fixed;
  KDL::Vector axis = KDL::Vector(0, 0, 1);   ///< unit axis, parent tip frame (RotAxis / TransAxis only)
  KDL::Vector origin = KDL::Vector::Zero();  ///< a point of the axis, parent tip frame, m (the same)
};

/// The joint named "rot_x", "rot_y", "rot_z", "trans_x", "trans_y", "trans_z" or "fixed"; false
/// (out unchanged) for any other name.
bool jointFromName(const std::string& name, JointSpec& out);

/// jointFromName with the message of a failure: Error::OutOfRange and "unknown joint type 'x':
/// use 'rot_x', ..., 'fixed', Joint.revolute(axis, origin) or Joint.prismatic(axis, origin)" in
/// `message` (the names of the Python API).
Status jointFromName(const std::string& name, JointSpec& out, std::string& message);

/// The Python expression that makes `joint`: "Joint.fixed()", or "Joint.revolute(axis=[0, 0, 1],
/// origin=[0.1, 0, 0])" / "Joint.prismatic(...)" for RotAxis / TransAxis (values as std::ostream
/// prints doubles). The named types (RotX, ...) print as "Joint.prismatic(...)" with their fields.
std::string jointExpression(const JointSpec& joint);

/// A revolute (RotAxis) or prismatic (TransAxis) joint about / along `axis` through `origin`
/// (parent tip frame, m). The axis is normalised; Error::OutOfRange ("axis must be a non-zero
/// 3-vector") for an axis of norm <= 1e-12 or not finite, or a non-finite origin ("origin must be
/// finite"), out unchanged then.
Status axisJoint(KDL::Joint::JointType type, const KDL::Vector& axis, const KDL::Vector& origin, JointSpec& out);

/// The name of a joint type as segmentSpec reports it: "rot_x" ... "trans_z", "revolute"
/// (RotAxis), "prismatic" (TransAxis) or "fixed".
const char* jointTypeName(KDL::Joint::JointType type);

/// One segment described by what builds it (see the top of this file for frames and units).
struct SegmentSpec {
  std::string name;        ///< the segment's name: non-empty, unique in the chain
  std::string joint_name;  ///< the joint's name, unique among the moving joints; empty: name + "_joint"
  JointSpec joint;         ///< the joint's type, axis and origin
  KDL::Frame tip = KDL::Frame::Identity();            ///< the tip frame in the joint frame at q = 0
  double mass = 0.0;                                  ///< kg, finite, >= 0
  KDL::Vector com = KDL::Vector::Zero();              ///< centre of mass in the tip frame, m
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the centre of mass, tip-frame axes, kg m^2
  double rotor_inertia = 0.0;                         ///< reflected to the joint, >= 0; 0 for a fixed joint
};

/// SegmentSpec::inertia from an array as a caller hands it over: 3x3, row-major, finite values.
/// On failure `out` is unchanged and `message` holds "<name> must be a 3x3 matrix (about the centre
/// of mass, tip-frame axes), got shape (3,)" (Error::SizeMismatch) or nonfiniteMessage's
/// (Error::NonfiniteInput).
Status inertiaFromArray(const ArrayArg& a, const std::string& name, Eigen::Matrix3d& out, std::string& message);

/// Appends `spec` to the end of `robot` (its chain, one link placement, and a JointInfo of type
/// "continuous" or "prismatic" for a moving joint). Checks first, and leaves `robot` unchanged on
/// failure (Error::InvalidModel, message in `message`, which Status::message() points into):
/// a non-empty unique segment name ("name: ..."), a unique joint name, then, prefixed by
/// "segment '<name>': ": mass finite and >= 0, finite com and inertia, the inertia symmetric (to
/// 1e-12 max(1, max |I_ij|)), and under InertiaCheck::Physical positive semi-definite (smallest
/// principal moment >= -1e-12 scale) with principal moments obeying the triangle inequality
/// I1 + I2 >= I3 - 1e-6 I3 (both messages name inertia_check='joint_space'); rotor_inertia finite
/// and >= 0, and 0 for a fixed joint.
Status addSegment(RobotChain& robot, const SegmentSpec& spec, InertiaCheck check, std::string& message);

/// Segment `segment` read back as a SegmentSpec: KDL's inertia about the tip origin moved to the
/// centre of mass by the parallel-axis theorem, I_com = I_tip - m (|c|^2 E - c c^T), made exactly
/// symmetric; origin zero unless the joint is RotAxis / TransAxis; rotor_inertia 0 for a fixed
/// joint. addSegment of the result rebuilds the segment (up to the round-off of I_com).
SegmentSpec segmentSpec(const KDL::Segment& segment);

}  // namespace vereshchagin
