// Helpers shared by the dynamics companions of Chain (dynamics_bindings.cpp) and Tree
// (tree_dynamics.cpp): the default gravity and checked conversions of their results.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "addressing.hpp"
#include "common.hpp"

namespace vsbind {

// Physical gravity on Earth in a base frame whose z axis points up, m/s^2.
inline const std::vector<double> kEarthGravity{0.0, 0.0, -9.81};

// Results of finite inputs can still overflow (e.g. |qd| = 1e160); never hand back Inf or NaN.
inline void requireFiniteResult(const double* p, size_t n, const char* what) {
  for (size_t k = 0; k < n; ++k)
    if (!std::isfinite(p[k])) raise(std::string(what) + ": the result overflows the double range");
}

// f_ext of the dynamics companions as n_segments rows [force, moment] (base axes, moment about
// each segment's tip origin), empty for None. The array form (n_segments, 6) is those rows; the
// dict form {segment or link: wrench (6,)} gives the moment about the named frame's origin, moved
// to its segment's tip: n_tip = n + (R_tip(q) p_link) x f, with tip_rotation(segment) = R_tip(q),
// the tip's orientation in the base (as Solver.solve reads f_ext).
template <typename TipRotation>
std::vector<Eigen::Matrix<double, 6, 1>> externalWrenchRows(const py::object& f_ext, const Addressable& model,
                                                            const TipRotation& tip_rotation) {
  const int ns = model.segmentCount();
  std::vector<Eigen::Matrix<double, 6, 1>> rows;
  if (f_ext.is_none()) return rows;
  rows.assign(static_cast<std::size_t>(ns), Eigen::Matrix<double, 6, 1>::Zero());
  if (!py::isinstance<py::dict>(f_ext)) {
    const Array f = toArray(f_ext, "f_ext");
    if (f.ndim() != 2 || f.shape(0) != static_cast<py::ssize_t>(ns) || f.shape(1) != 6)
      raise("f_ext must have shape (" + std::to_string(ns) + ", 6) or be a dict {segment: wrench (6,)}, got " +
            shapeStr(f));
    requireFinite(f, "f_ext");
    for (int i = 0; i < ns; ++i)
      for (int k = 0; k < 6; ++k) rows[static_cast<std::size_t>(i)](k) = f.at(i, k);
    return rows;
  }
  for (const auto& item : f_ext.cast<py::dict>()) {
    const std::string label = "f_ext[" + py::repr(item.first).cast<std::string>() + "]";
    const FrameTarget t = model.resolveMoving(item.first.ptr(), label);
    const Array w = vectorArg(item.second, label.c_str(), 6);
    KDL::Vector moment(w.at(3), w.at(4), w.at(5));
    const KDL::Vector force(w.at(0), w.at(1), w.at(2));
    if (t.merged) moment += (tip_rotation(t.segment) * t.link_in_tip.p) * force;
    Eigen::Matrix<double, 6, 1>& row = rows[static_cast<std::size_t>(t.segment)];
    for (int k = 0; k < 3; ++k) row(k) += force(k), row(3 + k) += moment(k);
  }
  return rows;
}

}  // namespace vsbind
