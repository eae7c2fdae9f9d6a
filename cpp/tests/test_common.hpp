// Shared test helpers beside doctest's checks: relative comparisons, message formatting, and dense
// reference quantities (joint-space inertia H, end Jacobian J, coupling matrix K) computed with
// KDL's own solvers. Defined in test_common.cpp, compiled once (their Eigen solvers instantiated in
// every test file cost about 8 s of compile time each).
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
double relErr(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b);

// Largest relErr over corresponding columns (each column its own scale).
double relErrCols(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b);

// |a - b| <= tol * max(1, |b|), and the same entrywise for frames.
inline bool near(double a, double b, double tol = 1e-12) {
  return std::abs(a - b) <= tol * std::max(1.0, std::abs(b));
}

bool nearFrame(const KDL::Frame& a, const KDL::Frame& b, double tol = 1e-12);

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

std::string mat(const Eigen::Ref<const Eigen::MatrixXd>& m);

// Copy of `chain` with every rotor inertia set to zero (same joints, frames and inertias).
KDL::Chain withoutRotorInertia(const KDL::Chain& chain);

// Dense reference model at configuration q: H (joint-space inertia including rotor inertias, added
// here on the diagonal to a rotor-free KDL mass matrix) and J (base-frame Jacobian of the last
// segment's tip, reference point at that tip).
struct DenseModel {
  Eigen::MatrixXd H, J;
};

DenseModel denseModel(const KDL::Chain& chain, const KDL::JntArray& q);

// f_ext in base axes (moment about each tip origin, the hybrid solvers' convention) -> each
// segment's tip axes (same reference point), the convention of KDL's RNE-based solvers.
KDL::Wrenches toTipAxes(const KDL::Chain& chain, const KDL::JntArray& q, const KDL::Wrenches& f_ext);

// Eigenvalues (ascending) of the coupling matrix K = A H^-1 A^T, A = alfa^T J.
Eigen::VectorXd couplingEigenvalues(const DenseModel& d, const Eigen::MatrixXd& alfa);

// Well-conditioned task: no constraints, or K's eigenvalues within a factor 1 / ratio of each other.
// Round-off in nu (and so in qdd) of any solver grows like cond(K) * eps; with cond(K) <= 1e5 the
// 1e-10 comparisons keep a margin of about 10 (observed: errors up to ~1e-10 at cond(K) ~ 8e5).
bool wellConditioned(const Eigen::VectorXd& eig, double ratio = 1e-5);

}  // namespace testutil
