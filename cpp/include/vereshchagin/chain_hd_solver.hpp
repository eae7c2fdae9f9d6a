// Acceleration-constrained hybrid dynamics of a serial KDL::Chain (Popov-Vereshchagin algorithm).
//
// The solver minimises Gauss' acceleration energy of the chain subject to m <= 6 linear
// acceleration constraints on the last segment, in O(n) sweeps plus one m x m eigen-solve:
//
//     min_qdd  Z(qdd)   s.t.   alfa^T Xdd_N = beta
//
// Units are SI throughout (m, rad, kg, kg m^2, N, N m, s).
//
// Frames and signs (identical to KDL 1.5.1's ChainHdSolver_Vereshchagin, so KDL users can switch):
//  * Spatial motion vectors (twists, accelerations) are [linear; angular]; force vectors (wrenches)
//    are [force; moment].
//  * root_acc: the spatial acceleration of the base, in the base frame. Gravity enters as an
//    upward base acceleration: gravity g = (0, 0, -9.81) m/s^2 is root_acc = (0, 0, +9.81, 0, 0, 0).
//    (KDL's RNE/FD solvers take the opposite sign; the Python API takes physical gravity.)
//  * alfa (6 x m): each column a unit constraint wrench, rows 0-2 force, rows 3-5 moment, axes of the
//    base frame, moment about the origin of the last segment's tip frame. m may change per call.
//  * beta (m): acceleration-energy set-points, beta = alfa^T Xdd_N, where Xdd_N is the last
//    segment's spatial acceleration (base axes, tip origin) INCLUDING root_acc. To hold the tip still
//    along z against gravity, beta_z = 9.81 (not 0).
//  * f_ext (6 x n_segments, one column per segment): the wrench applied on segment i by the
//    environment, base axes, moment about segment i's tip origin. Gravity does not go here.
//  * ff_torques (n_joints): generalised joint forces (N m or N) added as-is (springs, friction, ...).
//  * Segment inertias are KDL RigidBodyInertia in the segment tip frame; the joint's rotor inertia
//    (KDL::Joint::getInertia()) adds to the joint's articulated inertia. Joint damping and stiffness
//    are ignored, as in KDL. Fixed joints are supported anywhere in the chain.
//
// Outputs after a successful solve():
//  * qdd (n_joints): joint accelerations, rad/s^2 or m/s^2.
//  * nu (m): constraint force magnitudes; the constraint wrench acting ON the last segment is
//    -alfa * nu (base axes, tip origin).
//  * command torques (n_joints): tau_cmd = -J^T alfa nu, J the base-frame Jacobian of the last
//    segment's tip. ff_torques + tau_cmd applied to the unconstrained chain (forward dynamics with
//    the same f_ext and gravity) reproduces qdd exactly. Unlike KDL's `constraint_torques`, these
//    are valid motor commands.
//  * link accelerations (6 x (n_segments + 1)): column 0 is root_acc, column i the spatial
//    acceleration of segment i's tip frame, base axes, tip origin, including root_acc (KDL's
//    getTransformedLinkAcceleration).
//  * constraint rank and smallest singular value of the coupling matrix K = alfa^T J H^-1 J^T alfa
//    (m x m, symmetric positive semi-definite, units 1/kg-like: acceleration per force).
//
// Singular tasks: K is inverted by eigen-decomposition. Policy TruncatedPseudoInverse (default)
// drops eigenvalues below rcond * max(lambda_max, kappa), where kappa = 2 sum_i D_i^-1
// (|v_i|^2 |F_i|_F^2 + |w_i|^2 |N_i|_F^2) >= sum_i D_i^-1 sum_c (|v_i||f_ic| + |w_i||n_ic|)^2 >=
// trace K (S_i = [v_i; w_i], A_i = [F_i; N_i] with columns [f_ic; n_ic]; consistent units, so
// invariant to the length scale) is the size K would have if no cancellation reduced the
// couplings S_i^T A_i of the constraint wrenches A_i felt at the joints (so a constraint that no
// joint can affect, e.g. along a stretched arm, counts as rank 0 even when it is the only one);
// the rank reported counts the others. DampedLeastSquares uses lambda / (lambda^2 + damping^2) for every eigenvalue
// lambda. Both give finite outputs for any valid input. Fast path: when a Cholesky factor K = L L^T proves every
// eigenvalue above the threshold (lambda_min >= 1 / ||L^-1||_F^2 > rcond * kappa), K^+ = K^-1 is applied through L: the
// same solution at a fraction of the cost.
//
// Affine structure: qdd and tau_cmd are affine in ff_torques. After a solve, responseColumns()
// returns d(qdd)/d(tau_j) and d(tau_cmd)/d(tau_j) for requested joints j, O(n) per column, reusing
// the factorisation (the columns of G = H^-1 - H^-1 A^T K^+ A H^-1, A = alfa^T J).
//
// Constraints on any segment (Shakhimardanov's extension of the recursion, KU Leuven 2015): the
// overload of solve() with a `segments` vector puts column c of alfa on segment segments(c)
// instead of the last one, with the same conventions there: unit wrench in base axes with the
// moment about THAT segment's tip origin, beta(c) = alfa.col(c)^T Xdd_segments(c) including
// root_acc. At most 6 columns per segment, any number of segments (maxConstraints() = 6 x
// n_segments in total). In the inward sweep a segment's own columns join the wrenches felt from
// its descendants' constraints, so the sweeps stay O(n) (times the number of active columns), and
// one M x M coupling matrix K couples all constraints (M = total columns). nu() and the columns of
// responseColumns()'s dnu follow the caller's column order; the command torques are
// tau_cmd = -sum_c J_{segments(c)}^T alfa_c nu_c. Rank and singularity policy as above (a full
// Jacobi eigen-decomposition replaces Eigen's when K is not certified by Cholesky).
//
// Driver pass-through (Shakhimardanov, KU Leuven 2015, sec. 3.5.3, eq. 3.42: how much of each
// driver's own acceleration energy the constraint balance credits): the constraint magnitudes
// solve K nu = U - beta with U = a_nature + a_fext + a_ff the acceleration energy along the
// constraint columns of the unconstrained arm, split by driver (a_nature: gravity as root_acc and
// velocity products; a_fext: f_ext alone; a_ff: ff_torques alone, each with the others zero and
// q_dot = 0 for the last two). setPassThrough(p_f, p_t) replaces it by
//     K nu = a_nature + (1 - p_f) .* a_fext + (1 - p_t) .* a_ff - beta,
// p in [0, 1] per column in the order of nu(): 0 (default) = the constraint compensates that
// driver along that column (KDL's behaviour; results bit for bit as without weights); 1 = the
// driver's own effect along that column passes through, alfa_c^T Xdd = beta_c + a_driver,c (a
// commanded press of f_ext on a table, a support, feed-forward torques that should act along a
// constrained direction); in between, linear. qdd, nu and the command torques follow from this nu
// with all drivers acting, as always. responseColumns() is the response to joint torques that the
// constraints compensate (pass-through 0, e.g. friction), whatever the weights.
//
// Real-time use: construction allocates everything; solve(), CartToJnt() and responseColumns()
// allocate no heap memory and do bounded work. One instance is not thread-safe; use one per thread.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <kdl/chain.hpp>
#include <kdl/chainidsolver.hpp>  // KDL::Wrenches
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/solveri.hpp>

#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/spatial.hpp"

namespace vereshchagin {

enum class SingularityPolicy { TruncatedPseudoInverse, DampedLeastSquares };

struct SolverOptions {
  SingularityPolicy policy = SingularityPolicy::TruncatedPseudoInverse;
  // Truncation threshold relative to the coupling matrix's scale (see above), in [0, 1).
  double rcond = 1e-12;
  // Damping of the damped-least-squares policy, in the eigenvalues' units (> 0 for that policy).
  double damping = 1e-6;
  // Which inertial parameters the chain may have (inertia_check.hpp): Physical (default) checks
  // every segment's rigid-body inertia when the model is built; JointSpace accepts identified
  // models and instead requires every articulated joint inertia D_j > 0 at each solve.
  // Changing it through setOptions() rebuilds the model.
  InertiaCheck inertia_check = InertiaCheck::Physical;
};

class ChainHdSolver : public KDL::SolverI {
 public:
  static constexpr int kMaxConstraints = 6;
  using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
  using MatrixC = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxConstraints, kMaxConstraints>;
  using VectorC = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxConstraints, 1>;

  // Error codes in addition to KDL::SolverI's (E_SIZE_MISMATCH = -4, E_OUT_OF_RANGE = -6, ...).
  enum {
    E_NONFINITE_INPUT = -100,       // NaN or Inf in an input
    E_INVALID_MODEL = -101,         // negative mass, inertia failing options.inertia_check, negative rotor inertia, ...
    E_DEGENERATE_INERTIA = -102,    // a joint's articulated inertia D_j <= 0: no unique motion (zero),
                                    // or H(q) not positive definite here (inertia_check JointSpace)
    E_TOO_MANY_CONSTRAINTS = -103,  // alfa has more than 6 columns
    E_NO_SOLUTION = -104,           // responseColumns() called before a successful solve
    E_INVALID_OPTIONS = -105,       // rcond < 0, damping <= 0 for the damped policy, non-finite
    E_NONFINITE_RESULT = -106,      // finite inputs whose results overflow (Inf/NaN or > 1e150)
  };

  // The chain is copied. root_acc: base acceleration (gravity as +9.81 along up), see above.
  // Construction never throws for a bad model: the error is kept and returned by every solve
  // (check modelError()).
  ChainHdSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options = SolverOptions());

  // KDL-compatible entry point. alfa: KDL::Jacobian (6 x m, m = 0..6); beta: m entries;
  // f_ext: one wrench per segment; command_torques: output tau_cmd (see above), must be sized
  // n_joints like q_dotdot. Returns 0 or an error code.
  int CartToJnt(const KDL::JntArray& q, const KDL::JntArray& q_dot, KDL::JntArray& q_dotdot, const KDL::Jacobian& alfa,
                const KDL::JntArray& beta, const KDL::Wrenches& f_ext, const KDL::JntArray& ff_torques,
                KDL::JntArray& command_torques);

  // Eigen entry point. f_ext (6 x n_segments) and ff_torques (n_joints) may be empty (zero).
  // alfa may have 0 columns (plain forward dynamics); beta has as many entries as alfa columns.
  int solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
            const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
            const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);

  // Constraints on any segments: column c of alfa (6 x M) acts on segment segments(c) (base axes,
  // moment about that segment's tip origin; see above); beta has M entries. At most 6 columns per
  // segment. Columns all on the last segment give exactly the solve() above.
  int solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
            const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
            const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
            const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  // Largest total number of constraint columns: 6 per segment (at least 6).
  int maxConstraints() const { return mcap_; }

  // Results of the last successful solve.
  const Eigen::VectorXd& qdd() const { return qdd_; }
  const Eigen::VectorXd& commandTorques() const { return tau_cmd_; }
  Eigen::Map<const Eigen::VectorXd> nu() const {
    return Eigen::Map<const Eigen::VectorXd>(general_ ? nu_user_.data() : nu_.data(), m_);
  }
  const Matrix6X& linkAccelerations() const;  // computed on first request after a solve
  int constraintCount() const { return m_; }
  // Segment i's state at the last successful solve (i < nrOfSegments(), unchecked; unspecified before):
  // the pose of its tip frame in its parent's tip frame (the base for i = 0), and its spatial
  // velocity and acceleration (the latter including root_acc) in its own tip axes about its own
  // tip origin. (KDL's getLinkPose / getLinkVelocity / getLinkAcceleration.)
  KDL::Frame linkLocalPose(unsigned int i) const;
  KDL::Twist linkLocalVelocity(unsigned int i) const;
  KDL::Twist linkLocalAcceleration(unsigned int i) const;
  // Articulated inertia D_j of joint j (its own rotor plus everything it moves, with its parent
  // held) at the last solve: a lower bound of the unconstrained (H^-1)_jj is 1 / D_j.
  double articulatedInertia(unsigned int joint) const { return segs_[joint_segment_[joint]].D; }
  int constraintRank() const { return rank_; }
  // Smallest eigenvalue (= singular value) of K; computed on first request after a solve.
  double smallestSingularValue() const;

  // KDL-style getters.
  void getTransformedLinkAcceleration(std::vector<KDL::Twist>& x_dotdot) const;
  void getConstraintForceMagnitude(Eigen::VectorXd& nu) const { nu = this->nu(); }
  void getContraintForceMagnitude(Eigen::VectorXd& nu) const { getConstraintForceMagnitude(nu); }

  // Affine response to unit joint torques, after a successful solve. joints: k joint indices;
  // dqdd, dtau_cmd: n_joints x k outputs (column c answers joint joints[c]).
  int responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                      Eigen::Ref<Eigen::MatrixXd> dtau_cmd);
  // The same, plus d(nu)/d(tau_j) into dnu (constraintCount() x k; its storage may be larger:
  // only the top m rows are written; rows in the order of nu()). Here dtau_cmd may also be empty
  // (0 x 0): it is then not computed (commandTorquesOf(nu) gives tau_cmd for any nu).
  int responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                      Eigen::Ref<Eigen::MatrixXd> dtau_cmd, Eigen::Ref<Eigen::MatrixXd> dnu);

  // The command torques that constraint magnitudes nu (constraintCount(), the order of nu())
  // would need at the last solve's state: tau = -sum_c J_c^T alfa_c nu_c (n_joints, linear in nu;
  // commandTorques() is commandTorquesOf(nu())). O(n m), no allocation.
  int commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd);

  // Driver pass-through weights (see above), kept for the following solves: f_ext_pass_through
  // and ff_pass_through (m entries each in [0, 1], the order of nu(), or empty: all 0). m is then
  // the number of constraint columns every solve must have (else E_SIZE_MISMATCH) until
  // clearPassThrough() or new weights. Returns E_OUT_OF_RANGE (weights unchanged) for entries
  // outside [0, 1] or NaN, E_SIZE_MISMATCH for sizes (different non-zero sizes, or more than
  // maxConstraints()). All-zero weights are the same as none. Rebuilding the model
  // (updateInternalDataStructures(), setOptions() changing inertia_check) clears them.
  int setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                     const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through);
  void clearPassThrough();
  // Number of constraint columns the weights are for (-1: no weights set).
  int passThroughColumns() const { return pt_m_; }

  void setRootAcceleration(const KDL::Twist& root_acc);
  // Returns E_INVALID_OPTIONS (options unchanged) or, when inertia_check changed, modelError().
  int setOptions(const SolverOptions& options);
  const SolverOptions& options() const { return options_; }

  unsigned int nrOfJoints() const { return nj_; }
  unsigned int nrOfSegments() const { return ns_; }
  const KDL::Chain& chain() const { return chain_; }

  // E_NOERROR if the model is valid, else the reason's code (message in errorMessage()).
  int modelError() const { return model_error_; }
  // Human-readable detail of the last error (which argument, which joint, what was expected).
  const char* errorMessage() const { return message_.data(); }
  const char* strError(const int error) const override;

  // The chain has changed: recompute the model data (KDL::SolverI interface).
  void updateInternalDataStructures() override;

 private:
  friend class FrictionSolver;  // sets pt_driver_ (its ff_torques carry friction too)

  struct Segment {
    Pose X0;                                      // pose of this tip frame in the parent tip frame at q = 0
    Pose X;                                       // the same at the current q
    Matrix3 R_base;                               // orientation of this tip frame in the base frame
    Vector6 S;                                    // joint motion axis in the tip frame (zero for fixed joints)
    Matrix6 I;                                    // rigid-body inertia about the tip origin, tip frame
    Matrix6 IA;                                   // articulated inertia
    Vector6 v, c, pA;                             // velocity, velocity-product acceleration, articulated bias force
    Vector6 u;                                    // IA * S
    Vector6 xdd;                                  // spatial acceleration (tip frame)
    Eigen::Matrix<double, 6, kMaxConstraints> A;  // constraint wrenches felt by this segment
    Eigen::Matrix<double, 1, kMaxConstraints> e;  // S^T A
    double rotor = 0.0, D = 0.0, Dinv = 0.0;
    double w_norm = 0.0;        // |angular part of S| (0 for prismatic joints)
    double v2 = 0.0, w2 = 0.0;  // |linear part of S|^2, |angular part of S|^2
    int joint = -1;             // joint index or -1 for a fixed joint
  };

  int fail(int code, const char* fmt, ...);
  void buildModel();
  int checkInputs(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                  const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                  const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques,
                  int max_columns);
  // Joint part of segment i's inward step: u, D, 1/D; returns the free joint acceleration (parent
  // at rest, no constraint) and the apparent bias force pa; false if D is degenerate.
  inline bool articulate(Segment& s, double tau, Vector6& pa, double& free) const;
  // Apparent inertia and bias force of segment i > 0 added to its parent.
  inline void passToParent(int i, const Vector6& pa);
  // Final outward sweep shared by both paths (articulated_step.hpp); constraint_force(i, s) gives
  // segment i's S^T A nu.
  template <typename ConstraintForce>
  inline void finalSweep(const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const ConstraintForce& constraint_force);
  int degenerate(int i);
  // Pass-through (see above), after an inward sweep of either path: E_SIZE_MISMATCH if weights
  // are set for another column count; else, when a weight is non-zero, writes
  // p_f .* a_fext + p_t .* a_ff (m_, the path's column order) into pt_energy_ and sets pt_used_.
  int passThroughEnergy(const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  // Joint accelerations one driver alone gives (f_ext or joint torques tau, either may be empty),
  // each joint with its parent at rest and no constraint, through the last sweep's articulated
  // inertias: free_j = (tau_j - S_j^T p_j) / D_j, p the driver's articulated bias force.
  void driverFree(const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& tau);
  // Acceleration energy along the constraint columns (m_, the path's order) of driverFree()'s
  // accelerations: sum_j e_j^T free_j, into out.
  void driverEnergy(Eigen::Ref<Eigen::VectorXd> out) const;
  // E_NONFINITE_RESULT (with the inputs' sizes in the message) if a result is Inf, NaN or
  // beyond 1e150; nu in the caller's order. Inputs only for the message.
  int checkBounded(const Eigen::Ref<const Eigen::VectorXd>& nu, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                   const Eigen::Ref<const Eigen::VectorXd>& beta, const Eigen::Ref<const Matrix6X>& f_ext,
                   const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  // General path (constraints on several segments), in segment_constraints.cpp.
  int sortColumns(const Eigen::Ref<const Eigen::VectorXi>& segments);
  int inwardSweepGeneral(const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void factorizeCouplingGeneral();
  void finalSweepGeneral(const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void commandFromNuGeneral(const Eigen::Ref<const Eigen::VectorXd>& nu_sorted,
                            Eigen::Ref<Eigen::VectorXd> tau_cmd) const;
  // out = K^+ rhs for either path (vectors of length m_, sorted order on the general path).
  void couplingSolve(const Eigen::Ref<const Eigen::VectorXd>& rhs, Eigen::Ref<Eigen::VectorXd> out) const;
  void screwPose(Segment& s, double q) const;
  void outwardSweep(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Matrix6X>& f_ext);
  int inwardSweep(const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  template <int M>
  int inwardSweepT(const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  template <int M>
  void finalSweepT(const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void factorizeCoupling();
  bool choleskyFullRank();
  // out = K^+ rhs under the singularity policy (K = -L0).
  void applyCouplingInverse(const VectorC& rhs, VectorC& out) const;
  void commandFromNu(const VectorC& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) const;
  int responseColumnsImpl(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                          Eigen::Ref<Eigen::MatrixXd> dtau_cmd, Eigen::Ref<Eigen::MatrixXd>* dnu);

  KDL::Chain chain_;
  SolverOptions options_;
  Vector6 root_acc_;
  unsigned int nj_ = 0, ns_ = 0;
  double d_tolerance_ = 0.0;
  int model_error_ = E_NOERROR;
  std::array<char, 512> message_{};

  std::vector<Segment> segs_;
  std::vector<int> joint_segment_;  // segment index of each joint
  Eigen::VectorXd qdd_, tau_cmd_, zero_joints_;
  // Workspace of responseColumns(): d tau_cmd / d nu (n_joints x m), per segment and column the
  // joint-axis component of the apparent force change (n_segments x n_joints), column blocks.
  Eigen::MatrixXd cmd_per_nu_, col_energy_, col_nu_, col_sdp_;
  Matrix6X col_s0_, col_u0_;                             // joint axes S and IA S in base axes, about each tip origin
  Eigen::Matrix<double, 3, Eigen::Dynamic> col_offset_;  // tip origin - parent's tip origin, base axes
  Matrix6X col_force_;
  Eigen::VectorXd col_row_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> col_tmp3_;
  mutable Matrix6X link_acc_;
  mutable bool link_acc_known_ = false;
  Matrix6X f_ext_buf_, zero_f_ext_;
  Matrix6 alfa_buf_;
  int m_ = 0, rank_ = 0;
  bool solved_ = false;
  VectorC U0_, nu_;
  MatrixC L0_, K_;
  double kappa_ = 0.0;  // scale of K: 2 sum_i D_i^-1 (|v_i|^2 |F_i|^2 + |w_i|^2 |N_i|^2) (>= trace K)
  // K is factorised by Cholesky when it is certainly of full rank (fast path), else by a full
  // eigen-decomposition that applies the singularity policy.
  bool use_cholesky_ = false;
  MatrixC chol_;  // lower Cholesky factor of K on the fast path
  Eigen::SelfAdjointEigenSolver<MatrixC> eig_;
  VectorC inv_eigen_;  // per-eigenvalue multiplier of the policy
  mutable bool sigma_known_ = false;
  mutable double sigma_min_ = 0.0;
  mutable Eigen::SelfAdjointEigenSolver<MatrixC> sigma_eig_;

  // General path: constraints on several segments (storage sized at construction).
  bool general_ = false;        // the last solve used it
  int mcap_ = kMaxConstraints;  // 6 per segment
  Eigen::VectorXi order_;       // sorted position -> caller's column (distal segments first)
  Eigen::VectorXi seg_count_;   // per segment: its number of columns
  std::vector<int> active_;     // active_[i]: columns on segments >= i (n_segments + 1)
  Matrix6X anew_;               // each column's wrench in its own segment's tip axes (sorted)
  Matrix6X acur_, aproj_;       // wrenches felt by the current segment / passed to the parent
  Eigen::MatrixXd eg_;          // mcap x n_segments: column i = (S_i^T A_i)^T, zero past active_[i]
  Eigen::VectorXd ug_, nug_, nu_user_, rhs_g_;
  mutable Eigen::VectorXd tmp_g_;
  Eigen::MatrixXd kg_, cholg_, vg_;          // coupling matrix, its Cholesky factor or eigenvectors
  Eigen::VectorXd invg_;                     // policy multiplier per eigenvalue
  mutable Eigen::MatrixXd work_g_, work_v_;  // Jacobi workspace for the smallest singular value

  // Driver pass-through (storage sized at construction).
  Eigen::VectorXd pt_f_, pt_t_;               // weights per caller's column (mcap)
  int pt_m_ = -1;                             // columns they are for; -1: none
  bool pt_f_any_ = false, pt_t_any_ = false;  // some weight is non-zero
  bool pt_used_ = false;                      // the last solve applied pt_energy_
  Eigen::VectorXd pt_free_;                   // driverFree() per joint (n_joints)
  Eigen::VectorXd pt_energy_, pt_tmp_;        // p_f .* a_fext + p_t .* a_ff, and one driver's a (mcap)
  // The feed-forward driver when ff_torques also carry forces the constraints always compensate
  // (FrictionSolver's friction); nullptr: ff_torques.
  const Eigen::VectorXd* pt_driver_ = nullptr;
};

}  // namespace vereshchagin
