// Energy companions (energy.hpp). Every spatial quantity in the base frame about the base origin O
// (dynamics.cpp): a body's momentum h = [m v_c; I_c w + c x m v_c] with v_c = v_O + w x c its
// centre of mass's velocity, so that V . h = 2 T_body. The gradient comes from two facts of a fixed
// frame: a joint axis downstream of joint j turns with it, dS_l/dq_j = S_j x S_l, and so does a
// body's inertia, dI/dq_j = S_j x* I - I S_j x. Summed over the bodies of j's subtree, the terms
// of the velocities and of the inertias cancel except dT/dq_j = (V_j x S_j) . h_sub(j).
#include <cmath>

#include "vereshchagin/energy.hpp"

#include "dynamics_impl.hpp"
#include "kdl_convert.hpp"

namespace vereshchagin {
namespace detail {

// Places q and, with qd, the velocities; returns a failed Status for bad input.
Status startEnergy(const Model& model, detail::DynamicsImpl& d, const JointPositions& q, const double* qd_or_null,
                   const JointVelocities* qd) {
  detail::KinematicsImpl& k = d.k();
  if (const Status s = d.start(model, *q); !s) return s;
  if (qd) {
    if (const Status s = d.checkRate(**qd, "q_dot"); !s) return s;
    d.baseVelocity(**qd);
  }
  k.has_q = k.has_qd = false;
  k.place((*q).tail(k.nj));
  const double* qdj = qd_or_null ? qd_or_null + d.nb : nullptr;
  for (int i = 0; i < k.ns; ++i) {
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    detail::KinState& x = k.st[static_cast<std::size_t>(i)];
    x.V = s.parent < 0 ? d.V_root : k.st[static_cast<std::size_t>(s.parent)].V;
    if (qdj && s.joint >= 0) x.V += x.S * qdj[s.joint];
  }
  k.has_q = true;
  k.has_qd = qd_or_null != nullptr;
  return Status();
}

// Body i's momentum about O (base axes) into h; returns its kinetic energy without the rotor.
double bodyMomentum(const detail::KinematicsImpl& k, int i, Vector6& h) {
  const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
  const detail::KinState& x = k.st[static_cast<std::size_t>(i)];
  const Vector3 w = x.V.tail<3>();
  const Vector3 c = x.X.p + x.X.R * s.com;
  const Vector3 v_c = x.V.head<3>() + w.cross(c);
  const Vector3 Iw = x.X.R * (s.I_com * (x.X.R.transpose() * w));
  h.head<3>() = s.mass * v_c;
  h.tail<3>() = Iw + c.cross(h.head<3>());
  return 0.5 * (s.mass * v_c.squaredNorm() + w.dot(Iw));
}

}  // namespace detail

namespace {

Status finite(detail::KinematicsImpl& k, double value) {
  if (!std::isfinite(value)) return k.fail(Error::NonfiniteResult, "the result overflows the double range");
  return Status();
}

}  // namespace

Status kineticEnergy(const Model& model, DynamicsData& ddata, const JointPositions& q, const JointVelocities& q_dot,
                     double& energy) {
  detail::DynamicsImpl& d = ddata.impl();
  if (const Status s = detail::startEnergy(model, d, q, q_dot.value().data(), &q_dot); !s) return s;
  const detail::KinematicsImpl& k = d.k();
  double T = 0.0;
  Vector6 h;
  for (int i = 0; i < k.ns; ++i) {
    T += detail::bodyMomentum(k, i, h);
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    if (s.joint >= 0) T += 0.5 * s.rotor * (*q_dot)(d.nb + s.joint) * (*q_dot)(d.nb + s.joint);
  }
  if (d.nb != 0) T += 0.5 * d.V_root.dot(d.I_base * d.V_root);
  energy = T;
  return finite(d.k(), T);
}

Status potentialEnergy(const Model& model, DynamicsData& ddata, const JointPositions& q, const KDL::Vector& gravity,
                       double& energy) {
  detail::DynamicsImpl& d = ddata.impl();
  detail::KinematicsImpl& k = d.k();
  if (!std::isfinite(gravity.x()) || !std::isfinite(gravity.y()) || !std::isfinite(gravity.z()))
    return k.fail(Error::NonfiniteInput, "gravity is not finite");
  if (const Status s = detail::startEnergy(model, d, q, nullptr, nullptr); !s) return s;
  const Vector3 g = d.localGravity(detail::toEigen(gravity));
  double V = 0.0;
  for (int i = 0; i < k.ns; ++i) {
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    const detail::KinState& x = k.st[static_cast<std::size_t>(i)];
    V -= s.mass * g.dot(x.X.p + x.X.R * s.com);
  }
  if (d.nb != 0) {  // the base body's, and every mass at the base origin's height in the world
    const double m_base = d.I_base(0, 0);
    const Vector3 h_base(d.I_base(5, 1), d.I_base(3, 2), d.I_base(4, 0));  // [m c]x below-left
    V -= g.dot(h_base);
    double m_total = m_base;
    for (int i = 0; i < k.ns; ++i) m_total += k.seg[static_cast<std::size_t>(i)].mass;
    const Vector3 p(q.value()(0), q.value()(1), d.nb == 6 ? q.value()(2) : 0.0);  // the base origin, world
    V -= m_total * detail::toEigen(gravity).dot(p);
  }
  energy = V;
  return finite(k, V);
}

Status kineticEnergyGradient(const Model& model, DynamicsData& ddata, const JointPositions& q,
                             const JointVelocities& q_dot, Eigen::Ref<Eigen::VectorXd> gradient) {
  detail::DynamicsImpl& d = ddata.impl();
  if (const Status s = detail::startEnergy(model, d, q, q_dot.value().data(), &q_dot); !s) return s;
  if (const Status s = d.checkOut(gradient.size(), 1, 1, "gradient"); !s) return s;
  detail::KinematicsImpl& k = d.k();
  Vector6 h_root = Vector6::Zero();
  for (int i = 0; i < k.ns; ++i) detail::bodyMomentum(k, i, d.f[static_cast<std::size_t>(i)]);  // f: h_sub below
  for (int i = k.ns - 1; i >= 0; --i) {  // children (larger indices) before their parent
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    const detail::KinState& x = k.st[static_cast<std::size_t>(i)];
    const Vector6& h_sub = d.f[static_cast<std::size_t>(i)];
    if (s.joint >= 0) gradient(d.nb + s.joint) = crossMotion(x.V, x.S).dot(h_sub);
    if (s.parent >= 0) {
      d.f[static_cast<std::size_t>(s.parent)] += h_sub;
    } else if (d.nb != 0) {
      h_root += h_sub;
    }
  }
  if (d.nb != 0) {  // the base's rows: -S_b^T (V_b x* h), h the whole robot's momentum (energy.hpp)
    h_root.noalias() += d.I_base * d.V_root;
    gradient.head(d.nb).noalias() = -(d.S_b.transpose() * crossForce(d.V_root, h_root));
  }
  return k.checkResult(gradient);
}

}  // namespace vereshchagin
