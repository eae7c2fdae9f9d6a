// Shared test helpers beside doctest's checks: relative comparisons, message formatting, and dense
// reference quantities (joint-space inertia H, end Jacobian J, coupling matrix K) computed with
// KDL's own solvers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver.hpp>  // KDL::Wrenches
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>

namespace testutil {

// max |a - b| / max(1, max |b|); +inf if the shapes differ or anything is non-finite.
inline double relErr(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return INFINITY;
  if (a.size() == 0) return 0.0;
  if (!a.allFinite() || !b.allFinite()) return INFINITY;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

// Largest relErr over corresponding columns (each column its own scale).
inline double relErrCols(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return INFINITY;
  double e = 0.0;
  for (Eigen::Index c = 0; c < a.cols(); ++c) e = std::max(e, relErr(a.col(c), b.col(c)));
  return e;
}

// |a - b| <= tol * max(1, |b|), and the same entrywise for frames.
inline bool near(double a, double b, double tol = 1e-12) {
  return std::abs(a - b) <= tol * std::max(1.0, std::abs(b));
}

inline bool nearFrame(const KDL::Frame& a, const KDL::Frame& b, double tol = 1e-12) {
  for (int r = 0; r < 3; ++r) {
    if (!near(a.p(r), b.p(r), tol)) return false;
    for (int c = 0; c < 3; ++c)
      if (!near(a.M(r, c), b.M(r, c), tol)) return false;
  }
  return true;
}

// printf-style formatting, for MESSAGE() summaries.
template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

template <typename T>
std::string str(const T& x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

inline std::string mat(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  std::ostringstream os;
  os.precision(10);
  os << m.transpose();
  return os.str();
}

// Copy of `chain` with every rotor inertia set to zero (same joints, frames and inertias).
inline KDL::Chain withoutRotorInertia(const KDL::Chain& chain) {
  KDL::Chain out;
  for (const KDL::Segment& s : chain.segments) {
    const KDL::Joint& j = s.getJoint();
    KDL::Joint j0;
    switch (j.getType()) {
      case KDL::Joint::RotAxis:
      case KDL::Joint::TransAxis:
        j0 = KDL::Joint(j.getName(), j.JointOrigin(), j.JointAxis(), j.getType(), 1.0, 0.0, 0.0);
        break;
      default:
        j0 = KDL::Joint(j.getName(), j.getType(), 1.0, 0.0, 0.0);
        break;
    }
    out.addSegment(KDL::Segment(s.getName(), j0, s.getFrameToTip(), s.getInertia()));
  }
  return out;
}

// Dense reference model at configuration q: H (joint-space inertia including rotor inertias, added
// here on the diagonal to a rotor-free KDL mass matrix) and J (base-frame Jacobian of the last
// segment's tip, reference point at that tip).
struct DenseModel {
  Eigen::MatrixXd H, J;
};

inline DenseModel denseModel(const KDL::Chain& chain, const KDL::JntArray& q) {
  const unsigned int n = chain.getNrOfJoints();
  DenseModel d;
  KDL::Chain bare = withoutRotorInertia(chain);
  KDL::ChainDynParam dyn(bare, KDL::Vector::Zero());
  KDL::JntSpaceInertiaMatrix H(n);
  dyn.JntToMass(q, H);
  d.H = H.data;
  unsigned int j = 0;
  for (const KDL::Segment& s : chain.segments) {
    if (s.getJoint().getType() == KDL::Joint::Fixed) continue;
    d.H(j, j) += s.getJoint().getInertia();
    ++j;
  }
  KDL::ChainJntToJacSolver jac(chain);
  KDL::Jacobian J(n);
  jac.JntToJac(q, J);
  d.J = J.data;
  return d;
}

// f_ext in base axes (moment about each tip origin, the hybrid solvers' convention) -> each
// segment's tip axes (same reference point), the convention of KDL's RNE-based solvers.
inline KDL::Wrenches toTipAxes(const KDL::Chain& chain, const KDL::JntArray& q, const KDL::Wrenches& f_ext) {
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::Wrenches out(f_ext.size());
  for (std::size_t i = 0; i < f_ext.size(); ++i) {
    KDL::Frame F;
    fk.JntToCart(q, F, static_cast<int>(i) + 1);
    out[i] = F.M.Inverse() * f_ext[i];
  }
  return out;
}

// Eigenvalues (ascending) of the coupling matrix K = A H^-1 A^T, A = alfa^T J.
inline Eigen::VectorXd couplingEigenvalues(const DenseModel& d, const Eigen::MatrixXd& alfa) {
  if (alfa.cols() == 0) return Eigen::VectorXd();
  const Eigen::MatrixXd A = alfa.transpose() * d.J;
  const Eigen::MatrixXd K = A * d.H.lu().solve(A.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (K + K.transpose()), Eigen::EigenvaluesOnly);
  return es.eigenvalues();
}

// Well-conditioned task: no constraints, or K's eigenvalues within a factor 1 / ratio of each other.
// Round-off in nu (and so in qdd) of any solver grows like cond(K) * eps; with cond(K) <= 1e5 the
// 1e-10 comparisons keep a margin of about 10 (observed: errors up to ~1e-10 at cond(K) ~ 8e5).
inline bool wellConditioned(const Eigen::VectorXd& eig, double ratio = 1e-5) {
  if (eig.size() == 0) return true;
  return eig(0) > ratio * eig(eig.size() - 1) && eig(eig.size() - 1) > 0.0;
}

}  // namespace testutil
