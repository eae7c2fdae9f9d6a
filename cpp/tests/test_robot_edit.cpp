// RobotChain built with addSegment (robot_edit.hpp): each check's message, the robot left
// unchanged on failure, and segmentSpec reading a segment back (inertia about the centre of mass
// by the parallel-axis theorem, against the inertia given), plus the joint helpers and their
// messages.
#include <cmath>
#include <string>

#include <doctest/doctest.h>

#include "vereshchagin/robot_edit.hpp"

namespace {

using vereshchagin::InertiaCheck;
using vereshchagin::SegmentSpec;

SegmentSpec rod(const std::string& name) {
  SegmentSpec s;
  s.name = name;
  vereshchagin::jointFromName("rot_z", s.joint);
  s.tip = KDL::Frame(KDL::Rotation::RPY(0.1, 0.2, 0.3), KDL::Vector(0.0, 0.0, 0.4));
  s.mass = 2.0;
  s.com = KDL::Vector(0.01, -0.02, 0.2);
  s.inertia << 0.05, 0.001, 0.002, 0.001, 0.04, 0.003, 0.002, 0.003, 0.03;
  s.rotor_inertia = 0.1;
  return s;
}

// addSegment's message for `spec` on a chain holding one segment "a" (joint "a_joint").
std::string refusal(SegmentSpec spec, InertiaCheck check = InertiaCheck::Physical) {
  vereshchagin::RobotChain robot;
  std::string message;
  REQUIRE(vereshchagin::addSegment(robot, rod("a"), InertiaCheck::Physical, message));
  const vereshchagin::Status s = vereshchagin::addSegment(robot, spec, check, message);
  CHECK(s.code() == (s ? vereshchagin::Error::None : vereshchagin::Error::InvalidModel));
  CHECK(robot.chain.getNrOfSegments() == (s ? 2u : 1u));
  CHECK(robot.links.size() == (s ? 2u : 1u));
  return s ? std::string() : std::string(s.message());
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("addSegment appends the segment, its link and its joint") {
  vereshchagin::RobotChain robot;
  std::string message;
  SegmentSpec fixed = rod("plate");
  fixed.joint = vereshchagin::JointSpec();
  fixed.rotor_inertia = 0.0;
  REQUIRE(vereshchagin::addSegment(robot, rod("a"), InertiaCheck::Physical, message));
  REQUIRE(vereshchagin::addSegment(robot, fixed, InertiaCheck::Physical, message));
  REQUIRE(robot.chain.getNrOfSegments() == 2);
  REQUIRE(robot.joints.size() == 1);  // the fixed joint is no JointInfo
  CHECK(robot.joints[0].name == "a_joint");
  CHECK(robot.joints[0].type == "continuous");
  CHECK(robot.links[1].link == "plate");
  CHECK(robot.links[1].segment == 1);
  CHECK(robot.chain.getSegment(0).getJoint().getInertia() == 0.1);
}

TEST_CASE("addSegment refuses with messages naming the argument") {
  SegmentSpec s = rod("b");
  CHECK(refusal(s).empty());
  CHECK(has(refusal(rod("")), "name: a segment needs a non-empty name"));
  CHECK(has(refusal(rod("a")), "a segment named 'a' already exists"));
  s.joint_name = "a_joint";
  CHECK(has(refusal(s), "segment 'b': joint_name: a joint named 'a_joint' already exists"));
  s = rod("b");
  s.mass = -1.0;
  CHECK(has(refusal(s), "segment 'b': mass must be finite and >= 0, got -1"));
  s = rod("b");
  s.inertia(0, 1) = 0.5;
  CHECK(has(refusal(s), "segment 'b': inertia must be symmetric"));
  s = rod("b");
  s.inertia = Eigen::Vector3d(1.0, -1.0, 1.0).asDiagonal();
  CHECK(has(refusal(s),
            "positive semi-definite (smallest eigenvalue -1.000000); identified models with such "
            "inertias: inertia_check='joint_space'"));
  CHECK(refusal(s, InertiaCheck::JointSpace).empty());
  s = rod("b");
  s.inertia = Eigen::Vector3d(0.1, 0.01, 0.01).asDiagonal();
  CHECK(has(refusal(s), "principal moments 0.01, 0.01, 0.1 violate the triangle inequality"));
  CHECK(has(refusal(s), "inertia_check='joint_space'"));
  s = rod("b");
  s.rotor_inertia = -0.5;
  CHECK(has(refusal(s), "segment 'b': rotor_inertia must be finite and >= 0, got -0.5"));
  s.joint = vereshchagin::JointSpec();
  s.rotor_inertia = 0.1;
  CHECK(has(refusal(s), "segment 'b': rotor_inertia: a fixed joint has none"));
}

TEST_CASE("segmentSpec gives back what addSegment took") {
  vereshchagin::RobotChain robot;
  std::string message;
  SegmentSpec s = rod("a");
  REQUIRE(vereshchagin::axisJoint(KDL::Joint::TransAxis, KDL::Vector(0, 3, 4), KDL::Vector(0.1, 0, 0), s.joint));
  REQUIRE(vereshchagin::addSegment(robot, s, InertiaCheck::Physical, message));
  CHECK(robot.joints[0].type == "prismatic");
  const SegmentSpec back = vereshchagin::segmentSpec(robot.chain.getSegment(0));
  CHECK(back.name == "a");
  CHECK(back.joint_name == "a_joint");
  CHECK(std::string(vereshchagin::jointTypeName(back.joint.type)) == "prismatic");
  CHECK((back.joint.axis - KDL::Vector(0, 0.6, 0.8)).Norm() < 1e-15);
  CHECK((back.joint.origin - KDL::Vector(0.1, 0, 0)).Norm() < 1e-15);
  CHECK(KDL::Equal(back.tip, s.tip, 1e-15));
  CHECK(back.mass == 2.0);
  CHECK((back.com - s.com).Norm() < 1e-15);
  CHECK((back.inertia - s.inertia).cwiseAbs().maxCoeff() < 1e-15);
  CHECK(back.inertia == back.inertia.transpose());
  CHECK(back.rotor_inertia == 0.1);
}

TEST_CASE("joint names and axis joints") {
  vereshchagin::JointSpec j;
  CHECK(vereshchagin::jointFromName("trans_y", j));
  CHECK(j.type == KDL::Joint::TransY);
  CHECK_FALSE(vereshchagin::jointFromName("hinge", j));
  CHECK(j.type == KDL::Joint::TransY);
  const vereshchagin::Status zero = vereshchagin::axisJoint(KDL::Joint::RotAxis, KDL::Vector::Zero(), {}, j);
  CHECK(zero.code() == vereshchagin::Error::OutOfRange);
  CHECK(std::string(zero.message()) == "axis must be a non-zero 3-vector");
  CHECK(std::string(vereshchagin::jointTypeName(KDL::Joint::Fixed)) == "fixed");
  CHECK(std::string(vereshchagin::jointTypeName(KDL::Joint::RotX)) == "rot_x");
}

TEST_CASE("joint names with messages and joints as Python expressions") {
  vereshchagin::JointSpec j;
  std::string message;
  CHECK(vereshchagin::jointFromName("rot_x", j, message));
  CHECK(message.empty());
  const vereshchagin::Status s = vereshchagin::jointFromName("hinge", j, message);
  CHECK(s.code() == vereshchagin::Error::OutOfRange);
  CHECK(message.rfind("unknown joint type 'hinge': use 'rot_x', ", 0) == 0);
  CHECK(message.find("Joint.prismatic(axis, origin)") != std::string::npos);
  CHECK(vereshchagin::jointExpression(vereshchagin::JointSpec()) == "Joint.fixed()");
  REQUIRE(vereshchagin::axisJoint(KDL::Joint::RotAxis, {0, 0, 2}, {0.5, 0, 0}, j));
  CHECK(vereshchagin::jointExpression(j) == "Joint.revolute(axis=[0, 0, 1], origin=[0.5, 0, 0])");
  REQUIRE(vereshchagin::axisJoint(KDL::Joint::TransAxis, {1, 0, 0}, {}, j));
  CHECK(vereshchagin::jointExpression(j) == "Joint.prismatic(axis=[1, 0, 0], origin=[0, 0, 0])");
}

TEST_CASE("inertiaFromArray reads a 3x3 row-major array, or names its shape or first non-finite value") {
  const double values[9] = {0.05, 0.001, 0.002, 0.001, 0.04, 0.003, 0.002, 0.003, 0.03};
  vereshchagin::ArrayArg a;
  a.data = values;
  a.ndim = 2;
  a.shape[0] = a.shape[1] = 3;
  Eigen::Matrix3d out = Eigen::Matrix3d::Zero();
  std::string message;
  REQUIRE(vereshchagin::inertiaFromArray(a, "inertia", out, message));
  CHECK(out(0, 1) == 0.001);
  CHECK(out(1, 2) == 0.003);
  a.ndim = 1;
  a.shape[0] = 9;
  CHECK(vereshchagin::inertiaFromArray(a, "segment 'x': inertia", out, message).code() ==
        vereshchagin::Error::SizeMismatch);
  CHECK(message ==
        "segment 'x': inertia must be a 3x3 matrix (about the centre of mass, tip-frame axes), got shape (9,)");
  const double bad[9] = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, std::nan("")};
  a.data = bad;
  a.ndim = 2;
  a.shape[0] = 3;
  CHECK(vereshchagin::inertiaFromArray(a, "inertia", out, message).code() == vereshchagin::Error::NonfiniteInput);
  CHECK(message.find("inertia contains NaN or Inf") == 0);
  CHECK(out(0, 1) == 0.001);  // unchanged
}
