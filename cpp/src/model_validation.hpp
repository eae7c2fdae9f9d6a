// Model and result validity checks private to the library: what ChainHdSolver checks about a
// segment's frames and inertial parameters before it builds its model,
// and the bound on reported results.
#pragma once

#include <cstddef>

#include <Eigen/Core>
#include <kdl/segment.hpp>

#include "vereshchagin/inertia_check.hpp"

namespace vereshchagin {
namespace detail {

// nullptr if the segment's geometry is usable, else a short description of the problem:
//  * the tip frame (KDL Segment::getFrameToTip(), the tip in the joint-rotated frame at q = 0)
//    must be finite with a proper rotation: |R^T R - I|_max <= 1e-6 and det R > 0;
//  * the joint's origin and axis (RotAxis / TransAxis joints) must be finite.
const char* segmentGeometryProblem(const KDL::Segment& segment);

// nullptr if a body of mass `mass` (kg) with rotational inertia I_com (kg m^2) about its centre
// of mass, in any axes, passes `check` (see inertia_check.hpp); else a description of the problem
// written into buf (size bytes). Both checks: finite, mass >= 0, I_com symmetric (to 1e-12 of
// max(1, max |I_com|)). Physical also: every principal moment >= -1e-12 max(1, max |I_com|), and
// I1 + I2 >= I3 - 1e-6 I3 for the sorted moments I1 <= I2 <= I3. The messages of the physical
// check name the joint_space option.
const char* inertiaProblem(double mass, const Eigen::Matrix3d& I_com, InertiaCheck check, char* buf, std::size_t size);

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
