// WholeBodySolver's programme (whole_body.hpp): the equalities E x = e eliminated exactly
// (x = xp + N w, E^T Pi = Q R column-pivoted, N the last columns of Q: an orthonormal null-space
// basis), then the least effort min |tau_a|^2 and, among its minimisers, min |x|^2 (the least
// contact forces, tau_a being fixed there) with the cone rows D lambda >= 0, by
// LexicographicQp (Lemke's pivoting), and the certificate: every row met to round-off.
#include <algorithm>
#include <cmath>

#include "whole_body_impl.hpp"

namespace vereshchagin {

namespace {

// Largest |E x - e| relative to the rows' scale.
double equalityResidual(const WholeBodySolver::Impl& s, const Eigen::Ref<const Eigen::VectorXd>& x, int& worst) {
  double res = 0.0;
  worst = -1;
  const double xs = x.size() ? x.cwiseAbs().maxCoeff() : 0.0;
  for (int i = 0; i < s.m; ++i) {
    const double v = s.E.row(i).head(s.p).dot(x) - s.e(i);
    const double scale = 1.0 + std::abs(s.e(i)) + s.E.row(i).head(s.p).cwiseAbs().maxCoeff() * xs;
    if (std::abs(v) / scale > res) res = std::abs(v) / scale, worst = i;
  }
  return res;
}

}  // namespace

// The polyhedral cones as rows on the forces: n.f >= 0 and mu cos(pi/k) n.f - m_j.f >= 0, m_j the
// unit outward normal of the polygon's facet j (docs/contacts.md: vertices at 2 pi j / k from
// t1 = unit(e x n), e the base axis least aligned with n, t2 = n x t1).
void WholeBodySolver::Impl::coneRows(const SolveInput& in) {
  cone_rows = 0;
  for (const PointContact& pc : in.contacts) cone_rows += 1 + pc.facets;
  if (D.rows() < cone_rows) D.resize(cone_rows, D.cols()), G.resize(cone_rows, G.cols()), g.resize(cone_rows);
  D.topLeftCorner(cone_rows, 3 * k).setZero();
  int row = 0;
  for (int c = 0; c < k; ++c) {
    const PointContact& pc = in.contacts[c];
    const Vector3 n = pc.normal.normalized();
    Eigen::Index axis = 0;
    n.cwiseAbs().minCoeff(&axis);
    const Vector3 t1 = Vector3::Unit(axis).cross(n).normalized(), t2 = n.cross(t1);
    D.block(row++, 3 * c, 1, 3) = n.transpose();
    const double kf = pc.facets, pi = 3.14159265358979323846;
    for (int j = 0; j < pc.facets; ++j) {
      const double a = (2 * j + 1) * pi / kf;
      const Vector3 mj = std::cos(a) * t1 + std::sin(a) * t2;
      D.block(row++, 3 * c, 1, 3) = (pc.mu * std::cos(pi / kf) * n - mj).transpose();
    }
  }
}

bool WholeBodySolver::Impl::eliminate() {
  auto xq = xp.head(p);
  if (m == 0 || p == 0) {  // nothing to eliminate (no rows), or nothing to eliminate with (no unknowns)
    rank = 0;
    Q.topLeftCorner(p, p).setIdentity();
    xq.setZero();
    int worst = -1;
    residual = equalityResidual(*this, xq, worst);
    if (residual <= options.tolerance) return true;
    std::snprintf(message, sizeof(message),
                  "not realizable: no actuated joint and no support, and the task row %d is not met (%.3g relative)",
                  worst, residual);
    return false;
  }
  qr.setThreshold(1e-10);
  qr.compute(E.topLeftCorner(m, p).transpose());
  rank = static_cast<int>(qr.rank());
  auto Qb = Q.topLeftCorner(p, p);
  work.resize(p);
  qr.householderQ().evalTo(Qb, work);
  // R11^T y1 = (Pi^T e)_1 by forward substitution, xp = Q1 y1.
  const auto& Rm = qr.matrixR();
  const auto& perm = qr.colsPermutation().indices();
  for (int i = 0; i < rank; ++i) {
    double v = e(perm(i));
    for (int j = 0; j < i; ++j) v -= Rm(j, i) * y(j);
    y(i) = v / Rm(i, i);
  }
  xq.noalias() = Q.topLeftCorner(p, rank) * y.head(rank);
  int worst = -1;
  residual = equalityResidual(*this, xq, worst);
  if (residual <= options.tolerance) return true;
  if (worst < mt)
    std::snprintf(message, sizeof(message),
                  "not realizable: the task rows and the sticking supports contradict each other (task row %d "
                  "off by %.3g relative, whatever the torques and forces)",
                  worst, residual);
  else
    std::snprintf(message, sizeof(message),
                  "not realizable: the task rows and the sticking supports contradict each other (support %d "
                  "off by %.3g relative, whatever the torques and forces)",
                  (worst - mt) / 3, residual);
  return false;
}

bool WholeBodySolver::Impl::program(const SolveInput& in) {
  const int d = p - rank;
  const auto N = Q.block(0, rank, p, d);
  auto xv = x.head(p), wv = w.head(d);
  if (k == 0) {  // torques only: the least |tau_a| in the affine set
    wv.noalias() = -N.transpose() * xp.head(p);
  } else {
    coneRows(in);
    const auto Dk = D.topLeftCorner(cone_rows, 3 * k);
    G.topLeftCorner(cone_rows, d).noalias() = Dk * N.bottomRows(3 * k);
    g.head(cone_rows).noalias() = -Dk * xp.segment(na, 3 * k);
    if (d > 0) {
      if (lqp_p < d || lqp_k < cone_rows) lqp.reserve(lqp_p = std::max(lqp_p, d), lqp_k = std::max(lqp_k, cone_rows));
      const int cr = std::max(na, 1);  // no motor: a zero row (the first programme then only finds a feasible point)
      C.topLeftCorner(cr, d).setZero();
      t.head(cr).setZero();
      if (na > 0) {
        C.topLeftCorner(na, d) = N.topRows(na);
        t.head(na) = xp.head(na);
      }
      P.topLeftCorner(d, d).setIdentity();
      pv.head(d).noalias() = N.transpose() * xp.head(p);
      const detail::Lemke::Result rc = lqp.solve(C.topLeftCorner(cr, d), t.head(cr), P.topLeftCorner(d, d), pv.head(d),
                                                 G.topLeftCorner(cone_rows, d), g.head(cone_rows), wv);
      if (rc != detail::Lemke::kSolved) {
        std::snprintf(message, sizeof(message),
                      "not realizable: the task and the sticking supports need contact forces outside the friction "
                      "cones (a support would pull or slide: the cones are too narrow)%s",
                      rc == detail::Lemke::kPivotLimit ? " (pivot limit)" : "");
        return false;
      }
    }
  }
  xv = xp.head(p);
  if (d > 0) xv.noalias() += N * wv;
  int worst = -1;
  residual = equalityResidual(*this, xv, worst);
  double cone = 0.0;
  int worst_cone = -1;
  if (k > 0) {
    const double fs = 1.0 + xv.tail(3 * k).cwiseAbs().maxCoeff();
    for (int i = 0; i < cone_rows; ++i) {
      const double v = -D.row(i).head(3 * k).dot(xv.tail(3 * k)) / fs;
      if (v > cone) cone = v, worst_cone = i;
    }
  }
  if (residual <= options.tolerance && cone <= options.tolerance) {
    residual = std::max(residual, cone);
    return true;
  }
  std::snprintf(message, sizeof(message),
                "not realizable: no contact forces in the friction cones meet the task (task/support residual "
                "%.3g, cone row %d violated by %.3g relative)",
                residual, worst_cone, cone);
  return false;
}

}  // namespace vereshchagin
