// Model and result validity checks private to the library: what ChainHdSolver checks about a
// segment's frames before it builds its model (inertial parameters are checked in buildModel()),
// and the bound on reported results.
#pragma once

#include <Eigen/Core>
#include <kdl/segment.hpp>

namespace vereshchagin {
namespace detail {

// nullptr if the segment's geometry is usable, else a short description of the problem:
//  * the tip frame (KDL Segment::getFrameToTip(), the tip in the joint-rotated frame at q = 0)
//    must be finite with a proper rotation: |R^T R - I|_max <= 1e-6 and det R > 0;
//  * the joint's origin and axis (RotAxis / TransAxis joints) must be finite.
const char* segmentGeometryProblem(const KDL::Segment& segment);

// Largest magnitude of a reported result: beyond it (or Inf / NaN) a solve fails with
// E_NONFINITE_RESULT, so that products of two results (energies, powers, the Gauss value) stay
// representable (sqrt of the largest double is 1.3e154).
constexpr double kMaxResult = 1e150;

template <typename Derived>
bool bounded(const Eigen::DenseBase<Derived>& v) {
  return (v.derived().array().abs() <= kMaxResult).all();  // false for NaN
}

}  // namespace detail
}  // namespace vereshchagin
