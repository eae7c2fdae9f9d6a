// Who carries the load when the accelerations do not say (contact_stage.hpp): once the contact
// forces are found, every force distribution that leaves qdd unchanged and meets the contact
// conditions is as valid (redundant contacts, or a contact whose direction a task constraint also
// holds). The solve takes the one of least motor effort: the smallest ||tau_command||^2 (the
// motors' torques: the task's constraint forces and the set-points' reactions), so that surfaces
// carry what they can and the motors only the rest. With joint friction, the torques of the
// sticking joints (within their bounds) are coordinates too: the friction solver's least-command
// rule, together with the contacts. A small convex programme in the free coordinates (lemke.hpp,
// ConvexQp); skipped when their response columns are independent (the forces are then unique).
// Over a time step the same programme on the step's problem: the impulses that keep qdd (so the
// end velocities) and meet the velocity-level conditions, a point's row being its end velocity
// over dt, a + v / dt, and a joint's qdd_j + qd_j / dt.
#include <algorithm>
#include <cmath>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "dense_small.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

// The free coordinates of the solved forces: their directions, the validity rows in them, and
// their current values (x*). Returns the number of coordinates.
int ContactStage::effortCoordinates(const SolveInput& in, const Eigen::VectorXd& qdd) {
  int p = 0, k = 0;
  const auto addDir = [&](int contact, const Vector3& e) {
    eff_dir_.col(p) = e;
    eff_contact_(p) = contact;
    eff_x_(p) = e.dot(forces.col(contact));
    return p++;
  };
  const auto addRow = [&](double rhs) {
    eff_r_(k) = rhs;
    eff_rows_.row(k).head(eff_dir_.cols()).setZero();
    return k++;
  };
  for (std::size_t c = 0; c < points_.size(); ++c) {
    Point& pt = points_[c];
    const PointContact& pc = in.contacts[c];
    const Vector3 f = forces.col(c);
    const double fn = pt.n.dot(f);
    const int ci = static_cast<int>(c);
    // The point's row in the solved motion (its acceleration; over a time step its end velocity
    // over dt, a + v / dt): a support whose normal row is not zero leaves its surface (no force);
    // one with a zero tangential row may stick.
    Vector3 bias;
    Vector3 a = pointAcceleration(pc, qdd, bias);
    if (dt_ > 0.0) a += pt.v / dt_;
    if (step_without_bias_) a -= bias;  // the velocity-level retry's rows (contact_step.cpp)
    const double an = pt.n.dot(a), a_tol = 1e-9 * std::max(1.0, a.norm());
    const Vector3 at_ = a - an * pt.n;
    const bool resting = pt.kind == kTouching || pt.kind == kSetPointRest;
    const bool sticking = resting && pc.mu > 0.0 && at_.norm() <= a_tol;
    pt.held = sticking;
    if (pc.isSupport()) {
      if (pt.kind == kSeparating || an > a_tol) continue;
      // Frictionless or sliding: the force keeps its direction (at rest: opposing a_t).
      Vector3 e = pt.n;
      if (!sticking && pc.mu > 0.0) {
        const Vector3 slide = pt.kind == kSliding ? pt.v - pt.n.dot(pt.v) * pt.n : at_;
        e = fn > 0.0 ? Vector3(f / fn)
                     : Vector3(pt.n + pc.mu * mostOpposed(pt, slide, pc.facets));  // found, or a vertex
      }
      const int xn = addDir(ci, e);
      eff_x_(xn) = fn;
      eff_rows_(addRow(0.0), xn) = 1.0;  // f_n >= 0
      if (!sticking) continue;
      const int x1 = addDir(ci, pt.t1), x2 = addDir(ci, pt.t2);
      for (int i = 0; i < pc.facets; ++i) {  // inside every edge of mu f_n conv{d_j}
        const Eigen::Vector2d e_i = edgeCoords(i, pc.facets);
        const int row = addRow(0.0);
        eff_rows_(row, xn) = pc.mu * std::cos(M_PI / pc.facets);
        eff_rows_(row, x1) = -e_i(0);
        eff_rows_(row, x2) = -e_i(1);
      }
    } else if (sticking) {  // a set-point's tangential force, inside mu F conv{d_j}
      const int x1 = addDir(ci, pt.t1), x2 = addDir(ci, pt.t2);
      for (int i = 0; i < pc.facets; ++i) {
        const Eigen::Vector2d e_i = edgeCoords(i, pc.facets);
        const int row = addRow(-pc.mu * pc.force * std::cos(M_PI / pc.facets));
        eff_rows_(row, x1) = -e_i(0);
        eff_rows_(row, x2) = -e_i(1);
      }
    }
  }
  // The sticking joints with friction or on a limit (their row zero): a torque within its bounds.
  const double a_tol = 1e-9 * (nz_ > 0 ? lcp_scale_ : std::max(1.0, qdd.cwiseAbs().maxCoeff()));
  eff_contacts_ = p;
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const JointUnknown& u = joints_[i];
    if (std::abs(qdd(nbv_ + u.joint) + u.row_bias) > a_tol) continue;
    eff_dir_.col(p).setZero();
    eff_contact_(p) = -1 - static_cast<int>(i);
    eff_joint_(p - eff_contacts_) = u.joint;
    eff_x_(p) = joint_tau_(nbv_ + u.joint);
    const int x = p++;
    if (std::isfinite(u.lo)) eff_rows_(addRow(u.lo), x) = 1.0;    // tau >= lo
    if (std::isfinite(u.hi)) eff_rows_(addRow(-u.hi), x) = -1.0;  // tau <= hi
  }
  eff_k_ = k;
  return p;
}

int ContactStage::leastEffort(DataImpl& d, const SolveInput& in) {
  HdCore& c = d.core;
  const int n = nv_, m = c.res.m;
  const int nj = static_cast<int>(joints_.size());
  int k_max = 2 * nj;
  for (const PointContact& pc : in.contacts) k_max += 1 + pc.facets;
  reserveEffort(3 * static_cast<int>(in.contacts.size()) + nj, k_max, m);
  const int p = effortCoordinates(in, c.res.qdd), pc = eff_contacts_;
  if (p == 0) return 0;
  for (int i = 0; i < pc; ++i) {
    const int ci = eff_contact_(i);
    const Vector3 e = eff_dir_.col(i);
    eff_seg_(i) = in.contacts[ci].segment;
    eff_wrench_.col(i) << e, points_[ci].r.cross(e);
  }
  auto G = eff_dqdd_.topLeftCorner(n, p);
  auto N = eff_dnu_.topLeftCorner(m, p);
  Eigen::Ref<Eigen::MatrixXd> dnu_c(N.leftCols(pc)), dnu_j(N.rightCols(p - pc));
  if (c.wrenchResponse(eff_seg_.head(pc), eff_wrench_.leftCols(pc), G.leftCols(pc), &dnu_c) != 0) return 0;
  if (p > pc && c.responseColumns(eff_joint_.head(p - pc), G.rightCols(p - pc), joint_dtau_.leftCols(0), &dnu_j))
    return 0;
  // Unique forces when G has independent columns (certified Cholesky of G^T G).
  auto GtG = eff_gtg_.topLeftCorner(p, p);
  GtG.noalias() = G.transpose() * G;
  const double scale = std::max(1e-300, GtG.diagonal().maxCoeff());
  if (choleskyCertified(GtG, eff_l_, 1e-10 * scale)) return 0;
  // min 1/2 ||tau* + T dx||^2 subject to G dx = 0 (qdd kept) and the validity rows at x* + dx.
  const int k = eff_k_, rows = 2 * n + k;
  auto R = eff_r_all_.topLeftCorner(rows, p);
  auto r = eff_rhs_.head(rows);
  R.topRows(n) = G;
  R.middleRows(n, n) = -G;
  R.bottomRows(k) = eff_rows_.topLeftCorner(k, p);
  const double tol = 1e-12 * std::max(1.0, G.cwiseAbs().maxCoeff());
  r.head(2 * n).setConstant(-tol);  // G dx = 0 to round-off
  r.tail(k) = eff_r_.head(k);       // (two statements: no temporary)
  r.tail(k).noalias() -= eff_rows_.topLeftCorner(k, p) * eff_x_.head(p);
  // tau_cmd is linear in nu: its change per coordinate, column by column. Without motor columns
  // (m == 0) every distribution costs no effort: the first programme has no rows, and the least
  // contact forces alone pick the split.
  const int tr = m == 0 ? 0 : n;
  auto T = eff_dtau_.topLeftCorner(tr, p);
  for (int i = 0; i < p && m > 0; ++i)
    if (c.commandTorquesOf(N.col(i), T.col(i)) != 0) return 0;
  // Then the least contact forces: 1/2 sum_c ||f_c||^2, f_c = fixed_c + sum_i x_i e_i over its
  // coordinates (their Gram matrix per contact; the gradient at x* is e_i . f_c).
  auto P = eff_q_.topLeftCorner(p, p);
  auto pv = eff_c_.head(p);
  for (int i = 0; i < p; ++i) {  // (the joints' coordinates: none of it)
    for (int j = 0; j < p; ++j)
      P(i, j) = eff_contact_(i) == eff_contact_(j) ? eff_dir_.col(i).dot(eff_dir_.col(j)) : 0.0;
    pv(i) = i < pc ? eff_dir_.col(i).dot(forces.col(eff_contact_(i))) : 0.0;
  }
  auto dx = eff_dx_.head(p);
  if (lqp_.solve(T, c.res.tau_cmd.head(tr), P, pv, R, r, dx, n) != Lemke::kSolved) return 0;  // keep the forces
  if (dx.isZero(0.0)) return 0;  // the forces found are the programme's: the last sweep stands
  eff_x_.head(p) += dx;
  for (int i = 0; i < pc; ++i) forces.col(eff_contact_(i)) = points_[eff_contact_(i)].fixed;  // known part
  for (int i = 0; i < pc; ++i) forces.col(eff_contact_(i)) += eff_x_(i) * eff_dir_.col(i);
  for (int i = 0; i < pc; ++i) {  // f_n >= 0 holds to the programme's round-off: no pulling at all
    const int ci = eff_contact_(i);
    const double fn = points_[ci].n.dot(forces.col(ci));
    if (in.contacts[ci].isSupport() && fn < 0.0) forces.col(ci) -= fn * points_[ci].n;
  }
  for (int i = pc; i < p; ++i) joint_tau_(nbv_ + eff_joint_(i - pc)) = eff_x_(i);
  if (const int rc = solveWithForces(d, in)) return rc;
  for (int i = 0; i < pc; ++i) {  // the supports' statuses with their new forces
    const int ci = eff_contact_(i);
    if (!in.contacts[ci].isSupport()) continue;
    if (!pushes(points_[ci], forces.col(ci)))
      status[ci] = ContactStatus::Separating;
    else if (status[ci] == ContactStatus::Separating)  // touching, now carrying
      status[ci] = points_[ci].held ? ContactStatus::Sticking : ContactStatus::Sliding;
  }
  return 0;
}

void ContactStage::reserveEffort(int p, int k, int m) {
  const int n = nv_;
  if (eff_dir_.cols() < p) {
    eff_dir_.resize(3, p);
    eff_contact_.resize(p), eff_x_.resize(p), eff_seg_.resize(p), eff_c_.resize(p), eff_dx_.resize(p);
    eff_joint_.resize(p);
    eff_wrench_.resize(6, p);
    eff_gtg_.resize(p, p), eff_l_.resize(p, p), eff_q_.resize(p, p);
    eff_dqdd_.resize(n, p);
    eff_dtau_.resize(n, p);
  }
  if (eff_rows_.rows() < k || eff_rows_.cols() < eff_dir_.cols()) {
    eff_rows_.resize(std::max<Eigen::Index>(k, eff_rows_.rows()), eff_dir_.cols());  // (never shrinks)
    eff_r_.resize(eff_rows_.rows());
  }
  if (eff_dnu_.rows() < m || eff_dnu_.cols() < eff_dir_.cols())
    eff_dnu_.resize(std::max<Eigen::Index>({m, 1, eff_dnu_.rows()}), eff_dir_.cols());  // (never shrinks)
  const int rows = 2 * n + static_cast<int>(eff_rows_.rows());
  if (eff_r_all_.rows() < rows || eff_r_all_.cols() < eff_dir_.cols()) {
    eff_r_all_.resize(rows, eff_dir_.cols());
    eff_rhs_.resize(rows);
  }
  lqp_.reserve(static_cast<int>(eff_dir_.cols()), rows);
}

}  // namespace detail
}  // namespace vereshchagin
