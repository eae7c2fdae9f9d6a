// The floating base in the dynamics and energy companions (dynamics.hpp, energy.hpp): its model
// (axes, spatial inertia), the checks of its part of q, q_dot and q_ddot, and the base rows of a
// generalized force. The sweeps run in the inertial frame that coincides with the base body at
// the call's instant, so the joints' quantities are those of a fixed base, the base's velocity and
// acceleration (Pinocchio's LOCAL: base axes, about the base origin) start them, and gravity and
// f_ext (world axes) are turned into base axes by R_b^T.
#include <cmath>

#include "dynamics_impl.hpp"
#include "kdl_convert.hpp"

namespace vereshchagin {
namespace detail {

namespace {
constexpr double kUnitTolerance = 1e-6;  // as the solver's (floating_base.cpp)
}  // namespace

void DynamicsImpl::initBase(const Model& m) {
  const BaseKind kind = m.baseKind();
  nb = baseVelocitySize(kind);
  nbq = baseConfigurationSize(kind);
  S_b.setZero(6, nb);
  if (kind == BaseKind::FreeFlyer) {
    S_b.setIdentity(6, 6);
  } else if (kind == BaseKind::Planar) {  // x, y translation, z rotation
    S_b(0, 0) = S_b(1, 1) = S_b(5, 2) = 1.0;
  }
  if (nb == 0) return;
  const KDL::RigidBodyInertia& rbi = m.options().base_inertia;
  const Matrix3 I_origin = Eigen::Map<const Matrix3>(rbi.getRotationalInertia().data);
  I_base = rigidInertia(rbi.getMass(), toEigen(rbi.getCOG()), 0.5 * (I_origin + I_origin.transpose()));
}

Status DynamicsImpl::checkBaseVector(const Eigen::Ref<const Eigen::VectorXd>& v, int base, const char* name) {
  KinematicsImpl& ki = k();
  const long want = base + ki.nj;
  const char* kind = nb == 6 ? "free-flyer base" : "planar base";
  if (v.size() != want)
    return ki.fail(Error::SizeMismatch, "%s has %ld entries, expected %ld (%d for the %s, then %d joints)", name,
                   static_cast<long>(v.size()), want, base, kind, ki.nj);
  for (long j = 0; j < want; ++j)
    if (!std::isfinite(v(j))) return ki.fail(Error::NonfiniteInput, "%s[%ld] is not finite", name, j);
  return Status();
}

// q's base part: the unit quaternion (x, y, z, w) or (cos yaw, sin yaw) into R_b.
Status DynamicsImpl::startBase(const Eigen::Ref<const Eigen::VectorXd>& q) {
  if (const Status s = checkBaseVector(q, nbq, "q"); !s) return s;
  const bool ff = nb == 6;
  const double norm = ff ? q.segment<4>(3).norm() : q.segment<2>(2).norm();
  if (!(std::abs(norm - 1.0) <= kUnitTolerance))
    return k().fail(Error::NonfiniteInput,
                    ff ? "the base quaternion q[3:7] (x, y, z, w) has norm %.17g: it must be a unit quaternion "
                         "(within 1e-6; normalize it)"
                       : "the planar base's (cos yaw, sin yaw) = q[2:4] has norm %.17g: it must be a unit vector "
                         "(within 1e-6; normalize it)",
                    norm);
  if (ff) {
    R_b = Eigen::Quaterniond(q(6), q(3), q(4), q(5)).normalized().toRotationMatrix();
  } else {
    const double c = q(2) / norm, s = q(3) / norm;
    R_b << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  }
  return Status();
}

void DynamicsImpl::baseRows(Eigen::Ref<Eigen::VectorXd> tau) const {
  const Vector6 f = I_base * A_root + crossForce(V_root, I_base * V_root) + f_root;
  tau.head(nb).noalias() = S_b.transpose() * f;
}

}  // namespace detail
}  // namespace vereshchagin
