// Task-space helpers (task.hpp).
#include "vereshchagin/task.hpp"

#include <cmath>

#include "kinematics_impl.hpp"

namespace vereshchagin {

Vector6 spatialFromClassical(const Vector6& classical, const Vector6& twist, const KDL::Vector& gravity) {
  const Vector3 v = twist.head<3>(), w = twist.tail<3>();
  Vector6 out;
  out.head<3>() = classical.head<3>() - w.cross(v) - Vector3(gravity.x(), gravity.y(), gravity.z());
  out.tail<3>() = classical.tail<3>();
  return out;
}

void betaFromClassical(const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Vector6& classical, const Vector6& twist,
                       const KDL::Vector& gravity, Eigen::Ref<Eigen::VectorXd> beta) {
  beta.noalias() = alfa.transpose() * spatialFromClassical(classical, twist, gravity);
}

bool betaShape(const ArrayArg& alfa, const ArrayArg& classical, const ArrayArg& twist, const ArrayArg& gravity,
               int& ndim, long shape[2]) {
  for (const ArrayArg* a : {&alfa, &classical, &twist, &gravity})
    for (long i = 0; i < a->size(); ++i)
      if (!std::isfinite(a->data[i])) return false;
  if (gravity.size() != 3 || (alfa.ndim != 1 && alfa.ndim != 2) || alfa.shape[0] != 6) return false;
  const bool batched = twist.ndim == 2 && twist.shape[1] == 6 && twist.size() != 6;
  const long rows = batched ? twist.shape[0] : 1;
  const bool classical_rows = classical.size() != 6;
  if ((!batched && twist.size() != 6) ||
      (classical_rows && !(batched && classical.ndim == 2 && classical.shape[0] == rows && classical.shape[1] == 6)))
    return false;
  const long m = alfa.ndim == 1 ? 1 : alfa.shape[1];
  ndim = batched ? 2 : 1;
  shape[0] = batched ? rows : m;
  shape[1] = m;
  return true;
}

bool betaFromArrays(const ArrayArg& alfa, const ArrayArg& classical, const ArrayArg& twist, const ArrayArg& gravity,
                    double* beta) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Index m = alfa.ndim == 1 ? 1 : alfa.shape[1];
  const Eigen::Index rows = twist.size() / 6;
  const Eigen::Map<const RowMajor> alfa_rows(alfa.data, 6, m);
  const KDL::Vector g(gravity.data[0], gravity.data[1], gravity.data[2]);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Vector6 acc = Eigen::Map<const Vector6>(classical.data + (classical.size() != 6 ? 6 * r : 0));
    const Vector6 tw = Eigen::Map<const Vector6>(twist.data + 6 * r);
    Eigen::Map<Eigen::VectorXd>(beta + m * r, m).noalias() = alfa_rows.transpose() * spatialFromClassical(acc, tw, g);
  }
  return Eigen::Map<const Eigen::ArrayXd>(beta, rows * m).allFinite();
}

Status betaForFrame(const Model& model, KinematicsData& kdata, const FrameRef& frame,
                    const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Vector6& classical, const KDL::Vector& gravity,
                    Eigen::Ref<Eigen::VectorXd> beta) {
  detail::KinematicsImpl& k = kdata.impl();
  if (alfa.rows() != 6 || beta.size() != alfa.cols())
    return k.fail(Error::SizeMismatch, "alfa is %ldx%ld and beta has %ld entries, expected 6 x m and m",
                  static_cast<long>(alfa.rows()), static_cast<long>(alfa.cols()), static_cast<long>(beta.size()));
  Vector6 twist;
  if (const Status s = frameTwist(model, kdata, frame, twist); !s) return s;
  betaFromClassical(alfa, classical, twist, gravity, beta);
  return Status();
}

namespace {

// Unit quaternion (w, x, y, z), w >= 0, of a rotation matrix: Shepperd's choice of the largest of
// the trace and the diagonal for the square root.
Eigen::Vector4d quaternion(const Matrix3& R) {
  const double t = R.trace();
  int k = 0;
  double best = t;
  for (int i = 0; i < 3; ++i)
    if (R(i, i) > best) best = R(i, i), k = i + 1;
  Eigen::Vector4d q;
  if (k == 0) {
    const double w = 0.5 * std::sqrt(std::max(1.0 + t, 0.0)), s = 0.25 / w;
    q << w, (R(2, 1) - R(1, 2)) * s, (R(0, 2) - R(2, 0)) * s, (R(1, 0) - R(0, 1)) * s;
  } else {
    const int i = k - 1, j = (i + 1) % 3, l = (i + 2) % 3;
    const double r = 0.5 * std::sqrt(std::max(1.0 + 2.0 * R(i, i) - t, 0.0)), s = 0.25 / r;
    q(0) = (R(l, j) - R(j, l)) * s;
    q(1 + i) = r;
    q(1 + j) = (R(j, i) + R(i, j)) * s;
    q(1 + l) = (R(l, i) + R(i, l)) * s;
  }
  q /= q.norm();
  return q(0) < 0.0 ? Eigen::Vector4d(-q) : q;
}

// Axis * angle, angle in [0, pi], of the rotation of a unit quaternion with w >= 0.
Vector3 rotationVector(const Eigen::Vector4d& q) {
  const double w = q(0);
  const Vector3 v = q.tail<3>();
  const double s = v.norm();
  if (s < 1e-8) return v * (2.0 / w) * (1.0 - s * s / (3.0 * w * w));  // 2 atan2(s, w) / s, series
  return v * (2.0 * std::atan2(s, w) / s);
}

}  // namespace

Vector6 poseError(const KDL::Frame& current, const KDL::Frame& desired) {
  Matrix3 Rc, Rd;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Rc(r, c) = current.M(r, c), Rd(r, c) = desired.M(r, c);
  Vector6 e;
  const KDL::Vector dp = desired.p - current.p;
  e.head<3>() = Vector3(dp.x(), dp.y(), dp.z());
  e.tail<3>() = rotationVector(quaternion(Rd * Rc.transpose()));
  return e;
}

}  // namespace vereshchagin
