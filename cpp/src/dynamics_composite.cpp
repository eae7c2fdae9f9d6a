// Mass matrix and gravity torques (dynamics.hpp) from composite bodies: in the base frame about
// the base origin O a subtree's inertia is the plain sum of its bodies' (mass M, first moment
// h = sum m c, rotational inertia J_O = sum I_c + m (|c|^2 1 - c c^T)), so the inward sweep only
// adds. Spatial inertia about O applied to a motion S = [v; w]:  [M v + w x h;  h x v + J_O w].
#include <cmath>

#include "dynamics_impl.hpp"

namespace vereshchagin {

namespace {

// Body i's mass, first moment and (with rotational = true) rotational inertia about O, base axes.
void placeBody(detail::DynamicsImpl& d, int i, bool rotational) {
  const detail::KinSegment& s = d.k().seg[static_cast<std::size_t>(i)];
  const Pose& X = d.k().st[static_cast<std::size_t>(i)].X;
  const Vector3 c = X.p + X.R * s.com;
  d.mass[static_cast<std::size_t>(i)] = s.mass;
  d.h[static_cast<std::size_t>(i)] = s.mass * c;
  if (!rotational) return;
  Matrix3& J = d.J[static_cast<std::size_t>(i)];
  J.noalias() = X.R * s.I_com * X.R.transpose();
  J.noalias() -= s.mass * c * c.transpose();
  J.diagonal().array() += s.mass * c.squaredNorm();
}

// Adds composite i into its parent's.
void addToParent(detail::DynamicsImpl& d, int i, int parent, bool rotational) {
  d.mass[static_cast<std::size_t>(parent)] += d.mass[static_cast<std::size_t>(i)];
  d.h[static_cast<std::size_t>(parent)] += d.h[static_cast<std::size_t>(i)];
  if (rotational) d.J[static_cast<std::size_t>(parent)] += d.J[static_cast<std::size_t>(i)];
}

// The floating base's block of H: S_b^T (I_base + every root composite) S_b.
void baseBlock(detail::DynamicsImpl& d, Eigen::Ref<Eigen::MatrixXd> H) {
  const detail::KinematicsImpl& k = d.k();
  Matrix6 I = d.I_base;
  for (int i = 0; i < k.ns; ++i) {
    if (k.seg[static_cast<std::size_t>(i)].parent >= 0) continue;
    const Vector3& h = d.h[static_cast<std::size_t>(i)];
    const double m = d.mass[static_cast<std::size_t>(i)];
    I.topLeftCorner<3, 3>().diagonal().array() += m;
    I.topRightCorner<3, 3>() -= skew(h);  // force of w: w x h = -[h]x w
    I.bottomLeftCorner<3, 3>() += skew(h);
    I.bottomRightCorner<3, 3>() += d.J[static_cast<std::size_t>(i)];
  }
  H.topLeftCorner(d.nb, d.nb).noalias() = d.S_b.transpose() * I * d.S_b;
}

}  // namespace

// H_jk = S_k . (Ic_i S_j) for the joint j of segment i and every joint k on i's path to the base
// (Ic_i: segment i and everything below it); rotor inertia on the diagonal.
Status massMatrix(const Model& model, DynamicsData& ddata, const JointPositions& q, Eigen::Ref<Eigen::MatrixXd> H) {
  detail::DynamicsImpl& d = ddata.impl();
  detail::KinematicsImpl& k = d.k();
  if (const Status s = d.start(model, *q); !s) return s;
  const int nb = d.nb;
  if (const Status s = d.checkOut(H.rows(), H.cols(), k.nj + nb, "H"); !s) return s;
  k.has_q = k.has_qd = false;
  k.place((*q).tail(k.nj));
  H.setZero();
  for (int i = 0; i < k.ns; ++i) placeBody(d, i, true);
  for (int i = k.ns - 1; i >= 0; --i) {  // composite i is complete: its children were added already
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    if (s.joint >= 0) {
      const Vector6& S = k.st[static_cast<std::size_t>(i)].S;
      const Vector3 v = S.head<3>(), w = S.tail<3>();
      const Vector3& h = d.h[static_cast<std::size_t>(i)];
      Vector6 F;  // the wrench that gives the composite a unit q_ddot_j
      F.head<3>() = d.mass[static_cast<std::size_t>(i)] * v + w.cross(h);
      F.tail<3>().noalias() = d.J[static_cast<std::size_t>(i)] * w;
      F.tail<3>() += h.cross(v);
      const int j = nb + s.joint;
      H(j, j) = S.dot(F) + s.rotor;
      for (int a = s.parent; a >= 0; a = k.seg[static_cast<std::size_t>(a)].parent) {
        const int r = k.seg[static_cast<std::size_t>(a)].joint;
        if (r >= 0) H(nb + r, j) = H(j, nb + r) = k.st[static_cast<std::size_t>(a)].S.dot(F);
      }
      if (nb != 0) H.col(j).head(nb).noalias() = d.S_b.transpose() * F;
      if (nb != 0) H.row(j).head(nb) = H.col(j).head(nb).transpose();
    }
    if (s.parent >= 0) addToParent(d, i, s.parent, true);
  }
  if (nb != 0) baseBlock(d, H);
  k.has_q = true;
  return k.checkResult(H);
}

// With the base accelerated by -g and the bodies at rest, each body needs the wrench
// [-m g; c x (-m g)] about O; a subtree needs [-M g; g x h] and tau_j = S_j . that.
Status gravityTorques(const Model& model, DynamicsData& ddata, const JointPositions& q, const KDL::Vector& gravity,
                      Eigen::Ref<Eigen::VectorXd> tau) {
  detail::DynamicsImpl& d = ddata.impl();
  detail::KinematicsImpl& k = d.k();
  if (const Status s = d.start(model, *q); !s) return s;
  if (!std::isfinite(gravity.x()) || !std::isfinite(gravity.y()) || !std::isfinite(gravity.z()))
    return k.fail(Error::NonfiniteInput, "gravity is not finite");
  if (const Status s = d.checkOut(tau.size(), 1, 1, "tau"); !s) return s;
  k.has_q = k.has_qd = false;
  k.place((*q).tail(k.nj));
  const Vector3 g = d.localGravity(Vector3(gravity.x(), gravity.y(), gravity.z()));
  for (int i = 0; i < k.ns; ++i) placeBody(d, i, false);
  for (int i = k.ns - 1; i >= 0; --i) {
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    if (s.joint >= 0) {
      const Vector6& S = k.st[static_cast<std::size_t>(i)].S;
      tau(d.nb + s.joint) = -d.mass[static_cast<std::size_t>(i)] * S.head<3>().dot(g) +
                            S.tail<3>().dot(g.cross(d.h[static_cast<std::size_t>(i)]));
    }
    if (s.parent >= 0) addToParent(d, i, s.parent, false);
  }
  if (d.nb != 0) {  // the base's rows: the whole robot's weight held, as a wrench on the base
    d.A_root << -g, Vector3::Zero();
    d.f_root.setZero();
    for (int i = 0; i < k.ns; ++i)
      if (k.seg[static_cast<std::size_t>(i)].parent < 0) {
        const double m = d.mass[static_cast<std::size_t>(i)];
        d.f_root.head<3>() -= m * g;
        d.f_root.tail<3>() += g.cross(d.h[static_cast<std::size_t>(i)]);
      }
    d.baseRows(tau);
  }
  k.has_q = true;
  return k.checkResult(tau);
}

}  // namespace vereshchagin
