// The position update of a floating base (base_kind.hpp: integrateConfiguration), written from
// the exponential maps of SE(3) and SE(2). A LOCAL twist (v, w) held for unit time moves the base
// frame M to M exp([v; w]): the rotation exp([w]x) = Rodrigues' formula, and the translation
// G(w) v with G = 1 + (1 - cos t) / t^2 [w]x + (t - sin t) / t^3 [w]x^2 (t = |w|), in base axes.
// Near t = 0 the coefficients come from their series (error below 1e-17 for t < 1e-4).
#include <cmath>

#include <Eigen/Geometry>

#include "vereshchagin/base_kind.hpp"

namespace vereshchagin {

namespace {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;

// (1 - cos t) / t^2 and (t - sin t) / t^3 for t = |w|, and sin(t/2)/t, cos(t/2).
struct ExpCoefficients {
  double a, b, half_sin_over_t, half_cos;
};

ExpCoefficients coefficients(double t) {
  const double t2 = t * t;
  if (t < 1e-4) return {0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0, 0.5 - t2 / 48.0, 1.0 - t2 / 8.0};
  return {(1.0 - std::cos(t)) / t2, (t - std::sin(t)) / (t2 * t), std::sin(0.5 * t) / t, std::cos(0.5 * t)};
}

void freeFlyer(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& v, double dt,
               Eigen::Ref<Eigen::VectorXd> q_next) {
  const Eigen::Quaterniond quat(q(6), q(3), q(4), q(5));  // (w, x, y, z)
  const Vector3 lin = dt * v.head<3>(), w = dt * v.segment<3>(3);
  const ExpCoefficients c = coefficients(w.norm());
  const Vector3 wxv = w.cross(lin);
  const Vector3 step = lin + c.a * wxv + c.b * w.cross(wxv);  // G(w) v, base axes
  q_next.head<3>() = q.head<3>() + quat.normalized().toRotationMatrix() * step;
  const Vector3 axis = c.half_sin_over_t * w;
  Eigen::Quaterniond next = quat * Eigen::Quaterniond(c.half_cos, axis.x(), axis.y(), axis.z());
  next.normalize();
  q_next.segment<4>(3) << next.x(), next.y(), next.z(), next.w();
}

void planar(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& v, double dt,
            Eigen::Ref<Eigen::VectorXd> q_next) {
  const double norm = std::hypot(q(2), q(3)), c0 = q(2) / norm, s0 = q(3) / norm;
  const double vx = dt * v(0), vy = dt * v(1), t = dt * v(2), ct = std::cos(t), st = std::sin(t);
  double sinc, cosc;  // sin(t) / t and (1 - cos(t)) / t
  if (std::abs(t) < 1e-4) {
    sinc = 1.0 - t * t / 6.0;
    cosc = t / 2.0 - t * t * t / 24.0;
  } else {
    sinc = st / t;
    cosc = (1.0 - ct) / t;
  }
  const double dx = sinc * vx - cosc * vy, dy = cosc * vx + sinc * vy;  // base axes
  q_next(0) = q(0) + c0 * dx - s0 * dy;
  q_next(1) = q(1) + s0 * dx + c0 * dy;
  const double c1 = c0 * ct - s0 * st, s1 = s0 * ct + c0 * st, n1 = std::hypot(c1, s1);
  q_next(2) = c1 / n1;
  q_next(3) = s1 / n1;
}

}  // namespace

void integrateConfiguration(BaseKind kind, const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& v, double dt, Eigen::Ref<Eigen::VectorXd> q_next) {
  const Eigen::Index n = q.size() - baseConfigurationSize(kind);
  q_next.tail(n) = q.tail(n) + dt * v.tail(n);
  if (kind == BaseKind::FreeFlyer) freeFlyer(q, v, dt, q_next);
  if (kind == BaseKind::Planar) planar(q, v, dt, q_next);
}

void setNeutralBase(BaseKind kind, Eigen::Ref<Eigen::VectorXd> q) {
  const int nbq = baseConfigurationSize(kind);
  q.head(nbq).setZero();
  if (kind == BaseKind::FreeFlyer) q(6) = 1.0;
  if (kind == BaseKind::Planar) q(2) = 1.0;
}

}  // namespace vereshchagin
