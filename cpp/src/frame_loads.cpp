// Loads about points of segment frames (input.hpp: ConstraintBlock::point, FrameWrench::point),
// moved to the segment tips inside a solve with the rotations its outward sweep just computed:
// a wrench [f; n_point] about a point p (tip axes) is [f; n_point + (R_base p) x f] about the tip
// origin (base axes). No forward kinematics of its own.
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

// Blocks with a classical set-point (ConstraintBlock::classical): beta = alfa^T [a - w x v +
// root_acc_lin; alpha] with the frame's twist [v; w] (base axes, at its point) from the sweep; the
// root acceleration is -gravity (a base at rest). Before the moments of alfa move to the tip.
void HdCore::classicalSetPoints() {
  const SolveInput& in = *loads->input;
  Eigen::VectorXd& beta = *loads->beta;
  const Matrix6X& alfa = *loads->alfa;
  int col = 0;
  for (const ConstraintBlock& b : in.constraints) {
    if (b.classical) {
      const SegmentState& s = ws.seg[b.segment];
      const Vector3 w = s.R_base * s.v.tail<3>();
      const Vector3 v = s.R_base * s.v.head<3>() + w.cross(s.R_base * b.point);
      Vector6 spatial;
      spatial.head<3>() = b.classical_acceleration.head<3>() - w.cross(v) + root_acc.head<3>();
      spatial.tail<3>() = b.classical_acceleration.tail<3>() + root_acc.tail<3>();
      for (int c = 0; c < b.columns; ++c) beta(col + c) = alfa.col(col + c).dot(spatial);
    }
    col += b.columns;
  }
}

// After outwardSweep(): the blocks' columns with a point get their moments moved to the tip; the
// frame wrenches are added to the solve's f_ext (for the pass-through and the checks) and to the
// bias forces the sweep formed from the input's f_ext alone.
void HdCore::applyFrameLoads() {
  const SolveInput& in = *loads->input;
  if (loads->classical) classicalSetPoints();
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
