// The workspace behind DynamicsData (dynamics.hpp): the kinematics workspace plus per-segment
// accelerations, wrenches and composite inertias, all in the base frame about the base origin.
// On a floating base (base_kind.hpp) "the base frame" is the inertial frame that coincides with
// the base body at the call's instant (dynamics_base.cpp): the base's velocity and acceleration
// (base axes, Pinocchio's LOCAL) start the sweeps, and gravity and f_ext are turned into it.
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
        f_frames(6, m.nrOfSegments()) {
    initBase(m);
  }

  KinematicsData kin;
  std::vector<Vector6> A, f;  // spatial accelerations; transmitted wrenches (about O)
  std::vector<double> mass;   // composite: mass,
  std::vector<Vector3> h;     // first moment sum m c,
  std::vector<Matrix3> J;     // rotational inertia about O
  Matrix6X f_frames;          // companion_call.cpp: f_ext summed from wrenches on frames
  // The floating base (dynamics_base.cpp): nb velocity entries (0 on a fixed base), nbq
  // configuration entries, axes S_b (6 x nb, base frame), the base body's spatial inertia about
  // its origin; per call its orientation R_b (base to world axes), velocity V_root and the
  // acceleration A_root (base axes, the world's -gravity included) the sweeps start from, and
  // the wrench f_root the root segments' subtrees transmit to the base (about O, base axes).
  int nb = 0, nbq = 0;
  Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6> S_b;
  Matrix6 I_base = Matrix6::Zero();
  Matrix3 R_b = Matrix3::Identity();
  Vector6 V_root = Vector6::Zero(), A_root = Vector6::Zero(), f_root = Vector6::Zero();

  KinematicsImpl& k() { return kin.impl(); }
  // Checks the model and q (nq entries; on a floating base its base part, whose orientation R_b
  // it reads); V_root is zero until baseVelocity().
  Status start(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q) {
    KinematicsImpl& ki = k();
    if (const Status s = ki.checkModel(model); !s) return s;
    V_root.setZero();
    if (nb == 0) return ki.checkVector(q, "q");
    return startBase(q);
  }
  // q_dot, q_ddot (nv entries): the joints' check on a fixed base, else sizes and values here.
  Status checkRate(const Eigen::Ref<const Eigen::VectorXd>& v, const char* name) {
    if (nb == 0) return k().checkVector(v, name);
    return checkBaseVector(v, nb, name);
  }
  void initBase(const Model& m);
  Status startBase(const Eigen::Ref<const Eigen::VectorXd>& q);
  Status checkBaseVector(const Eigen::Ref<const Eigen::VectorXd>& v, int base, const char* name);
  // V_root = S_b qd_b from q_dot's base rows (nothing on a fixed base).
  void baseVelocity(const Eigen::Ref<const Eigen::VectorXd>& q_dot) {
    if (nb != 0) V_root.noalias() = S_b * q_dot.head(nb);
  }
  // Gravity (physical, world axes on a floating base) in the sweeps' axes.
  Vector3 localGravity(const Vector3& g) const { return nb == 0 ? g : Vector3(R_b.transpose() * g); }
  // The base's rows of a generalized force: S_b^T of the wrench the base body needs for A_root
  // and V_root plus f_root (dynamics_base.cpp).
  void baseRows(Eigen::Ref<Eigen::VectorXd> tau) const;
  Status checkOut(Eigen::Index rows, Eigen::Index cols, Eigen::Index want_cols, const char* name) {
    const int n = k().nj + nb;
    if (rows != n || cols != want_cols)
      return k().fail(Error::SizeMismatch, "%s is %ldx%ld, expected %dx%ld", name, static_cast<long>(rows),
                      static_cast<long>(cols), n, static_cast<long>(want_cols));
    return Status();
  }
  void rnea(const double* qd, const double* qdd, const Eigen::Ref<const Matrix6X>& f_ext, const Vector3& gravity,
            Eigen::Ref<Eigen::VectorXd> tau);
  void bodyWrench(int i);
};

// Places q and, with qd (nv entries, qd_or_null its data), every segment's velocity; returns a
// failed Status for bad input (dynamics_energy.cpp).
Status startEnergy(const Model& model, DynamicsImpl& d, const JointPositions& q, const double* qd_or_null,
                   const JointVelocities* qd);
// Body i's momentum about O (base axes) into h; returns its kinetic energy without the rotor.
double bodyMomentum(const KinematicsImpl& k, int i, Vector6& h);

}  // namespace detail
}  // namespace vereshchagin
