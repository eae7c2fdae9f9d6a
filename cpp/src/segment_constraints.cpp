// Constraints on any segments of a chain or a tree (Shakhimardanov's extension of the
// Popov-Vereshchagin recursion, on a parent array): HdCore's several-segment path. Conventions
// in hd_solver.hpp, the column ordering in hd_core.hpp.
//
// Columns are sorted by segment, highest index first, so that the columns felt by segment i
// (those on its subtree [i, subtree_end[i])) are the contiguous range [lo_i, active[i]) of the
// sorted order. In the inward sweep segment i's own columns (alfa in its tip axes) join the
// wrenches its children passed (each child's range, already in i's frame); each column then goes
// through the same projection A <- A - u e / D as on the fast path, and K = sum_i D_i^-1 e_i e_i^T
// with e_i = A_i^T S_i couples every pair felt by a common segment, block-wise.
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "articulated_step.hpp"
#include "dense_small.hpp"
#include "hd_core.hpp"
#include "model_validation.hpp"

namespace vereshchagin {
namespace detail {

int HdCore::solveSegments(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                          const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
                          const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  res.solved = false;
  res.general = false;
  if (segments.size() != alfa.cols())
    return fail(KDL::SolverI::E_SIZE_MISMATCH, "segments has %ld entries, expected %ld (one per alfa column)",
                (long)segments.size(), (long)alfa.cols());
  const int last = static_cast<int>(model.ns) - 1;
  bool last_only = model.is_chain && alfa.cols() <= kMaxConstraints && model.ns > 0;
  for (Eigen::Index c = 0; c < segments.size() && last_only; ++c) last_only = segments(c) == last;
  if (last_only) return solveLast(q, q_dot, alfa, beta, f_ext, ff_torques);  // the fast path
  return solveGeneral(q, q_dot, alfa, beta, segments, f_ext, ff_torques);
}

int HdCore::solveGeneral(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                         const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                         const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
                         const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  if (model.floating) return solveFloating(q, q_dot, alfa, beta, segments, f_ext, ff_torques);
  res.solved = false;
  res.general = false;
  state_q = &q;
  state_q_dot = &q_dot;
  int rc = checkInputs(q, q_dot, alfa, beta, f_ext, ff_torques, mcap);
  if (rc != 0) return rc;
  rc = sortColumns(segments);
  if (rc != 0) return rc;
  res.general = true;
  outwardSweep(q, q_dot, f_ext);
  if (loads != nullptr) applyFrameLoads();
  rc = inwardSweepGeneral(alfa, ff_torques);
  if (rc == 0) rc = passThroughEnergy(f_ext, ff_torques);
  if (rc != 0) {
    res.general = false;
    return rc;
  }
  factorizeCouplingGeneral();
  CouplingGeneral& g = ws.general;
  const int m = res.m;
  for (int k = 0; k < m; ++k) g.rhs(k) = g.ug(k) - beta(g.order(k));  // nu = K^+ (U - beta)
  if (ws.pt.used) g.rhs.head(m) -= ws.pt.energy.head(m);              // the drivers' parts that pass through
  couplingSolve(g.rhs.head(m), g.nug.head(m));
  finalSweepGeneral(ff_torques);
  for (int k = 0; k < m; ++k) res.nu_user(g.order(k)) = g.nug(k);
  commandFromNuGeneral(g.nug.head(m), res.tau_cmd);
  rc = checkBounded(res.nu_user.head(m), q_dot, beta, f_ext, ff_torques);
  if (rc != 0) return rc;
  res.solved = true;
  return 0;
}

// Counting sort of the columns by segment, highest index first (stable within a segment).
int HdCore::sortColumns(const Eigen::Ref<const Eigen::VectorXi>& segments) {
  const int m = static_cast<int>(segments.size());
  const int ns = static_cast<int>(model.ns);
  CouplingGeneral& g = ws.general;
  g.seg_count.setZero();
  for (int c = 0; c < m; ++c) {
    const int s = segments(c);
    if (s < 0 || s >= ns)
      return fail(KDL::SolverI::E_OUT_OF_RANGE, "segments(%d) = %d is out of range [0, %d)", c, s, ns);
    if (++g.seg_count(s) > kMaxConstraints)
      return fail(HdSolver::E_TOO_MANY_CONSTRAINTS, "segment %d ('%s') has more than %d constraint columns", s,
                  model.source.segments[s].getName().c_str(), kMaxConstraints);
  }
  g.active[ns] = 0;
  for (int i = ns - 1; i >= 0; --i) g.active[i] = g.active[i + 1] + g.seg_count(i);
  for (int i = 0; i < ns; ++i) g.seg_count(i) = g.active[i + 1];  // next free position
  for (int c = 0; c < m; ++c) g.order(g.seg_count(segments(c))++) = c;
  res.m = m;
  return 0;
}

// Calls f(lo, w) for each diagonal block [lo, lo + w) of K: the columns under one segment
// attached to the base (columns of different such subtrees share no segment, so K couples them
// by exact zeros). A chain has one block.
template <typename F>
void HdCore::forEachCouplingBlock(const F& f) const {
  const CouplingGeneral& g = ws.general;
  if (model.floating) {  // every column is felt by the base: one block
    if (res.m > 0) f(0, res.m);
    return;
  }
  for (int r = 0; r < static_cast<int>(model.ns); r = model.subtree_end[r]) {
    const int lo = g.lo(model, r), w = g.active[r] - lo;
    if (w > 0) f(lo, w);
  }
}

// Calls g(size) with size = std::integral_constant<int, S>: S = 6 for a block of one 6-D
// constraint (the same loops then run unrolled at a fixed size), Eigen::Dynamic otherwise.
namespace {
template <typename G>
void withBlockSize(int w, const G& g) {
  if (w == kMaxConstraints) {
    g(std::integral_constant<int, kMaxConstraints>());
  } else {
    g(std::integral_constant<int, Eigen::Dynamic>());
  }
}
}  // namespace

// Segment i's own columns: alfa in its tip axes (the moment is already about its origin).
void HdCore::addOwnColumns(int i, const Eigen::Ref<const Matrix6X>& alfa) {
  CouplingGeneral& g = ws.general;
  const Matrix3& R = ws.seg[i].R_base;
  for (int k = g.active[i + 1]; k < g.active[i]; ++k) {
    const auto a = alfa.col(g.order(k));
    g.anew.col(k).head<3>().noalias() = R.transpose() * a.head<3>();
    g.anew.col(k).tail<3>().noalias() = R.transpose() * a.tail<3>();
    g.acur.col(k) = g.anew.col(k);
  }
}

int HdCore::inwardSweepGeneral(const Eigen::Ref<const Matrix6X>& alfa,
                               const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  CouplingGeneral& g = ws.general;
  const int M = res.m;
  g.ug.head(M).setZero();
  forEachCouplingBlock([&g](int lo, int w) {  // K is only ever read block by block
    withBlockSize(w, [&](auto size) {
      constexpr int S = decltype(size)::value;
      g.kg.block<S, S>(lo, lo, w, w).setZero();
    });
  });
  ws.kappa = 0.0;
  const bool has_tau = ff_torques.size() != 0;
  for (int i = static_cast<int>(model.ns) - 1; i >= 0; --i) {
    const SegmentModel& sm = model.seg[i];
    SegmentState& s = ws.seg[i];
    addOwnColumns(i, alfa);
    const int lo = g.lo(model, i), w = g.active[i] - lo;  // the columns felt here: [lo, lo + w)
    Vector6 pa;
    if (sm.joint >= 0) {
      double free = 0.0;
      if (!articulate(i, has_tau ? ff_torques(sm.joint) : 0.0, pa, free)) return degenerate(i);
      if (w > 0) projectColumns(i, lo, w, free);
    } else {
      pa = s.pA;
      if (w > 0) moveColumnsToParent(i, lo, w);
    }
    if (model.parent(i) >= 0) {
      passToParent(i, pa);
    } else if (model.floating) {
      passToBase(i, pa);  // the columns stay in acur, in base axes (closeAtBase)
    } else if (w > 0) {
      g.ug.segment(lo, w).noalias() += g.acur.middleCols(lo, w).transpose().lazyProduct(root_acc);
    }
  }
  return 0;
}

// The felt columns [lo, lo + w) at moving segment i, one 6-vector at a time: e_c = S^T a_c into
// eg, U_c += a_c^T (c_i + S free), the bound kappa, then a_c <- a_c - u e_c / D (what the parent
// feels through the joint) carried to the parent's frame; K += e e^T / D on the block.
void HdCore::projectColumns(int i, int lo, int w, double free) {
  const SegmentModel& sm = model.seg[i];
  const SegmentState& s = ws.seg[i];
  CouplingGeneral& g = ws.general;
  const Vector6 bias = s.c + sm.S * free;
  const Vector6 ud = s.Dinv * s.u;
  double* e = g.eg.col(i).data() + lo;
  double* u = g.ug.data() + lo;
  double kappa = 0.0;
  for (int k = 0; k < w; ++k) {
    Eigen::Map<Vector6> a(g.acur.col(lo + k).data());
    const double ek = sm.dotS(a);
    e[k] = ek;
    u[k] += a.dot(bias);
    // The fast path's unit-consistent bound of |e_c|: |v||f_c| + |w||n_c|.
    kappa += sm.v2 * a.head<3>().squaredNorm() + sm.w2 * a.tail<3>().squaredNorm();
    a -= ek * ud;
    forceToParentInPlace(s.X, a);
  }
  ws.kappa += 2.0 * s.Dinv * kappa;
  for (int c = 0; c < w; ++c) {
    double* kc = g.kg.col(lo + c).data() + lo;
    for (int r = 0; r < w; ++r) kc[r] += s.Dinv * (e[r] * e[c]);
  }
}

// The felt columns at a segment on a fixed joint: carried rigidly to the parent's frame.
void HdCore::moveColumnsToParent(int i, int lo, int w) {
  const Pose& X = ws.seg[i].X;
  for (int k = lo; k < lo + w; ++k) {
    Eigen::Map<Vector6> a(ws.general.acur.col(k).data());
    forceToParentInPlace(X, a);
  }
}

// K = kg (M x M): certified Cholesky (truncation policy, every eigenvalue provably above the
// threshold) else an eigen-decomposition with the policy's multipliers (symmetricEigen(): Householder
// tridiagonalisation and implicit QR, about a third of cyclic Jacobi's work at M = 7; jacobiEigen()
// only if the QR steps do not converge). The Cholesky factor
// is built block by block (choleskyBlocks()): its entries off the blocks are exact zeros anyway,
// and L^-1 is block-diagonal too, so ||L^-1||_F^2 is the sum over the blocks.
void HdCore::factorizeCouplingGeneral() {
  CouplingGeneral& g = ws.general;
  const int m = res.m;
  res.rank = 0;
  res.sigma_known = false;
  ws.use_cholesky = false;
  if (m == 0) return;
  if (options.policy == SingularityPolicy::TruncatedPseudoInverse && choleskyBlocks()) {
    ws.use_cholesky = true;
    res.rank = m;
    return;
  }
  auto W = g.work_g.topLeftCorner(m, m);
  auto V = g.vg.topLeftCorner(m, m);
  const auto fill = [&] {
    W.setZero();  // the exact zeros between the blocks, which kg does not hold
    forEachCouplingBlock([&](int lo, int w) { W.block(lo, lo, w, w) = g.kg.block(lo, lo, w, w); });
  };
  fill();
  auto scratch = g.work_v.topLeftCorner(m, 4);
  if (!detail::symmetricEigen(W, V, scratch)) {  // (the QR steps did not converge: rotations instead)
    fill();
    detail::jacobiEigen(W, V);
  }
  const auto lam = W.diagonal();
  const double cut = options.rcond * std::max(std::max(lam.maxCoeff(), 0.0), ws.kappa);
  res.sigma_min = std::max(lam.minCoeff(), 0.0);
  res.sigma_known = true;
  auto inv = g.invg.head(m);
  res.rank = detail::policyMultipliers(lam, inv, cut, options.policy == SingularityPolicy::TruncatedPseudoInverse,
                                       options.damping);
}

int HdCore::nullMultipliers(Eigen::Ref<Eigen::MatrixXd> out) const {
  if (!res.general || ws.use_cholesky || res.rank >= res.m ||
      options.policy != SingularityPolicy::TruncatedPseudoInverse)
    return -1;
  const CouplingGeneral& g = ws.general;
  int d = 0;
  for (int j = 0; j < res.m; ++j) {
    if (g.invg(j) != 0.0) continue;  // a kept eigenvalue
    for (int s = 0; s < res.m; ++s) out(g.order(s), d) = g.vg(s, j);
    ++d;
  }
  return d;
}

// Cholesky factor of K into cholg's diagonal blocks (their lower triangles; nothing reads the
// rest) and the certificate that every eigenvalue is above the truncation threshold rcond kappa
// (kappa >= lambda_max(K)): L^-1 is block-diagonal, so ||L^-1||_2^2 is the largest of the blocks'
// (each bounded by inverseNormBound(), k^2 operations) and ||L^-1||_F^2 their sum (the exact
// fallback, k^3 / 3, when the bound is not enough); lambda_min(K) >= 1 / either. False if a block
// is not positive definite or both proofs fail.
bool HdCore::choleskyBlocks() {
  CouplingGeneral& g = ws.general;
  bool ok = true;
  double bound2 = 0.0;  // >= ||L^-1||_2^2
  forEachCouplingBlock([&](int lo, int w) {
    if (!ok) return;
    withBlockSize(w, [&](auto size) {
      constexpr int S = decltype(size)::value;
      auto L = g.cholg.block<S, S>(lo, lo, w, w);
      ok = detail::choleskyCertified(g.kg.block<S, S>(lo, lo, w, w), L, 0.0);
      auto x = g.tmp.segment<S>(0, w);
      if (ok) bound2 = std::max(bound2, detail::inverseNormBound(L, x));
    });
  });
  if (!ok) return false;
  const double threshold = options.rcond * ws.kappa;
  if (1.0 / bound2 > threshold) return true;
  double frob2 = 0.0;  // ||L^-1||_F^2
  forEachCouplingBlock([&](int lo, int w) {
    withBlockSize(w, [&](auto size) {
      constexpr int S = decltype(size)::value;
      auto x = g.tmp.segment<S>(0, w);
      frob2 += detail::inverseFrobeniusSquared(g.cholg.block<S, S>(lo, lo, w, w), x);
    });
  });
  const double lower = 1.0 / frob2;
  return std::isfinite(lower) && lower > threshold;
}

// Smallest eigenvalue of K: the smallest over its diagonal blocks.
double HdCore::smallestEigenvalueGeneral() const {
  const CouplingGeneral& g = ws.general;
  double lam = std::numeric_limits<double>::infinity();
  forEachCouplingBlock([&](int lo, int w) {
    auto W = g.work_g.topLeftCorner(w, w);
    auto scratch = g.work_v.topLeftCorner(w, 4);
    W = g.kg.block(lo, lo, w, w);
    lam = std::min(lam, detail::smallestEigenvalue(W, scratch));
  });
  return std::max(lam, 0.0);
}

void HdCore::couplingSolve(const Eigen::Ref<const Eigen::VectorXd>& rhs, Eigen::Ref<Eigen::VectorXd> out) const {
  const int m = res.m;
  if (!res.general) {
    VectorC r = rhs.head(m), o;
    applyCouplingInverse(r, o);
    out.head(m) = o;
    return;
  }
  if (m == 0) return;
  const CouplingGeneral& g = ws.general;
  if (ws.use_cholesky) {
    out.head(m) = rhs.head(m);
    forEachCouplingBlock([&](int lo, int w) {
      withBlockSize(w, [&](auto size) {
        constexpr int S = decltype(size)::value;
        auto x = out.template segment<S>(lo, w);
        detail::choleskySolve(g.cholg.block<S, S>(lo, lo, w, w), x);
      });
    });
    return;
  }
  const auto V = g.vg.topLeftCorner(m, m);
  g.tmp.head(m).noalias() = V.transpose().lazyProduct(rhs.head(m));
  g.tmp.head(m).array() *= g.invg.head(m).array();
  out.head(m).noalias() = V.lazyProduct(g.tmp.head(m));
}

void HdCore::couplingSolveColumns(Eigen::Ref<Eigen::MatrixXd> B) const {
  if (!res.general) {
    detail::choleskySolveColumns(ws.fast.chol, B);
    return;
  }
  forEachCouplingBlock([&](int lo, int w) {
    auto rows = B.middleRows(lo, w);
    detail::choleskySolveColumns(ws.general.cholg.block(lo, lo, w, w), rows);
  });
}

// Final outward sweep of the several-segment path: the columns felt by segment i.
void HdCore::finalSweepGeneral(const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  const CouplingGeneral& g = ws.general;
  finalSweep(ff_torques, [this, &g](int i) {
    const int lo = g.lo(model, i), w = g.active[i] - lo;
    return w > 0 ? g.eg.col(i).segment(lo, w).dot(g.nug.segment(lo, w)) : 0.0;
  });
}

// tau_cmd = -sum_c J_c^T alfa_c nu_c: each segment adds the wrenches -alfa nu of its own columns
// (tip axes, tip origin) to what its children pass, carried rigidly to the base.
void HdCore::commandFromNuGeneral(const Eigen::Ref<const Eigen::VectorXd>& nu_sorted,
                                  Eigen::Ref<Eigen::VectorXd> tau_cmd) const {
  const CouplingGeneral& g = ws.general;
  Matrix6X& f = g.seg_force;  // the wrench felt by each segment
  tau_cmd.setZero();
  if (res.m == 0) return;
  f.setZero();
  double* const joints = tau_cmd.data() + model.nbv;  // after a floating base's entries
  Vector6 base = Vector6::Zero();                     // the wrench felt by a floating base
  for (int i = static_cast<int>(model.ns) - 1; i >= 0; --i) {
    const SegmentModel& sm = model.seg[i];
    const int c0 = g.active[i + 1], c = g.active[i];
    if (c > c0) f.col(i).noalias() -= g.anew.middleCols(c0, c - c0).lazyProduct(nu_sorted.segment(c0, c - c0));
    if (sm.joint >= 0) joints[sm.joint] = sm.S.dot(f.col(i));
    if (model.parent(i) >= 0) {
      auto fp = f.col(model.parent(i));
      addForceToParent(ws.seg[i].X, f.col(i), fp);
    } else if (model.floating) {
      addForceToParent(ws.seg[i].X, f.col(i), base);
    }
  }
  if (model.floating) tau_cmd.head(model.nbv).noalias() = model.S_base.transpose() * base;
}

}  // namespace detail
}  // namespace vereshchagin
