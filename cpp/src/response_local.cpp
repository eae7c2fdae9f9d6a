// HdCore::localResponse(): response columns of a few joint torques on a fixed-base chain on the
// fast path (at most kLocalColumns columns), both passes in each segment's own tip frame.
//
// The general passes (response_columns.cpp) first put every segment's joint axis S_i and IA_i S_i
// into base axes (baseAxes(), three rotations per segment), after which a column costs a cross
// product per segment. For the one to four columns the friction stage asks over a time step (the
// joints whose slide guess was refuted) that preparation costs as much as the passes themselves,
// so here each column's 6-vectors are carried between frames instead, as the solve's sweeps
// carry theirs: inward, the apparent force change f, n (about the tip origin, tip axes) goes to
// the parent as (R f, R n + p x R f); outward, the acceleration change a, w (linear at the tip
// origin, angular) comes from the parent as (R^T (a + w x p), R^T w), with X_i = (R, p) the pose of
// frame i in its parent's. The joint step is the general passes' (hd_solver.hpp's response math):
// a unit torque at joint j enters at j's segment; per segment with a joint, s_d = S^T (f; n),
// the free acceleration change (delta_ij - s_d) / D, the force change plus IA S times it, the
// constraints' energy change e_i^T times it; d nu = K^-1 d U; then outward
// d qdd_i = (delta_ij - s_d - (IA S)^T (a; w) - e_i d nu) / D and (a; w) += S d qdd_i.
// IA S enters both passes through its parent-frame image U = (R (IA S)_f, R (IA S)_n + p x
// R (IA S)_f), so that the rotation of the carried vectors runs beside the joint's arithmetic
// rather than before it: inward (f, n)_parent = (R f, R n + p x R f) + U acc, outward
// (IA S)^T (a; w)_child = U^T (a; w)_parent.
#include <algorithm>

#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

void HdCore::localResponse(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                           Eigen::Ref<Eigen::MatrixXd>* dnu_out) {
  static_assert(kLocalColumns == 4, "one instance per column count");
  switch (joints.size()) {
    case 1:
      return localResponseT<1>(joints, dqdd, dnu_out);
    case 2:
      return localResponseT<2>(joints, dqdd, dnu_out);
    case 3:
      return localResponseT<3>(joints, dqdd, dnu_out);
    default:
      return localResponseT<4>(joints, dqdd, dnu_out);
  }
}

// K columns (a compile-time count: the columns' 3-vectors stay in registers across segments).
template <int K>
void HdCore::localResponseT(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                            Eigen::Ref<Eigen::MatrixXd>* dnu_out) {
  ResponseWorkspace& r = ws.response;
  const int m = res.m;
  constexpr int k = K;
  const int ns = static_cast<int>(model.ns);
  auto DU = r.energy.topLeftCorner(m, k);
  auto SDP = r.sdp.leftCols(k);
  DU.setZero();
  // Per segment with a joint, IA S in the parent's axes about the parent's tip origin:
  // U_a = R (IA S)_f, U_w = R (IA S)_n + p x U_a (into axis_inertia, the general passes' scratch).
  // Both passes then rotate the carried vectors beside the joint's arithmetic instead of before it.
  for (int i = 0; i < ns; ++i) {
    if (model.seg[i].joint < 0) continue;
    const SegmentState& s = ws.seg[i];
    auto U = r.axis_inertia.col(i);
    U.head<3>().noalias() = s.X.R * s.u.head<3>();
    U.tail<3>().noalias() = s.X.R * s.u.tail<3>();
    U.tail<3>() += s.X.p.cross(Vector3(U.head<3>()));
  }
  // The carried vectors as scalars: Eigen 3-vectors written lane by lane and read back as pairs
  // stall on store forwarding, which dominated these short dependent chains.
  double f[K][3], n[K][3];
  int first[K], joint[K];  // the column's joint and source segment (alive from there to the base)
  int top = 0;
  for (int c = 0; c < k; ++c) {
    joint[c] = joints(c);
    first[c] = model.joint_segment[joint[c]];
    top = std::max(top, first[c]);
    for (int t = 0; t < 3; ++t) f[c][t] = n[c][t] = 0.0;
  }
  SDP.bottomRows(ns - top - 1).setZero();
  for (int i = top; i >= 0; --i) {
    const SegmentModel& sm = model.seg[i];
    const SegmentState& s = ws.seg[i];
    const double* U = r.axis_inertia.col(i).data();
    const Matrix3& R = s.X.R;
    const Vector3& p = s.X.p;
    for (int c = 0; c < k; ++c) {
      SDP(i, c) = 0.0;
      if (first[c] < i) continue;  // not alive yet
      // (f, n) to the parent frame: (R f, R n + p x R f), plus U acc for the joint's share.
      double fr[3], nr[3];
      for (int t = 0; t < 3; ++t) fr[t] = R(t, 0) * f[c][0] + R(t, 1) * f[c][1] + R(t, 2) * f[c][2];
      for (int t = 0; t < 3; ++t) nr[t] = R(t, 0) * n[c][0] + R(t, 1) * n[c][1] + R(t, 2) * n[c][2];
      nr[0] += p(1) * fr[2] - p(2) * fr[1];
      nr[1] += p(2) * fr[0] - p(0) * fr[2];
      nr[2] += p(0) * fr[1] - p(1) * fr[0];
      double acc = 0.0;
      if (sm.joint >= 0) {
        const double sd = sm.S(0) * f[c][0] + sm.S(1) * f[c][1] + sm.S(2) * f[c][2] + sm.S(3) * n[c][0] +
                          sm.S(4) * n[c][1] + sm.S(5) * n[c][2];
        SDP(i, c) = sd;
        acc = ((joint[c] == sm.joint ? 1.0 : 0.0) - sd) * s.Dinv;
        for (int t = 0; t < m; ++t) DU(t, c) += s.e(t) * acc;
      }
      for (int t = 0; t < 3; ++t) f[c][t] = fr[t] + U[t] * acc, n[c][t] = nr[t] + U[3 + t] * acc;
    }
  }
  responseCoupling(0, k, dnu_out);
  const auto DNU = r.dnu.topLeftCorner(m, k);
  double a[K][3], w[K][3];  // in the parent's axes, linear part at the parent's tip origin
  for (int c = 0; c < k; ++c)
    for (int t = 0; t < 3; ++t) a[c][t] = w[c][t] = 0.0;  // the base is fixed
  for (int i = 0; i < ns; ++i) {
    const SegmentModel& sm = model.seg[i];
    const SegmentState& s = ws.seg[i];
    const double* U = r.axis_inertia.col(i).data();
    const Matrix3& R = s.X.R;
    const Vector3& p = s.X.p;
    for (int c = 0; c < k; ++c) {
      // (IA S)^T of the acceleration in this frame = U_a . a + U_w . w in the parent's.
      double ua = 0.0;
      if (sm.joint >= 0)
        ua = U[0] * a[c][0] + U[1] * a[c][1] + U[2] * a[c][2] + U[3] * w[c][0] + U[4] * w[c][1] + U[5] * w[c][2];
      // To this frame: R^T (a + w x p), R^T w.
      const double b[3] = {a[c][0] + w[c][1] * p(2) - w[c][2] * p(1), a[c][1] + w[c][2] * p(0) - w[c][0] * p(2),
                           a[c][2] + w[c][0] * p(1) - w[c][1] * p(0)};
      double wt[3];
      for (int t = 0; t < 3; ++t) wt[t] = R(0, t) * w[c][0] + R(1, t) * w[c][1] + R(2, t) * w[c][2];
      for (int t = 0; t < 3; ++t) a[c][t] = R(0, t) * b[0] + R(1, t) * b[1] + R(2, t) * b[2];
      for (int t = 0; t < 3; ++t) w[c][t] = wt[t];
      if (sm.joint < 0) continue;
      double v = (joint[c] == sm.joint ? 1.0 : 0.0) - SDP(i, c) - ua;
      for (int t = 0; t < m; ++t) v -= s.e(t) * DNU(t, c);
      v *= s.Dinv;
      dqdd(sm.joint, c) = v;
      for (int t = 0; t < 3; ++t) a[c][t] += sm.S(t) * v, w[c][t] += sm.S(3 + t) * v;
    }
  }
}

}  // namespace detail
}  // namespace vereshchagin
