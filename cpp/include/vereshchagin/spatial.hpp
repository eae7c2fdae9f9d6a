/// @file
/// Small spatial-vector algebra on fixed-size Eigen types, used by the solver's sweeps.
///
/// Conventions (same as KDL): a motion vector (twist, spatial acceleration) is [linear; angular],
/// a force vector (wrench) is [force; moment]; both are expressed in some frame and refer to that
/// frame's origin. A `Pose` {R, p} is the pose of a child frame in its parent frame: R has the
/// child's axes as columns (parent coordinates), p is the child's origin in parent coordinates.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

namespace vereshchagin {

using Vector3 = Eigen::Matrix<double, 3, 1>;                ///< a 3-vector
using Vector6 = Eigen::Matrix<double, 6, 1>;                ///< a spatial vector
using Matrix3 = Eigen::Matrix<double, 3, 3>;                ///< a 3x3 matrix
using Matrix6 = Eigen::Matrix<double, 6, 6>;                ///< a spatial (6x6) matrix
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;  ///< one spatial vector per column

/// The pose {R, p} of a child frame in its parent frame (see the top of this file).
struct Pose {
  Matrix3 R = Matrix3::Identity();  ///< the child's axes as columns, parent coordinates
  Vector3 p = Vector3::Zero();      ///< the child's origin, parent coordinates
};

/// The cross-product matrix [a]x: skew(a) b = a x b.
inline Matrix3 skew(const Vector3& a) {
  Matrix3 s;
  s << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return s;
}

/// Motion vector given in the parent frame -> the same motion in the child frame.
/// w' = R^T w, v' = R^T (v - p x w).
template <typename In>
inline Vector6 motionToChild(const Pose& X, const Eigen::MatrixBase<In>& m) {
  Vector6 out;
  const Vector3 w = m.template tail<3>();
  out.template tail<3>().noalias() = X.R.transpose() * w;
  out.template head<3>().noalias() = X.R.transpose() * (m.template head<3>() - X.p.cross(w));
  return out;
}

/// Force vector given in the child frame -> the same force in the parent frame, as its two
/// halves: f = R f', n = R n' + p x (R f').
template <typename In>
inline void forceHalvesToParent(const Pose& X, const Eigen::MatrixBase<In>& f_child, Vector3& f, Vector3& n) {
  f.noalias() = X.R * f_child.template head<3>();
  n.noalias() = X.R * f_child.template tail<3>();
  n += X.p.cross(f);
}

/// Force vector given in the child frame -> the same force in the parent frame (forceHalvesToParent()).
template <typename In>
inline Vector6 forceToParent(const Pose& X, const Eigen::MatrixBase<In>& f_child) {
  Vector3 f, n;
  forceHalvesToParent(X, f_child, f, n);
  Vector6 out;
  out << f, n;
  return out;
}

/// The same transform written in place (f_io holds f' on entry, f on return), and added to an
/// accumulator (out += X^* f'). Both write the two 3-vector halves straight into their
/// destination: a returned 6-vector assembled from halves and read back as 2-wide packets makes
/// the processor wait on store forwarding, which cost half the time of the column loop.
template <typename Io>
inline void forceToParentInPlace(const Pose& X, Eigen::MatrixBase<Io>& f_io) {
  Vector3 f, n;
  forceHalvesToParent(X, f_io, f, n);
  f_io.template head<3>() = f;
  f_io.template tail<3>() = n;
}

/// out += the force f_child (child frame) in the parent frame (see forceToParentInPlace()).
template <typename In, typename Out>
inline void addForceToParent(const Pose& X, const Eigen::MatrixBase<In>& f_child, Eigen::MatrixBase<Out>& out) {
  Vector3 f, n;
  forceHalvesToParent(X, f_child, f, n);
  out.template head<3>() += f;
  out.template tail<3>() += n;
}

/// Spatial cross product for motions: m1 x m2.
inline Vector6 crossMotion(const Vector6& a, const Vector6& b) {
  Vector6 out;
  const Vector3 av = a.head<3>(), aw = a.tail<3>();
  out.head<3>() = aw.cross(b.head<3>()) + av.cross(b.tail<3>());
  out.tail<3>() = aw.cross(b.tail<3>());
  return out;
}

/// Spatial cross product motion x* force.
inline Vector6 crossForce(const Vector6& a, const Vector6& f) {
  Vector6 out;
  const Vector3 av = a.head<3>(), aw = a.tail<3>();
  out.head<3>() = aw.cross(f.head<3>());
  out.tail<3>() = aw.cross(f.tail<3>()) + av.cross(f.head<3>());
  return out;
}

/// Products with P = [p]x written as cross products: column j of P A is p x (column j of A), row
/// i of A P is (row i of A) x p. Each entry is then the same two products and one difference as
/// in the dense 3x3 product with P, whose third term is an exact zero (x + 0 = x), so the results
/// are bit for bit those of the dense product at a third fewer operations.
inline Matrix3 skewTimes(const Vector3& p, const Matrix3& A) {  // [p]x A
  Matrix3 out;
  for (int j = 0; j < 3; ++j) {
    out(0, j) = p.y() * A(2, j) - p.z() * A(1, j);
    out(1, j) = p.z() * A(0, j) - p.x() * A(2, j);
    out(2, j) = p.x() * A(1, j) - p.y() * A(0, j);
  }
  return out;
}

/// A [p]x, bit for bit the dense product (see skewTimes()).
template <typename M>  // any 3x3 expression, e.g. a transpose, read in place
inline Matrix3 timesSkew(const Eigen::MatrixBase<M>& A, const Vector3& p) {  // A [p]x
  Matrix3 out;
  for (int i = 0; i < 3; ++i) {
    out(i, 0) = A(i, 1) * p.z() - A(i, 2) * p.y();
    out(i, 1) = A(i, 2) * p.x() - A(i, 0) * p.z();
    out(i, 2) = A(i, 0) * p.y() - A(i, 1) * p.x();
  }
  return out;
}

/// R B R^T for a symmetric 3x3 B: T = R B, then the lower triangle of T R^T mirrored (the result
/// is symmetric), 45 multiplications instead of 54.
inline Matrix3 rotateSymmetric(const Matrix3& R, const Matrix3& B) {
  const Matrix3 T = R * B;
  Matrix3 out;
  for (int j = 0; j < 3; ++j)
    for (int i = j; i < 3; ++i) out(j, i) = out(i, j) = T.row(i).dot(R.row(j));
  return out;
}

/// A symmetric 6x6 inertia (rigid or articulated) given in the child frame, added to Ip in the
/// parent frame: Ip += X^* I X with X the parent-to-child motion transform. Block form with
/// I = [M H; H^T J] (M, J symmetric): rotate every block by R (M_r = R M R^T, ...), then shift the
/// reference point by p (P = [p]x):
///   M' = M_r,  H' = H_r - M_r P,  J' = J_r + P H_r - H_r^T P - P M_r P = J_r + Z + Z^T
/// with Z = P (H_r - M_r P / 2) (P^T = -P), so two products with P instead of four.
inline void addInertiaToParent(const Pose& X, const Matrix6& Ic, Matrix6& Ip) {
  const Matrix3& R = X.R;
  const Matrix3 M = rotateSymmetric(R, Ic.topLeftCorner<3, 3>());
  const Matrix3 H = R * Ic.topRightCorner<3, 3>() * R.transpose();
  const Matrix3 J = rotateSymmetric(R, Ic.bottomRightCorner<3, 3>());
  const Matrix3 MP = timesSkew(M, X.p);
  const Matrix3 H2 = H - MP;
  const Matrix3 Z = skewTimes(X.p, H - 0.5 * MP);
  Ip.topLeftCorner<3, 3>() += M;
  Ip.topRightCorner<3, 3>() += H2;
  Ip.bottomLeftCorner<3, 3>() += H2.transpose();
  Ip.bottomRightCorner<3, 3>() += J + Z + Z.transpose();
}

/// Rigid-body inertia about a frame origin, from mass m, centre of mass c and rotational inertia
/// Io about the frame origin (all in that frame): [m 1, -m [c]x; m [c]x, Io].
inline Matrix6 rigidInertia(double m, const Vector3& c, const Matrix3& Io) {
  Matrix6 I;
  const Matrix3 mc = m * skew(c);
  I.topLeftCorner<3, 3>() = m * Matrix3::Identity();
  I.topRightCorner<3, 3>() = -mc;
  I.bottomLeftCorner<3, 3>() = mc;
  I.bottomRightCorner<3, 3>() = Io;
  return I;
}

}  // namespace vereshchagin
