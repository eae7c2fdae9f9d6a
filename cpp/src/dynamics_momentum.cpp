// Centre-of-mass and momentum companions (momentum.hpp). As in dynamics.cpp every sum runs in the
// base frame about the base origin O: the robot's mass M and first moment h = sum m c give the
// centre of mass c_b = h / M; a joint moves its subtree (mass M_i, first moment h_i) with the
// unit twist S_j = [v; w] about O, so its centre of mass moves by (M_i v + w x h_i) / M per unit
// q_dot_j. On a floating base the world frame follows from the base's pose (p, R):
// c = p + R c_b; the base's LOCAL velocity [v_b; w_b] moves c by R (v_b + w_b x c_b).
#include <cmath>

#include "vereshchagin/momentum.hpp"

#include "dynamics_impl.hpp"

namespace vereshchagin {

namespace {

// The floating base body's first moment m c about O (base axes), from its spatial inertia.
Vector3 baseFirstMoment(const detail::DynamicsImpl& d) {
  return Vector3(d.I_base(5, 1), d.I_base(3, 2), d.I_base(4, 0));  // the lower-left block is [m c]x
}

// The base's origin in the world (a floating base), m.
Vector3 baseOrigin(const detail::DynamicsImpl& d, const JointPositions& q) {
  const auto& x = *q;
  return Vector3(x(0), x(1), d.nb == 6 ? x(2) : 0.0);
}

// Places q (and, with qd, the velocities) and sums the total mass M and first moment h (base
// frame, the base body included); fails for a massless robot.
Status massSums(const Model& model, detail::DynamicsImpl& d, const JointPositions& q, const JointVelocities* qd,
                double& M, Vector3& h) {
  if (const Status s = detail::startEnergy(model, d, q, qd ? (**qd).data() : nullptr, qd); !s) return s;
  const detail::KinematicsImpl& k = d.k();
  M = d.nb != 0 ? d.I_base(0, 0) : 0.0;
  h = d.nb != 0 ? baseFirstMoment(d) : Vector3::Zero();
  for (int i = 0; i < k.ns; ++i) {
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    const Pose& X = k.st[static_cast<std::size_t>(i)].X;
    M += s.mass;
    h += s.mass * (X.p + X.R * s.com);
  }
  if (!(M > 0.0)) return d.k().fail(Error::InvalidModel, "the robot has no mass: its centre of mass is undefined");
  return Status();
}

}  // namespace

Status centerOfMass(const Model& model, DynamicsData& ddata, const JointPositions& q, Eigen::Ref<Eigen::Vector3d> com) {
  detail::DynamicsImpl& d = ddata.impl();
  double M = 0.0;
  Vector3 h;
  if (const Status s = massSums(model, d, q, nullptr, M, h); !s) return s;
  com = h / M;
  if (d.nb != 0) com = baseOrigin(d, q) + d.R_b * com;
  return d.k().checkResult(com);
}

Status centerOfMassJacobian(const Model& model, DynamicsData& ddata, const JointPositions& q,
                            Eigen::Ref<Eigen::MatrixXd> jacobian) {
  detail::DynamicsImpl& d = ddata.impl();
  detail::KinematicsImpl& k = d.k();
  double M = 0.0;
  Vector3 h;
  if (const Status s = massSums(model, d, q, nullptr, M, h); !s) return s;
  if (jacobian.rows() != 3 || jacobian.cols() != k.nj + d.nb)
    return k.fail(Error::SizeMismatch, "the jacobian is %ldx%ld, expected 3x%d", static_cast<long>(jacobian.rows()),
                  static_cast<long>(jacobian.cols()), k.nj + d.nb);
  for (int i = 0; i < k.ns; ++i) {  // every body's mass and first moment, then the subtrees'
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    const Pose& X = k.st[static_cast<std::size_t>(i)].X;
    d.mass[static_cast<std::size_t>(i)] = s.mass;
    d.h[static_cast<std::size_t>(i)] = s.mass * (X.p + X.R * s.com);
  }
  for (int i = k.ns - 1; i >= 0; --i) {
    const detail::KinSegment& s = k.seg[static_cast<std::size_t>(i)];
    if (s.joint >= 0) {
      const Vector6& S = k.st[static_cast<std::size_t>(i)].S;
      const Vector3 dc =
          (d.mass[static_cast<std::size_t>(i)] * S.head<3>() + S.tail<3>().cross(d.h[static_cast<std::size_t>(i)])) / M;
      jacobian.col(d.nb + s.joint) = d.nb != 0 ? Vector3(d.R_b * dc) : dc;
    }
    if (s.parent >= 0) {
      d.mass[static_cast<std::size_t>(s.parent)] += d.mass[static_cast<std::size_t>(i)];
      d.h[static_cast<std::size_t>(s.parent)] += d.h[static_cast<std::size_t>(i)];
    }
  }
  if (d.nb != 0) {  // R [1, -[c_b]x] S_b
    Eigen::Matrix<double, 3, 6> B;
    B << Matrix3::Identity(), -skew(h / M);
    jacobian.leftCols(d.nb).noalias() = d.R_b * (B * d.S_b);
  }
  return k.checkResult(jacobian);
}

namespace {

// The centroidal momentum into `momentum` and the total mass into M.
Status momentumAndMass(const Model& model, detail::DynamicsImpl& d, const JointPositions& q,
                       const JointVelocities& q_dot, Eigen::Ref<Vector6> momentum, double& M) {
  detail::KinematicsImpl& k = d.k();
  Vector3 h;
  if (const Status s = massSums(model, d, q, &q_dot, M, h); !s) return s;
  Vector6 total = d.nb != 0 ? Vector6(d.I_base * d.V_root) : Vector6::Zero();  // about O, base axes
  Vector6 body;
  for (int i = 0; i < k.ns; ++i) {
    detail::bodyMomentum(k, i, body);
    total += body;
  }
  const Vector3 c = h / M;
  const Vector3 p = total.head<3>(), L = total.tail<3>() - c.cross(p);  // about the centre of mass
  if (d.nb != 0) {
    momentum << d.R_b * p, d.R_b * L;
  } else {
    momentum << p, L;
  }
  return k.checkResult(momentum);
}

}  // namespace

Status centroidalMomentum(const Model& model, DynamicsData& ddata, const JointPositions& q,
                          const JointVelocities& q_dot, Eigen::Ref<Vector6> momentum) {
  double M = 0.0;
  return momentumAndMass(model, ddata.impl(), q, q_dot, momentum, M);
}

Status centerOfMassVelocity(const Model& model, DynamicsData& ddata, const JointPositions& q,
                            const JointVelocities& q_dot, Eigen::Ref<Eigen::Vector3d> velocity) {
  double M = 0.0;
  Vector6 momentum;
  if (const Status s = momentumAndMass(model, ddata.impl(), q, q_dot, momentum, M); !s) return s;
  velocity = momentum.head<3>() / M;
  return Status();
}

}  // namespace vereshchagin
