// The floating base of HdCore (base_kind.hpp): the base body's model, the checks of q / q_dot on
// it, and the several-segment path closed at the base (Featherstone, Rigid Body Dynamics
// Algorithms, ch. 9, with the Popov-Vereshchagin constraint columns carried through the base).
//
// The base is a body of inertia I_base on a k-DOF joint to the world with axes S (6 x k, base
// frame; the identity for a free-flyer). The segments' sweeps run as on a fixed base, with the
// base's velocity and orientation at the root segments (their R_base: world axes). The inward
// sweep adds each root segment's apparent inertia and bias force to the base (passToBase), and
// the constraint columns arrive in base axes; the base step then closes the recursion:
//   U = IA S, D = S^T U, free = D^-1 (tau_b - S^T pA)    (the world at rest, no constraint)
//   e = S^T A, U_c += A_c^T S free, K += e^T D^-1 e, A <- A - U D^-1 e (what the world feels,
//   zero for a free-flyer), U_c += A_c^T a_world
// and the final sweep starts from the base's acceleration
//   qdd_b = D^-1 (tau_b - S^T (pA + IA a_world) - e nu), a_b = a_world + S qdd_b
// with a_world the world's (fictitious, -gravity) acceleration in base axes. qdd_b is then the
// base's acceleration relative to the world in base axes (Pinocchio's free-flyer / planar a).
#include <cmath>

#include "articulated_step.hpp"
#include "hd_core.hpp"
#include "model_validation.hpp"

namespace vereshchagin {
namespace detail {

// Cholesky factor, left-looking, one division per pivot.
bool BaseFactor::compute(const Matrix6& D, int size) {
  k = size;
  for (int j = 0; j < k; ++j) {
    double d = D(j, j);
    for (int p = 0; p < j; ++p) d -= L(j, p) * L(j, p);
    if (!(d > 0.0)) return false;
    L(j, j) = std::sqrt(d);
    inv(j) = 1.0 / L(j, j);
    for (int i = j + 1; i < k; ++i) {
      double v = D(i, j);
      for (int p = 0; p < j; ++p) v -= L(i, p) * L(j, p);
      L(i, j) = v * inv(j);
    }
  }
  return true;
}

// Forward substitution by columns: each solved entry updates the rows below it independently.
template <typename V>
void BaseFactor::forward(V&& x) const {
  for (int j = 0; j < k; ++j) {
    const double xj = x(j) * inv(j);
    x(j) = xj;
    for (int i = j + 1; i < k; ++i) x(i) -= L(i, j) * xj;
  }
}

template <typename V>
void BaseFactor::backward(V&& x) const {
  for (int j = k - 1; j >= 0; --j) {
    double v = x(j);
    for (int i = j + 1; i < k; ++i) v -= L(i, j) * x(i);
    x(j) = v * inv(j);
  }
}

namespace {

// K += Y^T Y for a symmetric K: the lower triangle's dot products, mirrored.
template <typename MY, typename MK>
void addGram(const MY& Y, MK& K) {
  const Eigen::Index m = Y.cols();
  for (Eigen::Index c = 0; c < m; ++c) {
    for (Eigen::Index r = c; r < m; ++r) K(r, c) += Y.col(r).dot(Y.col(c));
    for (Eigen::Index r = c + 1; r < m; ++r) K(c, r) = K(r, c);
  }
}

constexpr double kUnitTolerance = 1e-6;  // |norm - 1| of the quaternion / (cos, sin) accepted
constexpr int E_SIZE = KDL::SolverI::E_SIZE_MISMATCH, E_NF = HdSolver::E_NONFINITE_INPUT;
}  // namespace

// The base of a model (construction time): kind, sizes, axes and inertia, validated. 0 or a
// message in model.message.
int buildBase(HdModel& model) {
  const ModelSource& src = model.source;
  model.base = src.base;
  model.floating = src.base != BaseKind::Fixed;
  model.nbq = baseConfigurationSize(src.base);
  model.nbv = baseVelocitySize(src.base);
  if (!model.floating) return 0;
  model.S_base.setZero(6, model.nbv);
  if (src.base == BaseKind::FreeFlyer) {
    model.S_base.setIdentity(6, 6);
  } else {  // planar: x, y translation, z rotation
    model.S_base(0, 0) = model.S_base(1, 1) = model.S_base(5, 2) = 1.0;
  }
  const KDL::RigidBodyInertia& rbi = src.base_inertia;
  const double mass = rbi.getMass();
  const Vector3 c(rbi.getCOG().x(), rbi.getCOG().y(), rbi.getCOG().z());
  const Matrix3 I_origin = Eigen::Map<const Matrix3>(rbi.getRotationalInertia().data);
  const Matrix3 I_com = I_origin + mass * skew(c) * skew(c);
  char buf[320];
  const double round_off = std::max(I_origin.cwiseAbs().maxCoeff(), mass * c.squaredNorm());
  const char* why = c.allFinite() && I_origin.allFinite()
                        ? inertiaProblem(mass, I_com, model.inertia_check, buf, sizeof buf, round_off)
                        : "non-finite inertial parameters";
  if (why != nullptr) {
    model.error = HdSolver::E_INVALID_MODEL;
    model.message = std::string("the floating base body (ModelOptions::base_inertia and the root link): ") + why;
    return model.error;
  }
  model.I_base = rigidInertia(mass, c, 0.5 * (I_origin + I_origin.transpose()));
  return 0;
}

// Sizes (nq, nv), finiteness and the unit quaternion / (cos, sin) of the base's configuration.
int HdCore::checkFloatingInputs(const Eigen::Ref<const Eigen::VectorXd>& q,
                                const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                                const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  if (model_error != 0) return model_error;
  const long nq = model.nbq + model.nj, nv = model.nbv + model.nj;
  const char* kind = model.base == BaseKind::FreeFlyer ? "free-flyer base" : "planar base";
  if (q.size() != nq)
    return fail(E_SIZE, "q has %ld entries, expected %ld (%d for the %s, then %u joints)", (long)q.size(), nq,
                model.nbq, kind, model.nj);
  if (q_dot.size() != nv)
    return fail(E_SIZE, "q_dot has %ld entries, expected %ld (%d for the %s, then %u joints)", (long)q_dot.size(), nv,
                model.nbv, kind, model.nj);
  if (ff_torques.size() != nv && ff_torques.size() != 0)
    return fail(E_SIZE, "ff_torques has %ld entries, expected %ld (%d for the %s, then %u joints) or 0",
                (long)ff_torques.size(), nv, model.nbv, kind, model.nj);
  if (!q.head(model.nbq).allFinite() || !q_dot.head(model.nbv).allFinite())
    return fail(E_NF, "the base's entries of q or q_dot contain NaN or Inf");
  const bool ff = model.base == BaseKind::FreeFlyer;
  const double norm = ff ? q.segment<4>(3).norm() : q.segment<2>(2).norm();
  if (!(std::abs(norm - 1.0) <= kUnitTolerance))
    return fail(HdSolver::E_NONFINITE_INPUT,
                ff ? "the base quaternion q[3:7] (x, y, z, w) has norm %.17g: it must be a unit quaternion (within "
                     "1e-6; normalize it)"
                   : "the planar base's (cos yaw, sin yaw) = q[2:4] has norm %.17g: it must be a unit vector (within "
                     "1e-6; normalize it)",
                norm);
  return 0;
}

// The base's pose, velocity and the world's acceleration in base axes; its inertia and rigid
// bias force start the inward sweep's accumulation.
void HdCore::basePose(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot) {
  BaseState& b = ws.base;
  if (model.base == BaseKind::FreeFlyer) {
    const Eigen::Quaterniond quat(q(6), q(3), q(4), q(5));  // (w, x, y, z)
    b.X.R = quat.normalized().toRotationMatrix();
    b.X.p = q.head<3>();
    b.v = q_dot.head<6>();
  } else {
    const double n = std::hypot(q(2), q(3)), c = q(2) / n, s = q(3) / n;
    b.X.R << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
    b.X.p << q(0), q(1), 0.0;
    b.v.setZero();
    b.v(0) = q_dot(0);
    b.v(1) = q_dot(1);
    b.v(5) = q_dot(2);
  }
  b.a_world = motionToChild(b.X, root_acc);
  b.IA = model.I_base;
  b.pA = crossForce(b.v, model.I_base * b.v);
}

// The base step of the inward sweep (see the top of this file), after inwardSweepGeneral. With
// Y = L^-1 e (D = L L^T): K += Y^T Y, and kappa += |Y|_F^2 (the trace of that share).
int HdCore::closeAtBase(const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  BaseState& b = ws.base;
  CouplingGeneral& g = ws.general;
  const BaseAxes& S = model.S_base;
  const int k = model.nbv, m = res.m;
  const bool ff = model.base == BaseKind::FreeFlyer;  // S = identity: U = D = IA, e = A
  if (!ff) {
    b.U.noalias() = b.IA * S;
    b.D.topLeftCorner(k, k).noalias() = S.transpose() * b.U;
  }
  if (!b.factor.compute(ff ? b.IA : b.D, k))
    return fail(HdSolver::E_DEGENERATE_INERTIA,
                "the floating base's articulated inertia is not positive definite: the base and the robot on it have "
                "no mass or inertia along some base direction (ModelOptions::base_inertia, the URDF root link)");
  if (m == 0) return 0;  // free is only needed for the constraint columns' U
  b.free = ff ? BaseVector(-b.pA) : BaseVector(-(S.transpose() * b.pA));
  if (ff_torques.size() != 0) b.free += ff_torques.head(k);
  b.factor.solve(b.free);
  auto A = g.acur.leftCols(m);  // every column, carried to the base (base axes)
  auto e = b.e.leftCols(m);
  if (ff) {
    e = A;
  } else {
    e.noalias() = S.transpose() * A;
  }
  const Vector6 bias = ff ? Vector6(b.free) : Vector6(S * b.free);
  g.ug.head(m).noalias() += A.transpose().lazyProduct(bias);
  auto Y = b.De.leftCols(m);
  Y = e;
  auto K = g.kg.topLeftCorner(m, m);  // one block on a floating base (forEachCouplingBlock); symmetric
  if (ff) {
    Eigen::Map<Matrix6X> Y6(Y.data(), 6, m);  // fixed rows: the loops below unroll
    for (int j = 0; j < 6; ++j) {             // Y <- L^-1 Y, every column at once
      Y6.row(j) *= b.factor.inv(j);
      for (int i = j + 1; i < 6; ++i) Y6.row(i) -= b.factor.L(i, j) * Y6.row(j);
    }
    addGram(Y6, K);
  } else {
    for (int c = 0; c < m; ++c) b.factor.forward(Y.col(c));
    addGram(Y, K);
  }
  ws.kappa += Y.squaredNorm();  // trace of the base's share of K
  if (!ff) {                    // what the world feels: A - U D^-1 e (zero for a free-flyer)
    for (int c = 0; c < m; ++c) b.factor.backward(Y.col(c));  // D^-1 e
    A.noalias() -= b.U.lazyProduct(Y);
    g.ug.head(m).noalias() += A.transpose().lazyProduct(b.a_world);
  }
  return 0;
}

// The base's acceleration given the constraint magnitudes (sorted order), then the joints'.
void HdCore::finalBaseStep(const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  BaseState& b = ws.base;
  const BaseAxes& S = model.S_base;
  const int k = model.nbv, m = res.m;
  const bool ff = model.base == BaseKind::FreeFlyer;  // S = identity (see closeAtBase)
  const Vector6 p = b.pA + b.IA * b.a_world;
  BaseVector qdd = ff ? BaseVector(-p) : BaseVector(-(S.transpose() * p));
  if (ff_torques.size() != 0) qdd += ff_torques.head(k);
  if (m > 0) qdd.noalias() -= b.e.leftCols(m).lazyProduct(ws.general.nug.head(m));
  b.factor.solve(qdd);
  res.qdd.head(k) = qdd;
  b.xdd = ff ? Vector6(b.a_world + qdd) : Vector6(b.a_world + S * qdd);
}

// Response columns (response_columns.cpp) at the base. Inward: each column's apparent force
// change, about its root segment's tip origin in world axes, moved to the base origin in base
// axes; its joint-axis share S^T dp kept, the base's free acceleration change D^-1 (-S^T dp)
// adds e^T of it to the column's energy change (no torque on the base's own rows).
void HdCore::responseBaseInward(long kc) {
  ResponseWorkspace& r = ws.response;
  const BaseState& b = ws.base;
  const int m = res.m;
  for (long c = 0; c < kc; ++c) {
    const double* dp = r.force.col(c).data();
    const Vector3 f(dp[0], dp[1], dp[2]);
    const Vector3 n = Vector3(dp[3], dp[4], dp[5]) + Vector3(r.offset.col(r.holder(c))).cross(f);
    Vector6 dp_base;
    dp_base.head<3>().noalias() = b.X.R.transpose() * f;
    dp_base.tail<3>().noalias() = b.X.R.transpose() * n;
    r.base_sdp.col(c).noalias() = model.S_base.transpose() * dp_base;
    if (m == 0) continue;
    BaseVector dfree = -r.base_sdp.col(c);
    b.factor.solve(dfree);
    r.energy.col(c).head(m).noalias() += b.e.leftCols(m).transpose().lazyProduct(dfree);
  }
}

// Outward: the base's acceleration change of each column, D^-1 (-S^T dp - e dnu), into dqdd's
// base rows, and as the segments' starting acceleration change (world axes, base origin) into
// the pass's accumulator and base_acc (for later root segments).
void HdCore::responseBaseOutward(long c0, long kc, Eigen::Ref<Eigen::MatrixXd> dqdd) {
  ResponseWorkspace& r = ws.response;
  const BaseState& b = ws.base;
  const int m = res.m, k = model.nbv;
  for (long c = 0; c < kc; ++c) {
    BaseVector rhs = -r.base_sdp.col(c);
    if (m > 0) rhs.noalias() -= b.e.leftCols(m).lazyProduct(r.dnu.col(c).head(m));
    b.factor.solve(rhs);
    dqdd.col(c0 + c).head(k) = rhs;
    const Vector6 da = model.S_base * rhs;
    r.base_acc.col(c).head<3>().noalias() = b.X.R * da.head<3>();
    r.base_acc.col(c).tail<3>().noalias() = b.X.R * da.tail<3>();
  }
  r.force.leftCols(kc) = r.base_acc.leftCols(kc);
}

// The several-segment path on a floating base: solveGeneral's steps with the base step between
// the inward sweep and the coupling, and the base's acceleration before the final sweep.
int HdCore::solveFloating(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                          const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
                          const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  res.solved = false;
  res.general = false;
  int rc = checkFloatingInputs(q, q_dot, ff_torques);
  if (rc != 0) return rc;
  const int nj = static_cast<int>(model.nj);
  const auto qj = q.tail(nj), qdj = q_dot.tail(nj);
  const auto ffj = ff_torques.size() != 0 ? ff_torques.tail(nj) : ff_torques.head(0);
  state_q = &q;
  state_q_dot = &q_dot;
  rc = checkInputs(qj, qdj, alfa, beta, f_ext, ffj, mcap);
  if (rc == 0 && ws.pt.weights != nullptr && (ws.pt.weights->f_any || ws.pt.weights->t_any))
    rc = fail(HdSolver::E_INVALID_OPTIONS, "pass-through weights are not supported on a floating base yet");
  if (rc == 0) rc = sortColumns(segments);
  if (rc != 0) return rc;
  res.general = true;
  basePose(q, q_dot);
  outwardSweep(qj, qdj, f_ext);
  if (loads != nullptr) applyFrameLoads();
  rc = inwardSweepGeneral(alfa, ffj);
  if (rc == 0) rc = closeAtBase(ff_torques);
  if (rc != 0) {
    res.general = false;
    return rc;
  }
  ws.pt.used = false;
  factorizeCouplingGeneral();
  CouplingGeneral& g = ws.general;
  const int m = res.m;
  for (int c = 0; c < m; ++c) g.rhs(c) = g.ug(c) - beta(g.order(c));  // nu = K^+ (U - beta)
  couplingSolve(g.rhs.head(m), g.nug.head(m));
  finalBaseStep(ff_torques);
  finalSweepGeneral(ffj);
  for (int c = 0; c < m; ++c) res.nu_user(g.order(c)) = g.nug(c);
  commandFromNuGeneral(g.nug.head(m), res.tau_cmd);
  rc = checkBounded(res.nu_user.head(m), q_dot, beta, f_ext, ff_torques);
  if (rc != 0) return rc;
  res.solved = true;
  return 0;
}

}  // namespace detail
}  // namespace vereshchagin
