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
// written into buf (size bytes). Tolerances are relative to the body's inertia scale
//     s = max(max |I_com|, round_off, mass x 1 m^2),   t = 1e-12 s,
// round_off the size of the terms I_com was computed from (e.g. max(max |I_origin|, m |c|^2) for
// I_com = I_origin + m [c]x [c]x, whose round-off is a few ulps of them; 0 when I_com is given),
// and mass x 1 m^2 the inertia the body's mass has at the scale of a robot (1 m), so that a
// tensor made of round-off (iCub's l_ankle_2 in example-robot-data: moments -1.4e-20, 0, 1.4e-20
// for 0.27 kg) is not refused for a "violation" of 1e-20 kg m^2. Both checks: finite, mass >= 0,
// I_com symmetric to t. Physical also: every principal moment >= -t, and I1 + I2 >= I3 - max(1e-6
// I3, t) for the sorted moments I1 <= I2 <= I3 (1e-6: rounded model files). The messages of the
// physical check name the joint_space option.
const char* inertiaProblem(double mass, const Eigen::Matrix3d& I_com, InertiaCheck check, char* buf, std::size_t size,
                           double round_off = 0.0);

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
