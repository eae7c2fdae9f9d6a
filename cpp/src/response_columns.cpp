// HdCore::responseColumns() and wrenchResponse(): the affine response of the last solve to unit
// joint torques or to wrenches on segments (the columns of contact forces), on chains and trees,
// reusing the solve's articulated inertias and coupling factorisation. Conventions in
// hd_solver.hpp.
//
// A unit torque at joint j changes only the force part of the sweeps: in the inward pass its
// apparent force change is non-zero only on the path from j's segment to the base, so each
// requested column keeps one 6-vector (about the tip of the segment that last passed it), and a
// segment sees the column only if j lies in its subtree. The constraint magnitudes change by
// d nu = K^+ dU; the outward pass then gives d qdd everywhere (accelerations spread to every
// branch through the common ancestors), with the values at branching segments kept for their
// later children. Everything runs in base axes about each segment's tip origin: between segments
// only the reference point moves (a cross product), never the axes. (About one fixed point, the
// base origin, even that would go, but moments grow with the robot's distance from it and square
// in the products: precision is lost and a 1e150 m chain overflows.)
#include <algorithm>

#include "dense_small.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

// The sources of response columns: column c is the response to a unit torque at joint joints(c)
// (JointTorqueSources) or to the wrench wrenches.col(c) on segment segments(c)
// (WrenchSources: [force; moment] ON the body, base axes, moment about that segment's tip origin).
// A column is alive from its source's segment towards the base in the inward pass, where it starts
// with the change of that segment's bias force: zero for a torque, minus the wrench for a wrench.
struct JointTorqueSources {
  const Eigen::Ref<const Eigen::VectorXi>& joints;
  const HdModel& model;
  int segment(long c) const { return model.joint_segment[joints(c)]; }
  double torque(long c, int joint) const { return joints(c) == joint ? 1.0 : 0.0; }
  void start(long, Vector3& f, Vector3& n) const { f.setZero(), n.setZero(); }
  bool identity(long c0, long kc) const {  // every joint in order: the response is symmetric
    bool all = model.is_chain && c0 == 0 && kc == static_cast<long>(model.nj);
    for (long c = 0; c < kc && all; ++c) all = joints(c) == c;
    return all;
  }
};

struct WrenchSources {
  const Eigen::Ref<const Eigen::VectorXi>& segments;
  const Eigen::Ref<const Matrix6X>& wrenches;
  int segment(long c) const { return segments(c); }
  double torque(long, int) const { return 0.0; }
  void start(long c, Vector3& f, Vector3& n) const {
    f = -wrenches.col(c).head<3>();
    n = -wrenches.col(c).tail<3>();
  }
  bool identity(long, long) const { return false; }
};

int HdCore::checkResponseArgs(const Eigen::Ref<const Eigen::VectorXi>& joints, const Eigen::Ref<Eigen::MatrixXd>& dqdd,
                              const Eigen::Ref<Eigen::MatrixXd>& dtau_cmd, bool want_tau) {
  if (!res.solved) return fail(HdSolver::E_NO_SOLUTION, "responseColumns() needs a successful solve() first");
  const long k = joints.size(), nj = model.nj, nv = nj + model.nbv;  // rows: nv (a floating base's first)
  constexpr int E_SIZE = KDL::SolverI::E_SIZE_MISMATCH;
  if (dqdd.rows() != nv || dqdd.cols() != k)
    return fail(E_SIZE, "dqdd is %ldx%ld, expected %ldx%ld", (long)dqdd.rows(), (long)dqdd.cols(), nv, k);
  if (want_tau && (dtau_cmd.rows() != nv || dtau_cmd.cols() != k))
    return fail(E_SIZE, "dtau_cmd is %ldx%ld, expected %ldx%ld", (long)dtau_cmd.rows(), (long)dtau_cmd.cols(), nv, k);
  for (long c = 0; c < k; ++c) {
    if (joints(c) < 0 || joints(c) >= static_cast<int>(nj))
      return fail(KDL::SolverI::E_OUT_OF_RANGE, "joint index %d out of range [0, %ld)", joints(c), nj);
  }
  return 0;
}

int HdCore::responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                            Eigen::Ref<Eigen::MatrixXd> dtau_cmd, Eigen::Ref<Eigen::MatrixXd>* dnu_out) {
  const bool want_tau = !(dnu_out && dtau_cmd.size() == 0);  // empty beside dnu: not wanted
  int rc = checkResponseArgs(joints, dqdd, dtau_cmd, want_tau);
  if (rc != 0) return rc;
  const int m = res.m;
  if (want_tau) commandPerNu();
  const long k = joints.size(), width = ws.response.width;
  // A few columns on a fixed-base chain: in the segments' own frames (response_local.cpp).
  // (Not every joint in order: that request's response is the symmetric one, mirrored exactly.)
  const JointTorqueSources src{joints, model};
  const bool local = model.is_chain && !model.floating && !res.general && k <= std::min<long>(width, kLocalColumns) &&
                     !src.identity(0, k);
  if (!local) baseAxes();
  // All columns, in chunks of at most the workspace width (n_joints, at most kResponseWidth).
  for (long c0 = 0; c0 < k; c0 += width) {
    const long kc = std::min<long>(width, k - c0);
    if (local) {  // (then one chunk)
      localResponse(joints, dqdd, dnu_out);
    } else {
      responseInward(src, c0, kc);
      responseCoupling(c0, kc, dnu_out);
      responseOutward(src, c0, kc, dqdd);
    }
    // tau_cmd is linear in nu: d tau_cmd = (d tau_cmd / d nu) d nu, the m columns built once.
    if (!want_tau) continue;
    if (m > 0) {
      dtau_cmd.middleCols(c0, kc).noalias() =
          ws.response.cmd_per_nu.leftCols(m).lazyProduct(ws.response.dnu.topLeftCorner(m, kc));
    } else {
      dtau_cmd.middleCols(c0, kc).setZero();
    }
  }
  return 0;
}

int HdCore::wrenchResponse(const Eigen::Ref<const Eigen::VectorXi>& segments,
                           const Eigen::Ref<const Matrix6X>& wrenches, Eigen::Ref<Eigen::MatrixXd> dqdd,
                           Eigen::Ref<Eigen::MatrixXd>* dnu_out) {
  if (!res.solved) return fail(HdSolver::E_NO_SOLUTION, "wrenchResponse() needs a successful solve() first");
  const long k = segments.size();
  if (wrenches.cols() != k || dqdd.rows() != static_cast<long>(model.nj + model.nbv) || dqdd.cols() != k)
    return fail(KDL::SolverI::E_SIZE_MISMATCH, "wrenchResponse(): %ld segments, %ld wrenches, dqdd %ldx%ld", k,
                (long)wrenches.cols(), (long)dqdd.rows(), (long)dqdd.cols());
  for (long c = 0; c < k; ++c)
    if (segments(c) < 0 || segments(c) >= static_cast<int>(model.ns))
      return fail(KDL::SolverI::E_OUT_OF_RANGE, "segment index %d out of range [0, %u)", segments(c), model.ns);
  baseAxes();
  const long width = ws.response.width;
  for (long c0 = 0; c0 < k; c0 += width) {
    const long kc = std::min<long>(width, k - c0);
    const WrenchSources src{segments, wrenches};
    responseInward(src, c0, kc);
    responseCoupling(c0, kc, dnu_out);
    responseOutward(src, c0, kc, dqdd);
  }
  return 0;
}

// d tau_cmd / d nu, one column per constraint (path's order).
void HdCore::commandPerNu() {
  const int m = res.m;
  ResponseWorkspace& r = ws.response;
  if (res.general) {
    auto unit = ws.general.rhs.head(m);
    for (int c = 0; c < m; ++c) {
      unit.setZero();
      unit(c) = 1.0;
      commandFromNuGeneral(unit, r.cmd_per_nu.col(c));
    }
    return;
  }
  if (m == 0) return;
  // The m wrenches -A_N carried rigidly to each joint together: row j of -J^T alfa (a chain).
  auto F = r.force.leftCols(m);
  F = -ws.seg[model.ns - 1].A.leftCols(m);
  for (int i = static_cast<int>(model.ns) - 1; i >= 0; --i) {
    const SegmentState& s = ws.seg[i];
    const int joint = model.seg[i].joint;
    if (joint >= 0) r.cmd_per_nu.row(joint).head(m).noalias() = model.seg[i].S.transpose().lazyProduct(F);
    if (i > 0) {  // f = R f', n = R n' + p x f
      r.tmp3.leftCols(m).noalias() = s.X.R.lazyProduct(F.topRows<3>());
      F.topRows<3>() = r.tmp3.leftCols(m);
      r.tmp3.leftCols(m).noalias() = s.X.R.lazyProduct(F.bottomRows<3>());
      F.bottomRows<3>() = r.tmp3.leftCols(m);
      F.bottomRows<3>().noalias() += skew(s.X.p).lazyProduct(F.topRows<3>());
    }
  }
}

// Joint axes S and u = IA S of every segment in base axes (about the segment's own tip origin),
// each tip origin's offset from its parent's in base axes, and the fast path's S^T A rows in the
// general path's eg (so that both paths share the sweeps).
void HdCore::baseAxes() {
  ResponseWorkspace& r = ws.response;
  const int m = res.m;
  if (!res.general && m > 0)
    for (unsigned int i = 0; i < model.ns; ++i) ws.general.eg.col(i).head(m) = ws.seg[i].e.leftCols(m).transpose();
  for (unsigned int i = 0; i < model.ns; ++i) {
    const SegmentState& s = ws.seg[i];
    const int p = model.parent(i);
    if (p >= 0) {
      r.offset.col(i).noalias() = ws.seg[p].R_base * s.X.p;
    } else if (model.floating) {  // world axes
      r.offset.col(i).noalias() = ws.base.X.R * s.X.p;
    } else {
      r.offset.col(i) = s.X.p;
    }
    if (model.seg[i].joint < 0) continue;
    auto S0 = r.axis.col(i);
    auto u0 = r.axis_inertia.col(i);
    S0.head<3>().noalias() = s.R_base * model.seg[i].S.head<3>();
    S0.tail<3>().noalias() = s.R_base * model.seg[i].S.tail<3>();
    u0.head<3>().noalias() = s.R_base * s.u.head<3>();
    u0.tail<3>().noalias() = s.R_base * s.u.tail<3>();
  }
}

// Inward pass of columns [c0, c0 + kc): per column the apparent bias-force change passed towards
// the base (force), its joint-axis share per segment (sdp) and the energy change along the
// constraint columns (energy).
template <typename Sources>
void HdCore::responseInward(const Sources& src, long c0, long kc) {
  ResponseWorkspace& r = ws.response;
  const int m = res.m;
  auto DP = r.force.leftCols(kc);
  auto DU = r.energy.topLeftCorner(m, kc);
  auto SDP = r.sdp.leftCols(kc);
  DU.setZero();
  const auto joint_seg = [&](long c) { return src.segment(c0 + c); };
  // On a chain with the joints in chain order, the columns alive at segment i are a suffix
  // [lo, kc) that grows towards the base (the friction solver asks in that order).
  bool ascending = model.is_chain;
  for (long c = 1; c < kc && ascending; ++c) ascending = joint_seg(c) >= joint_seg(c - 1);
  long lo = ascending ? kc : 0;
  for (int i = static_cast<int>(model.ns) - 1; i >= 0; --i) {
    const SegmentModel& sm = model.seg[i];
    const double Dinv = ws.seg[i].Dinv;
    if (ascending)
      while (lo > 0 && joint_seg(lo - 1) >= i) --lo;
    const int end = model.subtree_end[i];
    const double* eg = ws.general.eg.col(i).data();  // defined on the felt columns
    const std::pair<int, int> felt = feltColumns(i);
    const Eigen::Map<const Vector6> S0(r.axis.col(i).data()), u0(r.axis_inertia.col(i).data());
    for (long c = lo; c < kc; ++c) {
      const int js = joint_seg(c);
      if (js < i || js >= end) {  // joint not in i's subtree: no force change here
        SDP(i, c) = 0.0;
        continue;
      }
      // Force part f and moment part n as separate 3-vectors: a 6-vector updated in its top half
      // and reloaded whole stalls on store forwarding.
      double* dp = DP.col(c).data();
      Vector3 f, n;
      if (js == i) {  // becomes alive at the source's segment
        src.start(c0 + c, f, n);
      } else {  // the child on the path passed its apparent force about its tip: n += d x f
        f = Vector3(dp[0], dp[1], dp[2]);
        n = Vector3(dp[3], dp[4], dp[5]) + Vector3(r.offset.col(r.holder(c))).cross(f);
      }
      r.holder(c) = i;
      double acc = 0.0;  // free joint acceleration change
      if (sm.joint >= 0) {
        const double sd = S0.head<3>().dot(f) + S0.tail<3>().dot(n);
        SDP(i, c) = sd;
        acc = (src.torque(c0 + c, sm.joint) - sd) * Dinv;
        f += u0.head<3>() * acc;
        n += u0.tail<3>() * acc;
      } else {
        SDP(i, c) = 0.0;
      }
      for (int t = 0; t < 3; ++t) dp[t] = f(t), dp[3 + t] = n(t);
      if (sm.joint < 0) continue;
      double* du = DU.col(c).data();
      for (int t = felt.first; t < felt.second; ++t) du[t] += eg[t] * acc;
    }
    for (long c = 0; c < lo; ++c) SDP(i, c) = 0.0;  // not alive yet
  }
  if (model.floating) responseBaseInward(kc);
}

// d nu = K^+ dU for every column; into dnu_out (caller's row order) if given.
void HdCore::responseCoupling(long c0, long kc, Eigen::Ref<Eigen::MatrixXd>* dnu_out) {
  const int m = res.m;
  ResponseWorkspace& r = ws.response;
  const auto DU = r.energy.topLeftCorner(m, kc);
  auto DNU = r.dnu.topLeftCorner(m, kc);
  if (m == 0) return;              // (no rows of dnu)
  if (ws.use_cholesky && m > 0) {  // all columns through one factor
    DNU = DU;
    couplingSolveColumns(DNU);
  }
  for (long c = 0; c < kc; ++c) {
    if (!ws.use_cholesky) couplingSolve(DU.col(c), DNU.col(c));
    if (dnu_out)
      for (int row = 0; row < m; ++row) (*dnu_out)(res.general ? ws.general.order(row) : row, c0 + c) = DNU(row, c);
  }
}

// Outward pass: accelerations of all columns, base at rest, into dqdd. When the columns are every
// joint in chain order, the response G is symmetric and square: column c needs only the rows of
// the joints up to its own (G(j, c) for j <= c); the rows below come from the columns already
// computed (G(j, c) = G(c, j)). The columns alive at segment i are then the suffix c >= (joints
// before segment i): about half the work.
template <typename Sources>
void HdCore::responseOutward(const Sources& src, long c0, long kc, Eigen::Ref<Eigen::MatrixXd> dqdd) {
  ResponseWorkspace& r = ws.response;
  const int m = res.m;
  const bool symmetric = src.identity(c0, kc);
  auto ACC = r.force.leftCols(kc);  // per column: linear part a, angular part w
  const auto SDP = r.sdp.leftCols(kc);
  const auto DNU = r.dnu.topLeftCorner(m, kc);
  double* const dqdd_joints = dqdd.data() + model.nbv;  // joint j's row: nbv + j (after a floating base's)
  if (model.floating) {
    responseBaseOutward(c0, kc, dqdd);
  } else {
    ACC.setZero();
  }
  long first = 0;  // first alive column
  for (unsigned int i = 0; i < model.ns; ++i) {
    const SegmentModel& sm = model.seg[i];
    const int p = model.parent(i);
    if (i > 0 && p != static_cast<int>(i) - 1) {  // a later child: its parent's accelerations again
      if (p >= 0) {
        ACC = r.branch_acc.middleCols(model.branch_slot[p] * r.width, kc);
      } else if (model.floating) {
        ACC = r.base_acc.leftCols(kc);
      } else {
        ACC.setZero();
      }
    }
    const Vector3 offset = r.offset.col(i);
    const double* eg = ws.general.eg.col(i).data();  // defined on the felt columns
    const std::pair<int, int> felt = feltColumns(i);
    const double Dinv = ws.seg[i].Dinv;
    const Eigen::Map<const Vector6> S0(r.axis.col(i).data()), u0(r.axis_inertia.col(i).data());
    for (long c = first; c < kc; ++c) {
      double* acc = ACC.col(c).data();
      const Vector3 w(acc[3], acc[4], acc[5]);
      Vector3 a = Vector3(acc[0], acc[1], acc[2]) + w.cross(offset);  // about this tip origin
      if (sm.joint < 0) {
        for (int t = 0; t < 3; ++t) acc[t] = a(t);
        continue;
      }
      double v = src.torque(c0 + c, sm.joint) - SDP(i, c) - u0.head<3>().dot(a) - u0.tail<3>().dot(w);
      const double* dnu = DNU.col(c).data();
      for (int t = felt.first; t < felt.second; ++t) v -= eg[t] * dnu[t];
      v *= Dinv;
      dqdd_joints[sm.joint + (c0 + c) * dqdd.outerStride()] = v;
      for (int t = 0; t < 3; ++t) acc[t] = a(t) + S0(t) * v, acc[3 + t] = w(t) + S0(3 + t) * v;
    }
    if (model.branch_slot[i] >= 0) r.branch_acc.middleCols(model.branch_slot[i] * r.width, kc) = ACC;
    if (symmetric && sm.joint >= 0) {
      for (long c = sm.joint + 1; c < kc; ++c) dqdd(c, sm.joint) = dqdd(sm.joint, c);
      first = sm.joint + 1;
    }
  }
}

}  // namespace detail
}  // namespace vereshchagin
