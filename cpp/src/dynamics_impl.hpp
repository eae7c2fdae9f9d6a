// The workspace behind DynamicsData (dynamics.hpp): the kinematics workspace plus per-segment
// accelerations, wrenches and composite inertias, all in the base frame about the base origin.
#pragma once

#include <vector>

#include "vereshchagin/dynamics.hpp"

#include "kinematics_impl.hpp"

namespace vereshchagin {
namespace detail {

struct DynamicsImpl {
  explicit DynamicsImpl(const Model& m)
      : kin(m),
        A(m.nrOfSegments(), Vector6::Zero()),
        f(m.nrOfSegments(), Vector6::Zero()),
        mass(m.nrOfSegments(), 0.0),
        h(m.nrOfSegments(), Vector3::Zero()),
        J(m.nrOfSegments(), Matrix3::Zero()),
        f_frames(6, m.nrOfSegments()) {}

  KinematicsData kin;
  std::vector<Vector6> A, f;  // spatial accelerations; transmitted wrenches (about O)
  std::vector<double> mass;   // composite: mass,
  std::vector<Vector3> h;     // first moment sum m c,
  std::vector<Matrix3> J;     // rotational inertia about O
  Matrix6X f_frames;          // companion_call.cpp: f_ext summed from wrenches on frames

  KinematicsImpl& k() { return kin.impl(); }
  Status start(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q) {
    KinematicsImpl& ki = k();
    if (const Status s = ki.checkModel(model); !s) return s;
    if (model.baseKind() != BaseKind::Fixed)  // (a fixed-base answer would be silently wrong)
      return ki.fail(Error::InvalidOptions,
                     "the dynamics companions (inverse_dynamics, mass_matrix, gravity_torques, coriolis_torques) do "
                     "not support a floating base yet (docs/floating-base.md); the kinematics companions work in the "
                     "base frame");
    return ki.checkVector(q, "q");
  }
  Status checkOut(Eigen::Index rows, Eigen::Index cols, Eigen::Index want_cols, const char* name) {
    const int n = k().nj;
    if (rows != n || cols != want_cols)
      return k().fail(Error::SizeMismatch, "%s is %ldx%ld, expected %dx%ld", name, static_cast<long>(rows),
                      static_cast<long>(cols), n, static_cast<long>(want_cols));
    return Status();
  }
  void rnea(const double* qd, const double* qdd, const Eigen::Ref<const Matrix6X>& f_ext, const Vector3& gravity,
            Eigen::Ref<Eigen::VectorXd> tau);
  void bodyWrench(int i);
};

}  // namespace detail
}  // namespace vereshchagin
