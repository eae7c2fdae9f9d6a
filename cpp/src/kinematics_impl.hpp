// The workspace behind KinematicsData (kinematics.hpp), shared with the dynamics sweeps
// (dynamics.cpp): per-segment constants read once from the Model, and per-call poses, joint axes
// and spatial velocities. Everything of a call lives in one fixed frame, the base frame, with
// spatial vectors about the base origin: nothing is transformed between links in the sweeps.
#pragma once

#include <array>
#include <cstdarg>
#include <vector>

#include "vereshchagin/kinematics.hpp"

namespace vereshchagin {
namespace detail {

enum class JointKind : unsigned char { Fixed, Revolute, Prismatic };

// Constants of segment i. The joint moves the tip frame by the screw motion exp(q [S_r]) in the
// segment's root frame (the parent's tip frame): tip(q) = exp(q [S_r]) X0, with S_r = [v_r; w_r]
// the joint's twist per unit q_dot about the root origin (root axes), |w_r| = KDL's joint scale.
struct KinSegment {
  Pose X0;  // tip in root frame at q = 0 (KDL::Segment::pose(0), offset included)
  Vector6 S_r = Vector6::Zero();
  Vector3 k = Vector3::Zero();    // w_r / |w_r| (revolute)
  Vector3 kxv = Vector3::Zero();  // k x v_r / |w_r| (revolute)
  double w_norm = 0.0;            // |w_r|
  double kv = 0.0;                // k . v_r (revolute: the screw's pitch term, zero for KDL joints)
  // Revolute: K = [k]x applied once and twice to X0.R and to d = X0.p - kxv (kinematics.cpp's jointPose).
  Matrix3 KR = Matrix3::Zero(), KKR = Matrix3::Zero();
  Vector3 Kd = Vector3::Zero(), KKd = Vector3::Zero();
  JointKind kind = JointKind::Fixed;
  int joint = -1, parent = -1;
  double rotor = 0.0;  // KDL::Joint::getInertia()
  double mass = 0.0;
  Vector3 com = Vector3::Zero();    // centre of mass, tip frame, m
  Matrix3 I_com = Matrix3::Zero();  // rotational inertia about the com, tip axes, kg m^2
};

// Per-call state of segment i (base axes; S and V about the base origin).
struct KinState {
  Pose X;                       // tip pose in the base frame
  Vector6 S = Vector6::Zero();  // joint axis (unit twist per q_dot)
  Vector6 V = Vector6::Zero();  // spatial velocity
};

struct KinematicsImpl {
  explicit KinematicsImpl(const Model& m);

  Model model;
  std::vector<KinSegment> seg;
  std::vector<KinState> st;
  int nj = 0, ns = 0;
  bool has_q = false, has_qd = false;
  std::array<char, 256> message{};

  // Status with a printf-formatted message written into `message` (no allocation).
  Status fail(Error code, const char* fmt, ...);
  // The checks every call shares: the model, and q / q_dot sizes and values.
  Status checkModel(const Model& m);
  Status checkVector(const Eigen::Ref<const Eigen::VectorXd>& v, const char* name);
  Status checkFrame(const FrameRef& frame, bool need_qd);
  // NonfiniteResult when a result of finite inputs overflowed to Inf or NaN (|q_dot| ~ 1e160).
  Status checkResult(const Eigen::Ref<const Eigen::MatrixXd>& out);
  // Sweeps without checks: poses and axes at q; velocities at q_dot (after place()).
  void place(const Eigen::Ref<const Eigen::VectorXd>& q);
  void velocities(const Eigen::Ref<const Eigen::VectorXd>& qd);
  // The frame's origin in the base frame.
  Vector3 origin(const FrameRef& frame) const;
};

}  // namespace detail
}  // namespace vereshchagin
