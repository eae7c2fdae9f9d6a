// Helpers shared by the dynamics companions of Chain (dynamics_bindings.cpp) and Tree
// (tree_dynamics.cpp): the default gravity and checked conversions of their results.
#pragma once

#include <string>
#include <vector>

#include <kdl/jntarray.hpp>

#include "common.hpp"

namespace vsbind {

// Physical gravity on Earth in a base frame whose z axis points up, m/s^2.
inline const std::vector<double> kEarthGravity{0.0, 0.0, -9.81};

// Results of finite inputs can still overflow (e.g. |qd| = 1e160); never hand back Inf or NaN.
inline void requireFiniteResult(const double* p, size_t n, const char* what) {
  for (size_t k = 0; k < n; ++k)
    if (!std::isfinite(p[k])) raise(std::string(what) + ": the result overflows the double range");
}

// Joint torques (n,) as a new numpy array, checked finite.
inline py::array_t<double> jointTorques(const KDL::JntArray& tau, const char* what) {
  requireFiniteResult(tau.data.data(), tau.rows(), what);
  return copyVector(tau.data.data(), tau.rows());
}

// A square joint-space matrix (n, n) as a new numpy array, checked finite.
inline py::array_t<double> jointMatrix(const Eigen::MatrixXd& H, const char* what) {
  requireFiniteResult(H.data(), static_cast<size_t>(H.size()), what);
  const auto n = static_cast<py::ssize_t>(H.rows());
  py::array_t<double> out({n, n});
  auto o = out.mutable_unchecked<2>();
  for (py::ssize_t r = 0; r < n; ++r)
    for (py::ssize_t k = 0; k < n; ++k) o(r, k) = H(r, k);
  return out;
}

// Frames as a new (n, 4, 4) array of homogeneous transforms.
inline py::array_t<double> homogeneousStack(const std::vector<KDL::Frame>& frames) {
  py::array_t<double> out(
      {static_cast<py::ssize_t>(frames.size()), static_cast<py::ssize_t>(4), static_cast<py::ssize_t>(4)});
  for (size_t i = 0; i < frames.size(); ++i) writeHomogeneous(frames[i], out.mutable_data() + 16 * i);
  return out;
}

}  // namespace vsbind
