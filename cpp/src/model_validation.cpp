// Geometric validity of a KDL segment. See model_validation.hpp.
#include "model_validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>

namespace vereshchagin {
namespace detail {

namespace {

bool finite(const KDL::Vector& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

}  // namespace

const char* segmentGeometryProblem(const KDL::Segment& segment) {
  const KDL::Frame tip = segment.getFrameToTip();
  if (!finite(tip.p)) return "tip frame position is not finite";
  double R[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      R[r][c] = tip.M(r, c);
      if (!std::isfinite(R[r][c])) return "tip frame rotation is not finite";
    }
  // Orthonormality: R^T R = I to 1e-6 (KDL rotations built from angles or quaternions are exact
  // to round-off), and a right-handed frame.
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      double dot = 0.0;
      for (int k = 0; k < 3; ++k) dot += R[k][a] * R[k][b];
      if (std::abs(dot - (a == b ? 1.0 : 0.0)) > 1e-6) return "tip frame rotation is not orthonormal";
    }
  const double det = R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) -
                     R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0]) +
                     R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]);
  if (!(det > 0.0)) return "tip frame rotation has determinant -1 (a reflection)";
  const KDL::Joint& joint = segment.getJoint();
  if (joint.getType() == KDL::Joint::RotAxis || joint.getType() == KDL::Joint::TransAxis) {
    if (!finite(joint.JointOrigin())) return "joint origin is not finite";
    if (!finite(joint.JointAxis())) return "joint axis is not finite";
  }
  return nullptr;
}

const char* inertiaProblem(double mass, const Eigen::Matrix3d& I_com, InertiaCheck check, char* buf, std::size_t size,
                           double round_off) {
  if (!std::isfinite(mass) || !I_com.allFinite()) return "inertial parameters are not finite";
  if (mass < 0.0) {
    std::snprintf(buf, size, "negative mass %g (must be >= 0)", mass);
    return buf;
  }
  constexpr double kRobotLength2 = 1.0;  // (1 m)^2: the length scale of a robot
  const double tol = 1e-12 * std::max({I_com.cwiseAbs().maxCoeff(), round_off, mass * kRobotLength2});
  if ((I_com - I_com.transpose()).cwiseAbs().maxCoeff() > tol) return "rotational inertia is not symmetric";
  if (check == InertiaCheck::JointSpace) return nullptr;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (I_com + I_com.transpose()), Eigen::EigenvaluesOnly);
  const Eigen::Vector3d I = es.eigenvalues();  // ascending
  if (I(0) < -tol) {
    std::snprintf(buf, size,
                  "rotational inertia about the centre of mass is not positive semi-definite (principal "
                  "moments %g, %g, %g); identified models are accepted with inertia_check = joint_space",
                  I(0), I(1), I(2));
    return buf;
  }
  if (I(0) + I(1) < I(2) - std::max(1e-6 * I(2), tol)) {
    std::snprintf(buf, size,
                  "principal moments of inertia about the centre of mass (%g, %g, %g) violate the triangle "
                  "inequality I1 + I2 >= I3: no rigid body has them; identified models are accepted with "
                  "inertia_check = joint_space",
                  I(0), I(1), I(2));
    return buf;
  }
  return nullptr;
}

}  // namespace detail
}  // namespace vereshchagin
