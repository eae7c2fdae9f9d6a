// Dynamics companions (dynamics.hpp), written from the Newton-Euler equations of each body and
// the composite-rigid-body idea, in ONE fixed frame: every spatial vector below has base axes and
// its reference point at the base origin O (kinematics_impl.hpp), so nothing is transformed
// between links; a body's quantities come from its mass m, centre of mass c and rotational
// inertia I_c about c, placed in the base frame at q.
//
// Per body, with V = [v_O; w] its spatial velocity and A = [a_O; dw] its spatial acceleration
// (a_O: acceleration of the body point at O, as a spatial vector; its point at c then has the
// classical acceleration a_c = a_O + dw x c + w x (v_O + w x c)):
//     F = m a_c,   N_O = I_c dw + w x (I_c w) + c x F      (Newton, Euler about c, moved to O).
// A joint's axis S (unit twist about O) moves with its body, dS/dt = V x S, so
// A_i = A_parent + S_i q_ddot_i + V_i x (S_i q_dot_i), with A_root = [-gravity; 0] (the base
// accelerated against gravity stands for the weights). tau_j = S_j . (wrench its joint transmits).
#include <cmath>

#include "vereshchagin/dynamics.hpp"

#include "dynamics_impl.hpp"
#include "kdl_convert.hpp"

namespace vereshchagin {
namespace detail {

// f[i] = the rate of change of body i's momentum (about O) for its V and A.
void DynamicsImpl::bodyWrench(int i) {
  const KinSegment& s = k().seg[static_cast<std::size_t>(i)];
  const KinState& x = k().st[static_cast<std::size_t>(i)];
  const Vector6& a = A[static_cast<std::size_t>(i)];
  const Vector3 w = x.V.tail<3>(), dw = a.tail<3>();
  const Vector3 c = x.X.p + x.X.R * s.com;
  const Vector3 v_c = x.V.head<3>() + w.cross(c);
  const Vector3 F = s.mass * (a.head<3>() + dw.cross(c) + w.cross(v_c));
  const Vector3 w_l = x.X.R.transpose() * w, dw_l = x.X.R.transpose() * dw;  // tip axes
  const Vector3 N_l = s.I_com * dw_l + w_l.cross(s.I_com * w_l);
  Vector6& out = f[static_cast<std::size_t>(i)];
  out.head<3>() = F;
  out.tail<3>().noalias() = x.X.R * N_l;
  out.tail<3>() += c.cross(F);
}

// Outward: velocities, accelerations and body wrenches; inward: joint torques. qd, qdd: the
// joints' rates, nullptr for zero; f_ext: 6 x 0 for none. Positions must be placed already. On a
// floating base the caller sets V_root and A_root (the base's own acceleration; -gravity is added
// here); f_ext is in world axes there, and baseRows() then gives the base's rows from f_root.
void DynamicsImpl::rnea(const double* qd, const double* qdd, const Eigen::Ref<const Matrix6X>& f_ext,
                        const Vector3& gravity, Eigen::Ref<Eigen::VectorXd> tau) {
  KinematicsImpl& ki = k();
  Vector6 root = Vector6::Zero();
  root.head<3>() = -gravity;
  if (nb != 0) root += A_root;  // the base's own acceleration (set by the caller)
  A_root = root;
  f_root.setZero();
  for (int i = 0; i < ki.ns; ++i) {
    const KinSegment& s = ki.seg[static_cast<std::size_t>(i)];
    KinState& x = ki.st[static_cast<std::size_t>(i)];
    Vector6& a = A[static_cast<std::size_t>(i)];
    if (s.parent < 0) {
      x.V = V_root;
      a = root;
    } else {
      x.V = ki.st[static_cast<std::size_t>(s.parent)].V;
      a = A[static_cast<std::size_t>(s.parent)];
    }
    if (s.joint >= 0) {
      if (qd) {
        const Vector6 rate = x.S * qd[s.joint];
        x.V += rate;
        a += crossMotion(x.V, rate);
      }
      if (qdd) a.noalias() += x.S * qdd[s.joint];
    }
    bodyWrench(i);
    if (f_ext.cols() != 0) {
      Vector6 fe = f_ext.col(i);
      if (nb != 0) {  // world axes to base axes
        fe.head<3>() = R_b.transpose() * Vector3(f_ext.col(i).head<3>());
        fe.tail<3>() = R_b.transpose() * Vector3(f_ext.col(i).tail<3>());
      }
      Vector6& out = f[static_cast<std::size_t>(i)];
      out.head<3>() -= fe.head<3>();
      out.tail<3>() -= fe.tail<3>() + x.X.p.cross(fe.head<3>());
    }
  }
  for (int i = ki.ns - 1; i >= 0; --i) {  // children (larger indices) before their parent
    const KinSegment& s = ki.seg[static_cast<std::size_t>(i)];
    const Vector6& fi = f[static_cast<std::size_t>(i)];
    if (s.joint >= 0)
      tau(s.joint) = ki.st[static_cast<std::size_t>(i)].S.dot(fi) + (qdd ? s.rotor * qdd[s.joint] : 0.0);
    if (s.parent >= 0) {
      f[static_cast<std::size_t>(s.parent)] += fi;
    } else if (nb != 0) {
      f_root += fi;
    }
  }
}

}  // namespace detail

DynamicsData::DynamicsData(const Model& model) : impl_(std::make_unique<detail::DynamicsImpl>(model)) {}
DynamicsData::~DynamicsData() = default;
DynamicsData::DynamicsData(DynamicsData&&) noexcept = default;
DynamicsData& DynamicsData::operator=(DynamicsData&&) noexcept = default;
const Model& DynamicsData::model() const noexcept {
  return impl_->kin.model();
}
KinematicsData& DynamicsData::kinematics() noexcept {
  return impl_->kin;
}
const KinematicsData& DynamicsData::kinematics() const noexcept {
  return impl_->kin;
}

namespace {

const Eigen::Map<const Matrix6X> kNoWrenches(nullptr, 6, 0);

Status checkGravity(detail::KinematicsImpl& k, const KDL::Vector& g) {
  if (!std::isfinite(g.x()) || !std::isfinite(g.y()) || !std::isfinite(g.z()))
    return k.fail(Error::NonfiniteInput, "gravity is not finite");
  return Status();
}

}  // namespace

Status inverseDynamics(const Model& model, DynamicsData& ddata, const JointPositions& q, const JointVelocities& q_dot,
                       const JointAccelerations& q_ddot, const Eigen::Ref<const Matrix6X>& f_ext,
                       const KDL::Vector& gravity, Eigen::Ref<Eigen::VectorXd> tau) {
  detail::DynamicsImpl& d = ddata.impl();
  detail::KinematicsImpl& k = d.k();
  if (const Status s = d.start(model, *q); !s) return s;
  if (const Status s = d.checkRate(*q_dot, "q_dot"); !s) return s;
  if (const Status s = d.checkRate(*q_ddot, "q_ddot"); !s) return s;
  if (const Status s = checkGravity(k, gravity); !s) return s;
  if (f_ext.cols() != 0 && f_ext.cols() != k.ns)
    return k.fail(Error::SizeMismatch, "f_ext has %ld columns, expected %d (one per segment) or 0",
                  static_cast<long>(f_ext.cols()), k.ns);
  if (!f_ext.allFinite()) return k.fail(Error::NonfiniteInput, "f_ext is not finite");
  if (const Status s = d.checkOut(tau.size(), 1, 1, "tau"); !s) return s;
  k.has_q = k.has_qd = false;
  const int nb = d.nb;
  k.place((*q).tail(k.nj));
  d.baseVelocity(*q_dot);
  if (nb != 0) d.A_root.noalias() = d.S_b * (*q_ddot).head(nb);
  d.rnea((*q_dot).data() + nb, (*q_ddot).data() + nb, f_ext, d.localGravity(detail::toEigen(gravity)), tau.tail(k.nj));
  if (nb != 0) d.baseRows(tau);
  k.has_q = k.has_qd = true;
  return k.checkResult(tau);
}

Status coriolisTorques(const Model& model, DynamicsData& ddata, const JointPositions& q, const JointVelocities& q_dot,
                       Eigen::Ref<Eigen::VectorXd> tau) {
  detail::DynamicsImpl& d = ddata.impl();
  detail::KinematicsImpl& k = d.k();
  if (const Status s = d.start(model, *q); !s) return s;
  if (const Status s = d.checkRate(*q_dot, "q_dot"); !s) return s;
  if (const Status s = d.checkOut(tau.size(), 1, 1, "tau"); !s) return s;
  k.has_q = k.has_qd = false;
  k.place((*q).tail(k.nj));
  d.baseVelocity(*q_dot);
  d.A_root.setZero();
  d.rnea((*q_dot).data() + d.nb, nullptr, kNoWrenches, Vector3::Zero(), tau.tail(k.nj));
  if (d.nb != 0) d.baseRows(tau);
  k.has_q = k.has_qd = true;
  return k.checkResult(tau);
}

}  // namespace vereshchagin
