// Popov-Vereshchagin hybrid dynamics: implementation. The math and conventions are stated in
// chain_hd_solver.hpp. Notation in the comments: segment i has tip frame i, X_i the pose of frame
// i in frame i-1, S_i the joint axis in frame i, IA_i / pA_i the articulated inertia / bias force,
// A_i the 6 x m constraint wrenches felt by segment i, U (m) the acceleration energy already
// produced by bias forces and torques, L (m x m) the one produced by unit constraint forces.
#include "vereshchagin/chain_hd_solver.hpp"

#include "articulated_step.hpp"
#include "dense_small.hpp"
#include "model_validation.hpp"

#if defined(__GNUC__) && !defined(__clang__)
// GCC 12 reports a false -Warray-bounds on Eigen's SSE loads of 1x1 fixed-size products.
#pragma GCC diagnostic ignored "-Warray-bounds"
#endif

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

namespace vereshchagin {

namespace {

bool allFinite(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  return m.allFinite();
}

Pose toPose(const KDL::Frame& f) {
  Pose X;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) X.R(r, c) = f.M(r, c);
    X.p(r) = f.p(r);
  }
  return X;
}

}  // namespace

ChainHdSolver::ChainHdSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options)
    : chain_(chain), options_(options) {
  setRootAcceleration(root_acc);
  buildModel();
  if (model_error_ == E_NOERROR) {
    const int rc = setOptions(options);
    if (rc != E_NOERROR) model_error_ = rc;
  }
}

void ChainHdSolver::updateInternalDataStructures() {
  buildModel();
}

void ChainHdSolver::setRootAcceleration(const KDL::Twist& root_acc) {
  for (int k = 0; k < 3; ++k) {
    root_acc_(k) = root_acc.vel(k);
    root_acc_(3 + k) = root_acc.rot(k);
  }
}

int ChainHdSolver::setOptions(const SolverOptions& options) {
  if (!std::isfinite(options.rcond) || options.rcond < 0.0 || options.rcond >= 1.0) {
    return fail(E_INVALID_OPTIONS, "options.rcond must be finite and in [0, 1), got %g", options.rcond);
  }
  if (!std::isfinite(options.damping) || options.damping < 0.0 ||
      (options.policy == SingularityPolicy::DampedLeastSquares && options.damping <= 0.0)) {
    return fail(E_INVALID_OPTIONS, "options.damping must be finite and > 0 for the damped least-squares policy, got %g",
                options.damping);
  }
  const bool rebuild = options.inertia_check != options_.inertia_check;
  options_ = options;
  solved_ = false;
  if (rebuild) {
    buildModel();
    return model_error_;
  }
  return E_NOERROR;
}

int ChainHdSolver::fail(int code, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(message_.data(), message_.size(), fmt, args);
  va_end(args);
  error = code;
  return code;
}

const char* ChainHdSolver::strError(const int code) const {
  switch (code) {
    case E_NONFINITE_INPUT:
      return "An input contains NaN or Inf";
    case E_INVALID_MODEL:
      return "The chain's physical parameters are invalid";
    case E_DEGENERATE_INERTIA:
      return "A joint has zero articulated inertia";
    case E_TOO_MANY_CONSTRAINTS:
      return "More than 6 constraints on one segment";
    case E_NO_SOLUTION:
      return "No successful solve to take the response from";
    case E_INVALID_OPTIONS:
      return "Invalid solver options";
    case E_NONFINITE_RESULT:
      return "The results overflow (inputs too large)";
    default:
      return KDL::SolverI::strError(code);
  }
}

void ChainHdSolver::buildModel() {
  model_error_ = E_NOERROR;
  message_[0] = '\0';
  solved_ = false;
  nj_ = chain_.getNrOfJoints();
  ns_ = chain_.getNrOfSegments();
  segs_.assign(ns_, Segment());
  joint_segment_.assign(nj_, 0);
  qdd_ = Eigen::VectorXd::Zero(nj_);
  tau_cmd_ = Eigen::VectorXd::Zero(nj_);
  zero_joints_ = Eigen::VectorXd::Zero(nj_);
  col_sdp_ = Eigen::MatrixXd::Zero(ns_, nj_);
  col_s0_ = col_u0_ = Matrix6X::Zero(6, ns_);
  col_offset_ = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, ns_);
  col_force_ = Matrix6X::Zero(6, std::max<unsigned int>(nj_, kMaxConstraints));
  col_row_ = Eigen::VectorXd::Zero(nj_);
  col_tmp3_ = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, std::max<unsigned int>(nj_, kMaxConstraints));
  link_acc_ = Matrix6X::Zero(6, ns_ + 1);
  link_acc_known_ = true;  // zeros until the first solve
  f_ext_buf_ = Matrix6X::Zero(6, ns_);
  zero_f_ext_ = Matrix6X::Zero(6, ns_);
  alfa_buf_.setZero();
  mcap_ = std::max<int>(kMaxConstraints, kMaxConstraints * static_cast<int>(ns_));
  pt_f_ = pt_t_ = pt_energy_ = pt_tmp_ = Eigen::VectorXd::Zero(mcap_);
  pt_free_ = Eigen::VectorXd::Zero(nj_);
  pt_m_ = -1;  // weights are per column of a model: cleared with it
  pt_f_any_ = pt_t_any_ = pt_used_ = false;
  general_ = false;
  order_ = Eigen::VectorXi::Zero(mcap_);
  seg_count_ = Eigen::VectorXi::Zero(ns_);
  active_.assign(ns_ + 1, 0);
  anew_ = acur_ = aproj_ = Matrix6X::Zero(6, mcap_);
  eg_ = Eigen::MatrixXd::Zero(mcap_, std::max<unsigned int>(ns_, 1));
  ug_ = nug_ = nu_user_ = rhs_g_ = tmp_g_ = invg_ = Eigen::VectorXd::Zero(mcap_);
  kg_ = cholg_ = vg_ = work_g_ = work_v_ = Eigen::MatrixXd::Zero(mcap_, mcap_);
  cmd_per_nu_ = Eigen::MatrixXd::Zero(nj_, mcap_);
  col_energy_ = Eigen::MatrixXd::Zero(mcap_, nj_);
  col_nu_ = Eigen::MatrixXd::Zero(mcap_, nj_);
  m_ = 0;
  rank_ = 0;
  sigma_min_ = 0.0;
  sigma_known_ = true;

  double scale = 0.0;  // typical size of a joint inertia, for the degeneracy tolerance
  unsigned int j = 0;
  for (unsigned int i = 0; i < ns_; ++i) {
    const KDL::Segment& seg = chain_.getSegment(i);
    const KDL::Joint& joint = seg.getJoint();
    Segment& s = segs_[i];
    if (const char* why = detail::segmentGeometryProblem(seg)) {
      model_error_ = fail(E_INVALID_MODEL, "segment %u ('%s'): %s", i, seg.getName().c_str(), why);
      return;
    }
    const KDL::RigidBodyInertia& rbi = seg.getInertia();
    const double mass = rbi.getMass();
    const KDL::Vector cog = rbi.getCOG();
    const KDL::RotationalInertia Io = rbi.getRotationalInertia();  // about the tip origin
    Vector3 c(cog.x(), cog.y(), cog.z());
    Matrix3 I_origin = Eigen::Map<const Matrix3>(Io.data);
    if (!c.allFinite()) {
      model_error_ =
          fail(E_INVALID_MODEL, "segment %u ('%s'): non-finite inertial parameters", i, seg.getName().c_str());
      return;
    }
    // Rotational inertia about the centre of mass, checked as options_.inertia_check says.
    const Matrix3 Sc = skew(c);
    const Matrix3 I_com = I_origin + mass * Sc * Sc;
    std::array<char, 320> why_buf{};
    if (const char* why = detail::inertiaProblem(mass, I_com, options_.inertia_check, why_buf.data(), why_buf.size())) {
      model_error_ = fail(E_INVALID_MODEL, "segment %u ('%s'): %s", i, seg.getName().c_str(), why);
      return;
    }
    s.I = rigidInertia(mass, c, 0.5 * (I_origin + I_origin.transpose()));
    scale += I_com.cwiseAbs().trace() +
             mass * (c.squaredNorm() + seg.getFrameToTip().p.Norm() * seg.getFrameToTip().p.Norm());
    s.X0 = toPose(seg.pose(0.0));
    if (joint.getType() == KDL::Joint::Fixed) {
      s.joint = -1;
      s.S.setZero();
    } else {
      joint_segment_[j] = static_cast<int>(i);
      s.joint = static_cast<int>(j++);
      s.rotor = joint.getInertia();
      if (!std::isfinite(s.rotor) || s.rotor < 0.0) {
        model_error_ = fail(E_INVALID_MODEL, "joint %d ('%s'): rotor inertia must be >= 0, got %g", s.joint,
                            joint.getName().c_str(), s.rotor);
        return;
      }
      scale += s.rotor;
      // The joint axis is fixed in the child body, so in the tip frame it does not depend on q.
      const KDL::Twist t = seg.twist(0.0, 1.0);            // root axes, tip reference point
      const KDL::Rotation Rt = seg.pose(0.0).M.Inverse();  // root axes -> tip axes
      const KDL::Vector v = Rt * t.vel, w = Rt * t.rot;
      s.S << v.x(), v.y(), v.z(), w.x(), w.y(), w.z();
      s.w_norm = s.S.tail<3>().norm();
      s.v2 = s.S.head<3>().squaredNorm();
      s.w2 = s.S.tail<3>().squaredNorm();
      if (!s.S.allFinite() || s.S.norm() == 0.0) {
        model_error_ = fail(E_INVALID_MODEL, "joint %d ('%s'): joint axis is zero or not finite", s.joint,
                            joint.getName().c_str());
        return;
      }
    }
  }
  d_tolerance_ = 1e-13 * std::max(scale, std::numeric_limits<double>::min());

  // Reject chains whose joints have no inertia to move. Checked at a generic configuration (not
  // q = 0, where a body may sit on an axis by coincidence); a configuration-dependent loss of
  // inertia is reported by solve().
  Eigen::VectorXd q_generic(nj_);
  for (unsigned int k = 0; k < nj_; ++k) q_generic(k) = 0.7 + 0.61 * k;
  outwardSweep(q_generic, zero_joints_, zero_f_ext_);
  const int rc = inwardSweep(alfa_buf_.leftCols(0), zero_joints_);
  if (rc != E_NOERROR) model_error_ = rc;
}

int ChainHdSolver::checkInputs(const Eigen::Ref<const Eigen::VectorXd>& q,
                               const Eigen::Ref<const Eigen::VectorXd>& q_dot, const Eigen::Ref<const Matrix6X>& alfa,
                               const Eigen::Ref<const Eigen::VectorXd>& beta, const Eigen::Ref<const Matrix6X>& f_ext,
                               const Eigen::Ref<const Eigen::VectorXd>& ff_torques, int max_columns) {
  if (model_error_ != E_NOERROR) {
    error = model_error_;
    return model_error_;  // message_ still holds the model's problem
  }
  const long nj = nj_, ns = ns_;
  if (q.size() != nj) return fail(E_SIZE_MISMATCH, "q has %ld entries, expected %ld (joints)", (long)q.size(), nj);
  if (q_dot.size() != nj)
    return fail(E_SIZE_MISMATCH, "q_dot has %ld entries, expected %ld (joints)", (long)q_dot.size(), nj);
  if (ff_torques.size() != nj && ff_torques.size() != 0)
    return fail(E_SIZE_MISMATCH, "ff_torques has %ld entries, expected %ld (joints) or 0", (long)ff_torques.size(), nj);
  if (f_ext.cols() != ns && f_ext.cols() != 0)
    return fail(E_SIZE_MISMATCH, "f_ext has %ld wrenches, expected %ld (segments) or 0", (long)f_ext.cols(), ns);
  if (alfa.cols() > max_columns)
    return fail(E_TOO_MANY_CONSTRAINTS, "alfa has %ld columns, at most %d constraints are supported", (long)alfa.cols(),
                max_columns);
  if (beta.size() != alfa.cols())
    return fail(E_SIZE_MISMATCH, "beta has %ld entries, expected %ld (one per alfa column)", (long)beta.size(),
                (long)alfa.cols());
  if (!allFinite(q)) return fail(E_NONFINITE_INPUT, "q contains NaN or Inf");
  if (!allFinite(q_dot)) return fail(E_NONFINITE_INPUT, "q_dot contains NaN or Inf");
  if (!allFinite(ff_torques)) return fail(E_NONFINITE_INPUT, "ff_torques contains NaN or Inf");
  if (!allFinite(f_ext)) return fail(E_NONFINITE_INPUT, "f_ext contains NaN or Inf");
  if (!allFinite(alfa)) return fail(E_NONFINITE_INPUT, "alfa contains NaN or Inf");
  if (!allFinite(beta)) return fail(E_NONFINITE_INPUT, "beta contains NaN or Inf");
  if (!root_acc_.allFinite()) return fail(E_NONFINITE_INPUT, "root acceleration contains NaN or Inf");
  return E_NOERROR;
}

// Pose of the tip frame at joint position q: the tip moves by the screw motion exp(q S) of its
// own joint axis (constant in the tip frame), so X(q) = X(0) * exp(q [S]) with, for S = [v; w]
// and theta = |w| q, unit axis k = w / |w|:  E.R = Rodrigues(k, theta),
// E.p = (I - E.R) (k x v) / |w| + k (k . v) q;  for |w| = 0 (prismatic) E = (I, v q).
void ChainHdSolver::screwPose(Segment& s, double q) const {
  const Vector3 v = s.S.head<3>();
  if (s.w_norm == 0.0) {
    s.X.R = s.X0.R;
    s.X.p.noalias() = s.X0.p + s.X0.R * (v * q);
    return;
  }
  const Vector3 k = s.S.tail<3>() / s.w_norm;
  const double theta = s.w_norm * q;
  const double sn = std::sin(theta), c1 = 1.0 - std::cos(theta);
  const Matrix3 K = skew(k);
  const Matrix3 KK = K * K;
  Matrix3 R = Matrix3::Identity();
  R.noalias() += sn * K + c1 * KK;
  // (I - R) = -(sn K + c1 KK), applied to k x v / |w|.
  const Vector3 kxv = k.cross(v) / s.w_norm;
  Vector3 p;
  p.noalias() = -(sn * (K * kxv) + c1 * (KK * kxv));
  p.noalias() += k * (k.dot(v) * q);
  s.X.R.noalias() = s.X0.R * R;
  s.X.p.noalias() = s.X0.p + s.X0.R * p;
}

// Outward sweep: poses, velocities, velocity-product accelerations, rigid bias forces.
void ChainHdSolver::outwardSweep(const Eigen::Ref<const Eigen::VectorXd>& q,
                                 const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                                 const Eigen::Ref<const Matrix6X>& f_ext) {
  Vector6 v_parent = Vector6::Zero();
  Matrix3 R_parent = Matrix3::Identity();
  const bool has_fext = f_ext.cols() != 0;
  for (unsigned int i = 0; i < ns_; ++i) {
    Segment& s = segs_[i];
    if (s.joint >= 0) {
      screwPose(s, q(s.joint));
    } else {
      s.X = s.X0;
    }
    s.R_base.noalias() = R_parent * s.X.R;
    s.v = motionToChild(s.X, v_parent);
    if (s.joint >= 0) {
      const Vector6 vj = s.S * q_dot(s.joint);
      s.v += vj;
      s.c = crossMotion(s.v, vj);
    } else {
      s.c.setZero();
    }
    s.pA = crossForce(s.v, s.I * s.v);
    if (has_fext) {
      // f_ext: base axes, moment about this tip's origin -> tip axes.
      s.pA.head<3>().noalias() -= s.R_base.transpose() * f_ext.col(i).head<3>();
      s.pA.tail<3>().noalias() -= s.R_base.transpose() * f_ext.col(i).tail<3>();
    }
    s.IA = s.I;
    v_parent = s.v;
    R_parent = s.R_base;
  }
}

// Inward sweep: articulated inertias and bias forces, constraint wrenches felt by each segment,
// acceleration-energy contributions U and L. Templated on the constraint count so that the
// per-segment constraint algebra runs on fixed-size blocks.
int ChainHdSolver::inwardSweep(const Eigen::Ref<const Matrix6X>& alfa,
                               const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  switch (alfa.cols()) {
    case 0:
      return inwardSweepT<0>(alfa, ff_torques);
    case 1:
      return inwardSweepT<1>(alfa, ff_torques);
    case 2:
      return inwardSweepT<2>(alfa, ff_torques);
    case 3:
      return inwardSweepT<3>(alfa, ff_torques);
    case 4:
      return inwardSweepT<4>(alfa, ff_torques);
    case 5:
      return inwardSweepT<5>(alfa, ff_torques);
    default:
      return inwardSweepT<6>(alfa, ff_torques);
  }
}

template <int M>
int ChainHdSolver::inwardSweepT(const Eigen::Ref<const Matrix6X>& alfa,
                                const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  using VecM = Eigen::Matrix<double, M, 1>;
  using MatM = Eigen::Matrix<double, M, M>;
  using Mat6M = Eigen::Matrix<double, 6, M>;
  m_ = M;
  VecM U = VecM::Zero();
  MatM L = MatM::Zero();
  double kappa = 0.0;
  if (ns_ > 0 && M > 0) {
    // alfa: base axes -> last tip axes (moment reference point is already the tip origin).
    Segment& last = segs_[ns_ - 1];
    last.A.template topLeftCorner<3, M>().noalias() = last.R_base.transpose() * alfa.template topLeftCorner<3, M>();
    last.A.template bottomLeftCorner<3, M>().noalias() =
        last.R_base.transpose() * alfa.template bottomLeftCorner<3, M>();
  }
  const bool has_tau = ff_torques.size() != 0;
  for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) {
    Segment& s = segs_[i];
    Vector6 pa;
    Mat6M Aproj;  // constraint wrenches passed to the parent
    const auto A = s.A.template leftCols<M>();
    if (s.joint >= 0) {
      double free = 0.0;
      if (!articulate(s, has_tau ? ff_torques(s.joint) : 0.0, pa, free)) return degenerate(i);
      if (M > 0) {
        auto e = s.e.template leftCols<M>();  // S^T A, kept for the final sweep
        e.noalias() = s.S.transpose() * A;
        U.noalias() += A.transpose() * (s.c + s.S * free);
        L.noalias() -= s.Dinv * e.transpose() * e;
        // |e_c| = |v.f_c + w.n_c| <= |v||f_c| + |w||n_c|, so sum_c e_c^2 <= 2 (|v|^2 |F|^2 +
        // |w|^2 |N|^2): a bound in consistent units (|S|^2 |A|^2 would mix N with N m and
        // inflate at small lengths), without square roots in the sweep.
        kappa += 2.0 * s.Dinv *
                 (s.v2 * A.template topRows<3>().squaredNorm() + s.w2 * A.template bottomRows<3>().squaredNorm());
        Aproj = A;
        Aproj.noalias() -= s.Dinv * s.u * e;
      }
    } else {
      pa = s.pA;  // rigid attachment: no joint freedom, no velocity product
      if (M > 0) Aproj = A;
    }
    if (i > 0) {
      passToParent(i, pa);
      Segment& p = segs_[i - 1];
      if (M > 0) {
        // Constraint wrenches to the parent frame, all columns at once: f = R f', n = R n' + p x f.
        auto top = p.A.template topLeftCorner<3, M>();
        auto bottom = p.A.template bottomLeftCorner<3, M>();
        top.noalias() = s.X.R * Aproj.template topRows<3>();
        bottom.noalias() = s.X.R * Aproj.template bottomRows<3>();
        bottom.noalias() += skew(s.X.p) * top;
      }
    } else if (M > 0) {
      // Constraint wrenches at the base frame: the balance uses A_0^T Xdd_0.
      Mat6M A0;
      A0.template topRows<3>().noalias() = s.X.R * Aproj.template topRows<3>();
      A0.template bottomRows<3>().noalias() = s.X.R * Aproj.template bottomRows<3>();
      A0.template bottomRows<3>().noalias() += skew(s.X.p) * A0.template topRows<3>();
      U.noalias() += A0.transpose() * root_acc_;
    }
  }
  U0_ = U;
  L0_ = L;
  kappa_ = kappa;
  return E_NOERROR;
}

// Finite inputs can still overflow (|q_dot| ~ 1e160 squares to Inf): never return Inf or NaN,
// nor results beyond kMaxResult whose products (energies, powers) would overflow. An overflowing
// coupling matrix (kappa >= trace K; e.g. alfa columns of size 1e200) would be truncated to rank 0,
// silently dropping the task. Inf and NaN propagate outward through the link accelerations: the
// last one tells.
int ChainHdSolver::checkBounded(const Eigen::Ref<const Eigen::VectorXd>& nu,
                                const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                                const Eigen::Ref<const Eigen::VectorXd>& beta, const Eigen::Ref<const Matrix6X>& f_ext,
                                const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  bool finite = std::isfinite(kappa_) && detail::bounded(qdd_) && detail::bounded(tau_cmd_) && detail::bounded(nu);
  if (finite && ns_ > 0) finite = detail::bounded(segs_[ns_ - 1].xdd);
  if (finite) return E_NOERROR;
  return fail(E_NONFINITE_RESULT,
              "the results overflow (Inf/NaN or beyond 1e150): inputs too large (max |q_dot| %g, "
              "max |ff_torques| %g, max |f_ext| %g, max |beta| %g)",
              q_dot.size() ? q_dot.cwiseAbs().maxCoeff() : 0.0,
              ff_torques.size() ? ff_torques.cwiseAbs().maxCoeff() : 0.0,
              f_ext.size() ? f_ext.cwiseAbs().maxCoeff() : 0.0, beta.size() ? beta.cwiseAbs().maxCoeff() : 0.0);
}

int ChainHdSolver::degenerate(int i) {
  const Segment& s = segs_[i];
  const char* name = chain_.getSegment(i).getJoint().getName().c_str();
  if (options_.inertia_check == InertiaCheck::JointSpace && s.D < 0.0)
    return fail(E_DEGENERATE_INERTIA,
                "joint %d ('%s') has articulated inertia D = %g <= 0 at this configuration: the model's "
                "joint-space inertia matrix is not positive definite here (inertia_check = joint_space "
                "accepts non-physical link inertias only where it is)",
                s.joint, name, s.D);
  return fail(E_DEGENERATE_INERTIA,
              "joint %d ('%s') has zero articulated inertia (%g): the bodies it moves have no "
              "mass or inertia about its axis and it has no rotor inertia",
              s.joint, name, s.D);
}

// Final outward sweep of the end-segment path: the constraint forces through S^T A_i = e_i.
template <int M>
void ChainHdSolver::finalSweepT(const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  Eigen::Matrix<double, M, 1> nu;
  if (M > 0) nu = nu_;
  finalSweep(ff_torques,
             [&nu](int, const Segment& s) { return M > 0 ? s.e.template leftCols<M>().dot(nu.transpose()) : 0.0; });
}

void ChainHdSolver::factorizeCoupling() {
  const int m = m_;
  rank_ = 0;
  sigma_known_ = false;
  use_cholesky_ = false;
  if (m == 0) return;
  K_ = -L0_;  // symmetric positive semi-definite
  if (options_.policy == SingularityPolicy::TruncatedPseudoInverse && choleskyFullRank()) {
    use_cholesky_ = true;
    rank_ = m;
    return;
  }
  eig_.compute(K_);
  inv_eigen_.setZero(m);
  const auto& lam = eig_.eigenvalues();  // ascending
  const double cut = options_.rcond * std::max(std::max(lam(m - 1), 0.0), kappa_);
  sigma_min_ = std::max(lam(0), 0.0);
  sigma_known_ = true;
  rank_ = detail::policyMultipliers(lam, inv_eigen_, cut, options_.policy == SingularityPolicy::TruncatedPseudoInverse,
                                    options_.damping);
}

// Cholesky factor K = L L^T (into chol_), and a proof that every eigenvalue of K is above the
// truncation threshold rcond * max(lambda_max, kappa) = rcond * kappa: lambda_min(K) =
// 1 / ||L^-1||_2^2 >= 1 / ||L^-1||_F^2 and lambda_max(K) <= trace(K) <= kappa. False if the
// factorisation breaks down or the proof fails.
bool ChainHdSolver::choleskyFullRank() {
  const int m = m_;
  chol_.setZero(m, m);
  if (!detail::choleskyCertified(K_, chol_, 0.0)) return false;
  VectorC x(m);
  const double lower = 1.0 / detail::inverseFrobeniusSquared(chol_, x);
  return std::isfinite(lower) && lower > options_.rcond * kappa_;
}

double ChainHdSolver::smallestSingularValue() const {
  if (!sigma_known_) {
    if (m_ == 0) {
      sigma_min_ = 0.0;
    } else if (general_) {
      auto W = work_g_.topLeftCorner(m_, m_);
      auto V = work_v_.topLeftCorner(m_, m_);
      W = kg_.topLeftCorner(m_, m_);
      detail::jacobiEigen(W, V);
      sigma_min_ = std::max(W.diagonal().minCoeff(), 0.0);
    } else {
      sigma_eig_.compute(K_, Eigen::EigenvaluesOnly);
      sigma_min_ = std::max(sigma_eig_.eigenvalues()(0), 0.0);
    }
    sigma_known_ = true;
  }
  return sigma_min_;
}

void ChainHdSolver::applyCouplingInverse(const VectorC& rhs, VectorC& out) const {
  const int m = m_;
  if (m == 0) {
    out.resize(0);
    return;
  }
  if (use_cholesky_) {
    out = rhs;  // K out = rhs with K = L L^T
    detail::choleskySolve(chol_, out);
    return;
  }
  VectorC t;
  t.noalias() = eig_.eigenvectors().transpose() * rhs;
  t.array() *= inv_eigen_.array();
  out.noalias() = eig_.eigenvectors() * t;
}

// tau_cmd = -J^T alfa nu: the wrench -A_N nu on the last segment carried rigidly to each joint.
void ChainHdSolver::commandFromNu(const VectorC& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) const {
  tau_cmd.setZero();
  if (m_ == 0 || ns_ == 0) return;
  Vector6 f;
  f.noalias() = -(segs_[ns_ - 1].A.leftCols(m_) * nu);
  // segs_[ns_-1].A was overwritten by nothing: the last segment's A is alfa in tip axes.
  for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) {
    const Segment& s = segs_[i];
    if (s.joint >= 0) tau_cmd(s.joint) = s.S.dot(f);
    if (i > 0) f = forceToParent(s.X, f);
  }
}

int ChainHdSolver::commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) {
  if (!solved_) return fail(E_NO_SOLUTION, "commandTorquesOf() needs a successful solve() first");
  if (nu.size() != m_ || tau_cmd.size() != nj_)
    return fail(E_SIZE_MISMATCH, "nu has %ld entries and tau_cmd %ld, expected %d and %u", (long)nu.size(),
                (long)tau_cmd.size(), m_, nj_);
  if (general_) {
    for (int c = 0; c < m_; ++c) tmp_g_(c) = nu(order_(c));  // sorted order
    commandFromNuGeneral(tmp_g_.head(m_), tau_cmd);
  } else {
    const VectorC v = nu;
    commandFromNu(v, tau_cmd);
  }
  return E_NOERROR;
}

int ChainHdSolver::solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                         const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                         const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  solved_ = false;
  general_ = false;
  int rc = checkInputs(q, q_dot, alfa, beta, f_ext, ff_torques, kMaxConstraints);
  if (rc != E_NOERROR) return rc;
  outwardSweep(q, q_dot, f_ext);
  rc = inwardSweep(alfa, ff_torques);
  if (rc != E_NOERROR) return rc;
  rc = passThroughEnergy(f_ext, ff_torques);
  if (rc != E_NOERROR) return rc;

  // Balance of acceleration energy at the base: A_0^T Xdd_0 + U_0 + L_0 nu = beta.
  factorizeCoupling();
  const int m = m_;
  VectorC rhs = U0_ - beta;                 // nu = L0^-1 (beta - U0) = K^+ (U0 - beta), K = -L0
  if (pt_used_) rhs -= pt_energy_.head(m);  // the drivers' parts that pass through
  applyCouplingInverse(rhs, nu_);

  switch (m) {
    case 0:
      finalSweepT<0>(ff_torques);
      break;
    case 1:
      finalSweepT<1>(ff_torques);
      break;
    case 2:
      finalSweepT<2>(ff_torques);
      break;
    case 3:
      finalSweepT<3>(ff_torques);
      break;
    case 4:
      finalSweepT<4>(ff_torques);
      break;
    case 5:
      finalSweepT<5>(ff_torques);
      break;
    default:
      finalSweepT<6>(ff_torques);
      break;
  }
  commandFromNu(nu_, tau_cmd_);
  rc = checkBounded(nu_, q_dot, beta, f_ext, ff_torques);
  if (rc != E_NOERROR) return rc;
  solved_ = true;
  error = E_NOERROR;
  return E_NOERROR;
}

int ChainHdSolver::CartToJnt(const KDL::JntArray& q, const KDL::JntArray& q_dot, KDL::JntArray& q_dotdot,
                             const KDL::Jacobian& alfa, const KDL::JntArray& beta, const KDL::Wrenches& f_ext,
                             const KDL::JntArray& ff_torques, KDL::JntArray& command_torques) {
  if (q_dotdot.rows() != nj_)
    return fail(E_SIZE_MISMATCH, "q_dotdot has %u entries, expected %u", q_dotdot.rows(), nj_);
  if (command_torques.rows() != nj_)
    return fail(E_SIZE_MISMATCH, "command_torques has %u entries, expected %u", command_torques.rows(), nj_);
  if (f_ext.size() != ns_)
    return fail(E_SIZE_MISMATCH, "f_ext has %zu wrenches, expected %u (segments)", f_ext.size(), ns_);
  if (ff_torques.rows() != nj_)
    return fail(E_SIZE_MISMATCH, "ff_torques has %u entries, expected %u", ff_torques.rows(), nj_);
  for (unsigned int i = 0; i < ns_; ++i) {
    for (int k = 0; k < 3; ++k) {
      f_ext_buf_(k, i) = f_ext[i].force(k);
      f_ext_buf_(3 + k, i) = f_ext[i].torque(k);
    }
  }
  const int rc = solve(q.data, q_dot.data, alfa.data, beta.data, f_ext_buf_, ff_torques.data);
  if (rc != E_NOERROR) return rc;
  q_dotdot.data = qdd_;
  command_torques.data = tau_cmd_;
  return E_NOERROR;
}

// Link accelerations in base axes, computed from the tip-frame ones on first request.
const ChainHdSolver::Matrix6X& ChainHdSolver::linkAccelerations() const {
  if (!link_acc_known_) {
    link_acc_.col(0) = root_acc_;
    for (unsigned int i = 0; i < ns_; ++i) {
      const Segment& s = segs_[i];
      link_acc_.col(i + 1).head<3>().noalias() = s.R_base * s.xdd.head<3>();
      link_acc_.col(i + 1).tail<3>().noalias() = s.R_base * s.xdd.tail<3>();
    }
    link_acc_known_ = true;
  }
  return link_acc_;
}

namespace {
KDL::Twist toTwist(const Vector6& v) {
  return KDL::Twist(KDL::Vector(v(0), v(1), v(2)), KDL::Vector(v(3), v(4), v(5)));
}
}  // namespace

KDL::Frame ChainHdSolver::linkLocalPose(unsigned int i) const {
  const Pose& X = segs_[i].X;
  return KDL::Frame(
      KDL::Rotation(X.R(0, 0), X.R(0, 1), X.R(0, 2), X.R(1, 0), X.R(1, 1), X.R(1, 2), X.R(2, 0), X.R(2, 1), X.R(2, 2)),
      KDL::Vector(X.p(0), X.p(1), X.p(2)));
}

KDL::Twist ChainHdSolver::linkLocalVelocity(unsigned int i) const {
  return toTwist(segs_[i].v);
}

KDL::Twist ChainHdSolver::linkLocalAcceleration(unsigned int i) const {
  return toTwist(segs_[i].xdd);
}

void ChainHdSolver::getTransformedLinkAcceleration(std::vector<KDL::Twist>& x_dotdot) const {
  x_dotdot.resize(ns_ + 1);
  for (unsigned int i = 0; i <= ns_; ++i) {
    const auto a = linkAccelerations().col(i);
    x_dotdot[i] = KDL::Twist(KDL::Vector(a(0), a(1), a(2)), KDL::Vector(a(3), a(4), a(5)));
  }
}

int ChainHdSolver::responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                                   Eigen::Ref<Eigen::MatrixXd> dtau_cmd) {
  return responseColumnsImpl(joints, dqdd, dtau_cmd, nullptr);
}

int ChainHdSolver::responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                                   Eigen::Ref<Eigen::MatrixXd> dtau_cmd, Eigen::Ref<Eigen::MatrixXd> dnu) {
  if (solved_ && (dnu.rows() < m_ || dnu.cols() < joints.size()))
    return fail(E_SIZE_MISMATCH, "dnu is %ldx%ld, expected at least %dx%ld", (long)dnu.rows(), (long)dnu.cols(), m_,
                (long)joints.size());
  return responseColumnsImpl(joints, dqdd, dtau_cmd, &dnu);
}

int ChainHdSolver::responseColumnsImpl(const Eigen::Ref<const Eigen::VectorXi>& joints,
                                       Eigen::Ref<Eigen::MatrixXd> dqdd, Eigen::Ref<Eigen::MatrixXd> dtau_cmd,
                                       Eigen::Ref<Eigen::MatrixXd>* dnu_out) {
  if (!solved_) return fail(E_NO_SOLUTION, "responseColumns() needs a successful solve() first");
  const long k = joints.size();
  if (dqdd.rows() != nj_ || dqdd.cols() != k)
    return fail(E_SIZE_MISMATCH, "dqdd is %ldx%ld, expected %ux%ld", (long)dqdd.rows(), (long)dqdd.cols(), nj_, k);
  const bool want_tau = !(dnu_out && dtau_cmd.size() == 0);  // empty beside dnu: not wanted
  if (want_tau && (dtau_cmd.rows() != nj_ || dtau_cmd.cols() != k))
    return fail(E_SIZE_MISMATCH, "dtau_cmd is %ldx%ld, expected %ux%ld", (long)dtau_cmd.rows(), (long)dtau_cmd.cols(),
                nj_, k);
  for (long c = 0; c < k; ++c) {
    if (joints(c) < 0 || joints(c) >= static_cast<int>(nj_))
      return fail(E_OUT_OF_RANGE, "joint index %d out of range [0, %u)", joints(c), nj_);
  }
  const int m = m_;
  // d tau_cmd / d nu, one column per constraint; the end-segment path's S^T A rows into eg_ so
  // that both paths share the sweeps below.
  if (!want_tau) {
    // d tau_cmd / d nu not needed
  } else if (general_) {
    for (int r = 0; r < m; ++r) {
      rhs_g_.head(m).setZero();
      rhs_g_(r) = 1.0;
      commandFromNuGeneral(rhs_g_.head(m), cmd_per_nu_.col(r));
    }
  } else if (m > 0) {
    // The m wrenches -A_N carried rigidly to each joint together: row j of -J^T alfa.
    auto F = col_force_.leftCols(m);
    F = -segs_[ns_ - 1].A.leftCols(m);
    for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) {
      const Segment& s = segs_[i];
      if (s.joint >= 0) cmd_per_nu_.row(s.joint).head(m).noalias() = s.S.transpose().lazyProduct(F);
      if (i > 0) {  // f = R f', n = R n' + p x f
        col_tmp3_.leftCols(m).noalias() = s.X.R.lazyProduct(F.topRows<3>());
        F.topRows<3>() = col_tmp3_.leftCols(m);
        col_tmp3_.leftCols(m).noalias() = s.X.R.lazyProduct(F.bottomRows<3>());
        F.bottomRows<3>() = col_tmp3_.leftCols(m);
        F.bottomRows<3>().noalias() += skew(s.X.p).lazyProduct(F.topRows<3>());
      }
    }
  }
  if (!general_ && m > 0)
    for (unsigned int i = 0; i < ns_; ++i) eg_.col(i).head(m) = segs_[i].e.leftCols(m).transpose();
  // Joint axes S and u = IA S of every segment in base axes (about the segment's own tip origin),
  // and each tip origin's offset from its parent's, in base axes: the column sweeps then change
  // only the reference point between segments (a cross product), never the axes. (About one fixed
  // point, the base origin, even that would go, but moments grow with the chain's distance from
  // it and square in the products: precision is lost and a 1e150 m chain overflows.)
  {
    Matrix3 R_parent = Matrix3::Identity();
    for (unsigned int i = 0; i < ns_; ++i) {
      const Segment& s = segs_[i];
      col_offset_.col(i).noalias() = R_parent * s.X.p;
      R_parent = s.R_base;
      if (s.joint < 0) continue;
      auto S0 = col_s0_.col(i);
      auto u0 = col_u0_.col(i);
      S0.head<3>().noalias() = s.R_base * s.S.head<3>();
      S0.tail<3>().noalias() = s.R_base * s.S.tail<3>();
      u0.head<3>().noalias() = s.R_base * s.u.head<3>();
      u0.tail<3>().noalias() = s.R_base * s.u.tail<3>();
    }
  }
  // All columns at once, in chunks of at most n_joints (the workspace width): a unit torque at
  // joint joints(c) changes only the force part of the sweeps; bodies distal to it feel nothing.
  for (long c0 = 0; c0 < k; c0 += nj_) {
    const long kc = std::min<long>(nj_, k - c0);
    auto DP = col_force_.leftCols(kc);  // apparent bias-force change passed to the parent (6 x kc)
    auto DU = col_energy_.topLeftCorner(m, kc);
    DU.setZero();
    // A unit torque at joint j changes nothing distal to it: in the inward pass its column is
    // zero on segments after j's. With the joints in chain order, the columns
    // alive at segment i are a suffix [lo, kc) that grows towards the base (the friction solver
    // asks in that order); otherwise every column is processed everywhere.
    bool ascending = true;
    for (long c = 1; c < kc; ++c)
      ascending = ascending && joint_segment_[joints(c0 + c)] >= joint_segment_[joints(c0 + c - 1)];
    // Per column, fixed-size 6-vector arithmetic (robust to the compiler's inlining budget), in
    // base axes (S0, u0 above): between segments only the reference point moves.
    long lo = ascending ? kc : 0;
    auto SDP = col_sdp_.leftCols(kc);  // S_i^T (apparent force change from the child), per segment
    const int m_rows = m;
    for (int i = static_cast<int>(ns_) - 1; i >= 0; --i) {
      const Segment& s = segs_[i];
      const long lo_child = lo;
      if (ascending)
        while (lo > 0 && joint_segment_[joints(c0 + lo - 1)] >= i) --lo;
      const bool last = i == static_cast<int>(ns_) - 1;
      const Vector3 offset_child = last ? Vector3::Zero() : Vector3(col_offset_.col(i + 1));
      const double* eg = eg_.col(i).data();
      const Eigen::Map<const Vector6> S0(col_s0_.col(i).data()), u0(col_u0_.col(i).data());
      for (long c = 0; c < kc; ++c) {
        if (c < lo) {  // not alive yet: no force change here
          SDP(i, c) = 0.0;
          continue;
        }
        // Force part f and moment part n as separate 3-vectors: a 6-vector updated in its top half
        // and reloaded whole stalls on store forwarding.
        double* dp = DP.col(c).data();
        Vector3 f = Vector3::Zero(), n = Vector3::Zero();  // becomes alive here (or the last segment)
        if (!(last || c < lo_child)) {  // the child's apparent force about this tip origin: n += d x f
          f = Vector3(dp[0], dp[1], dp[2]);
          n = Vector3(dp[3], dp[4], dp[5]) + offset_child.cross(f);
        }
        double r = 0.0;
        if (s.joint >= 0) {
          const double sd = S0.head<3>().dot(f) + S0.tail<3>().dot(n);
          SDP(i, c) = sd;
          r = ((joints(c0 + c) == s.joint ? 1.0 : 0.0) - sd) * s.Dinv;  // free joint acc change
          f += u0.head<3>() * r;
          n += u0.tail<3>() * r;
        } else {
          SDP(i, c) = 0.0;
        }
        for (int t = 0; t < 3; ++t) dp[t] = f(t), dp[3 + t] = n(t);
        if (s.joint < 0) continue;
        double* du = DU.col(c).data();
        for (int t = 0; t < m_rows; ++t) du[t] += eg[t] * r;
      }
    }
    auto DNU = col_nu_.topLeftCorner(m, kc);
    if (use_cholesky_ && m > 0) {  // d nu = K^-1 dU, all columns through one factor
      DNU = DU;
      if (general_) {
        detail::choleskySolveColumns(cholg_.topLeftCorner(m, m), DNU);
      } else {
        detail::choleskySolveColumns(chol_, DNU);
      }
    }
    for (long c = 0; c < kc; ++c) {
      if (!use_cholesky_) couplingSolve(DU.col(c), DNU.col(c));  // d nu = K^+ dU
      if (dnu_out)
        for (int r = 0; r < m; ++r) (*dnu_out)(general_ ? order_(r) : r, c0 + c) = DNU(r, c);
    }
    // Outward: accelerations of all columns, base at rest. When the columns are every joint in
    // chain order, the response G is symmetric and square: column c needs only the rows of the
    // joints up to its own (G(j, c) for j <= c, from the segments up to joint c's); the rows
    // below come from the columns already computed (G(j, c) = G(c, j)). The columns alive at
    // segment i are then the suffix c >= (joints before segment i): about half the work.
    bool symmetric = c0 == 0 && kc == static_cast<long>(nj_);
    for (long c = 0; c < kc && symmetric; ++c) symmetric = joints(c) == c;
    auto ACC = col_force_.leftCols(kc);
    ACC.setZero();
    long first = 0;  // first alive column
    for (unsigned int i = 0; i < ns_; ++i) {
      const Segment& s = segs_[i];
      const Vector3 offset = col_offset_.col(i);
      const double* eg = eg_.col(i).data();
      const Eigen::Map<const Vector6> S0(col_s0_.col(i).data()), u0(col_u0_.col(i).data());
      for (long c = first; c < kc; ++c) {
        double* acc = ACC.col(c).data();  // linear part a, angular part w (see the inward pass)
        const Vector3 w(acc[3], acc[4], acc[5]);
        Vector3 a = Vector3(acc[0], acc[1], acc[2]) + w.cross(offset);  // about this tip origin
        if (s.joint < 0) {
          for (int t = 0; t < 3; ++t) acc[t] = a(t);
          continue;
        }
        double v = (joints(c0 + c) == s.joint ? 1.0 : 0.0) - SDP(i, c) - u0.head<3>().dot(a) - u0.tail<3>().dot(w);
        const double* dnu = DNU.col(c).data();
        for (int t = 0; t < m_rows; ++t) v -= eg[t] * dnu[t];
        v *= s.Dinv;
        dqdd(s.joint, c0 + c) = v;
        for (int t = 0; t < 3; ++t) acc[t] = a(t) + S0(t) * v, acc[3 + t] = w(t) + S0(3 + t) * v;
      }
      if (symmetric && s.joint >= 0) {
        for (long c = s.joint + 1; c < kc; ++c) dqdd(c, s.joint) = dqdd(s.joint, c);
        first = s.joint + 1;
      }
    }
    // tau_cmd is linear in nu: d tau_cmd = (d tau_cmd / d nu) d nu, the m columns built once.
    if (!want_tau) {
      // skipped on request
    } else if (m > 0) {
      dtau_cmd.middleCols(c0, kc).noalias() = cmd_per_nu_.leftCols(m).lazyProduct(DNU);
    } else {
      dtau_cmd.middleCols(c0, kc).setZero();
    }
  }
  return E_NOERROR;
}

}  // namespace vereshchagin
