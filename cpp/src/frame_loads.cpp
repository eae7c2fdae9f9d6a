// Loads about points of segment frames (input.hpp: ConstraintBlock::point, FrameWrench::point),
// moved to the segment tips inside a solve with the rotations its outward sweep just computed:
// a wrench [f; n_point] about a point p (tip axes) is [f; n_point + (R_base p) x f] about the tip
// origin (base axes). No forward kinematics of its own.
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

// After outwardSweep(): the blocks' columns with a point get their moments moved to the tip; the
// frame wrenches are added to the solve's f_ext (for the pass-through and the checks) and to the
// bias forces the sweep formed from the input's f_ext alone.
void HdCore::applyFrameLoads() {
  const SolveInput& in = *loads->input;
  if (loads->points) {
    Matrix6X& alfa = *loads->alfa;
    int col = 0;
    for (const ConstraintBlock& b : in.constraints) {
      if (!b.point.isZero()) {
        const Vector3 r = ws.seg[b.segment].R_base * b.point;
        for (int c = 0; c < b.columns; ++c) {
          const Vector3 f = alfa.col(col + c).head<3>();
          alfa.col(col + c).tail<3>() += r.cross(f);  // m_tip = m_point + (p_point - p_tip) x f
        }
      }
      col += b.columns;
    }
  }
  if (loads->wrenches) {
    Matrix6X& f_ext = *loads->f_ext;
    for (const FrameWrench& w : in.wrenches) {
      SegmentState& s = ws.seg[w.segment];
      const Vector3 r = s.R_base * w.point;
      const Vector3 f = w.wrench.head<3>();
      const Vector3 n = w.wrench.tail<3>() + r.cross(f);
      f_ext.col(w.segment).head<3>() += f;
      f_ext.col(w.segment).tail<3>() += n;
      // As outwardSweep() does with f_ext: base axes, moment about the tip origin -> tip axes.
      s.pA.head<3>().noalias() -= s.R_base.transpose() * f;
      s.pA.tail<3>().noalias() -= s.R_base.transpose() * n;
    }
  }
}

}  // namespace detail
}  // namespace vereshchagin
