/// @file
/// Acceleration-constrained hybrid dynamics of a robot whose segments form a chain or a tree
/// (Popov-Vereshchagin algorithm): the common interface of ChainHdSolver (chain_hd_solver.hpp) and
/// TreeHdSolver (tree_hd_solver.hpp).
///
/// The solver minimises Gauss' acceleration energy subject to linear acceleration constraints on
/// any segments, in O(n) sweeps plus one M x M solve (M the constraint columns):
///
///     min_qdd  Z(qdd)   s.t.   alfa_c^T Xdd_{segments(c)} = beta_c,  c = 0..M-1
///
/// Units are SI throughout (m, rad, kg, kg m^2, N, N m, s).
///
/// Segment and joint order: segment i of the solver is the i-th segment of a depth-first preorder
/// walk from the base (for a chain: the chain's order); every segment's parent comes before it and
/// each subtree is a contiguous range of indices. Joint j is the j-th moving joint (fixed joints
/// have no index), in the segment order: for a chain the chain's order, for a tree the q_nr order
/// of KDL's tree solvers (see tree_hd_solver.hpp).
/// Vectors q, q_dot, ff_torques, qdd, command torques have one entry per joint in that order;
/// f_ext and link accelerations one column per segment in the segment order.
///
/// Frames and signs (identical to KDL 1.5.1's ChainHdSolver_Vereshchagin, so KDL users can switch):
///  * Spatial motion vectors (twists, accelerations) are [linear; angular]; force vectors (wrenches)
///    are [force; moment].
///  * root_acc: the spatial acceleration of the base, in the base frame. Gravity enters as an
///    upward base acceleration: gravity g = (0, 0, -9.81) m/s^2 is root_acc = (0, 0, +9.81, 0, 0, 0).
///    (KDL's RNE/FD solvers take the opposite sign; the Python API takes physical gravity.) A base
///    commanded to move (a mobile base, a torso driven by another controller) enters the same way:
///    root_acc = a_base - g, a_base the base's commanded spatial acceleration (base axes, base
///    origin; its velocity is taken as zero: the base frame is the inertial frame of the solve).
///  * alfa (6 x M): each column a unit constraint wrench, rows 0-2 force, rows 3-5 moment, axes of the
///    base frame, moment about the origin of the tip frame of the segment the column acts on (the
///    last segment, nrOfSegments() - 1, for the solve() overload without `segments`).
///  * beta (M): acceleration-energy set-points, beta_c = alfa_c^T Xdd, where Xdd is that segment's
///    spatial acceleration (base axes, tip origin) INCLUDING root_acc. To hold a tip still along z
///    against gravity, beta_z = 9.81 (not 0).
///  * f_ext (6 x n_segments, one column per segment in the segment order): the wrench applied on
///    segment i by the environment, base axes, moment about segment i's tip origin. Gravity does not
///    go here.
///  * ff_torques (n_joints): generalised joint forces (N m or N) added as-is (springs, friction, ...).
///  * Segment inertias are KDL RigidBodyInertia in the segment tip frame; the joint's rotor inertia
///    (KDL::Joint::getInertia()) adds to the joint's articulated inertia. Joint damping and stiffness
///    are ignored, as in KDL. Fixed joints are supported anywhere.
///
/// Outputs after a successful solve():
///  * qdd (n_joints): joint accelerations, rad/s^2 or m/s^2.
///  * nu (M, the caller's column order): constraint force magnitudes; the constraint wrench acting
///    ON segment segments(c) is -alfa_c nu_c (base axes, that segment's tip origin).
///  * command torques (n_joints): tau_cmd = -sum_c J_c^T alfa_c nu_c, J_c the base-frame Jacobian of
///    column c's segment tip. ff_torques + tau_cmd applied to the unconstrained robot (forward
///    dynamics with the same f_ext and gravity) reproduces qdd exactly. Unlike KDL's
///    `constraint_torques`, these are valid motor commands.
///  * link accelerations (6 x (n_segments + 1)): column 0 is root_acc, column i + 1 the spatial
///    acceleration of segment i's tip frame, base axes, tip origin, including root_acc (KDL's
///    getTransformedLinkAcceleration).
///  * constraint rank and smallest singular value of the coupling matrix K = alfa^T J H^-1 J^T alfa
///    (M x M, symmetric positive semi-definite, units 1/kg-like: acceleration per force).
///
/// Singular tasks: K is inverted by eigen-decomposition. Policy TruncatedPseudoInverse (default)
/// drops eigenvalues below rcond * max(lambda_max, kappa), where kappa = 2 sum_i D_i^-1
/// (|v_i|^2 |F_i|_F^2 + |w_i|^2 |N_i|_F^2) >= sum_i D_i^-1 sum_c (|v_i||f_ic| + |w_i||n_ic|)^2 >=
/// trace K (S_i = [v_i; w_i], A_i = [F_i; N_i] with columns [f_ic; n_ic]; consistent units, so
/// invariant to the length scale) is the size K would have if no cancellation reduced the
/// couplings S_i^T A_i of the constraint wrenches A_i felt at the joints (so a constraint that no
/// joint can affect, e.g. along a stretched arm, counts as rank 0 even when it is the only one);
/// the rank reported counts the others. DampedLeastSquares uses lambda / (lambda^2 + damping^2)
/// for every eigenvalue lambda. Both give finite outputs for any valid input. Fast path: when a
/// Cholesky factor K = L L^T proves every eigenvalue above the threshold (lambda_min = 1 /
/// ||L^-1||_2^2 > rcond * kappa, ||L^-1||_2^2 bounded through L's comparison matrix in O(M^2), else
/// by ||L^-1||_F^2), K^+ = K^-1 is applied through L: the same solution at a fraction of the cost.
///
/// Constraints on any segments (Shakhimardanov's extension of the recursion, KU Leuven 2015): at
/// most 6 columns per segment, any number of segments (maxConstraints() in total: 6 x n_segments,
/// capped by SolverOptions::max_constraints, 256 by default), on any branches. In the inward sweep a segment's own
/// columns join the wrenches felt from its subtree, so the sweeps stay O(n) (times the active columns), and one M x M
/// matrix K couples all constraints, also across branches (through their common ancestors). nu() and the rows of
/// responseColumns()'s dnu follow the caller's column order.
///
/// Affine structure: qdd and tau_cmd are affine in ff_torques. After a solve, responseColumns()
/// returns d(qdd)/d(tau_j) and d(tau_cmd)/d(tau_j) for requested joints j, O(n) per column, reusing
/// the factorisation (the columns of G = H^-1 - H^-1 A^T K^+ A H^-1, A = alfa^T J).
///
/// Driver pass-through (Shakhimardanov, KU Leuven 2015, sec. 3.5.3, eq. 3.42: how much of each
/// driver's own acceleration energy the constraint balance credits): the constraint magnitudes
/// solve K nu = U - beta with U = a_nature + a_fext + a_ff the acceleration energy along the
/// constraint columns of the unconstrained robot, split by driver (a_nature: gravity as root_acc
/// and velocity products; a_fext: f_ext alone; a_ff: ff_torques alone, each with the others zero
/// and q_dot = 0 for the last two). setPassThrough(p_f, p_t) replaces it by
///     K nu = a_nature + (1 - p_f) .* a_fext + (1 - p_t) .* a_ff - beta,
/// p in [0, 1] per column in the order of nu(): 0 (default) = the constraint compensates that
/// driver along that column (KDL's behaviour; results bit for bit as without weights); 1 = the
/// driver's own effect along that column passes through, alfa_c^T Xdd = beta_c + a_driver,c (a
/// commanded press of f_ext on a table, a support, feed-forward torques that should act along a
/// constrained direction); in between, linear. qdd, nu and the command torques follow from this nu
/// with all drivers acting, as always. responseColumns() is the response to joint torques that the
/// constraints compensate (pass-through 0, e.g. friction), whatever the weights.
///
/// Real-time use: construction allocates everything; solve(), CartToJnt() and responseColumns()
/// allocate no heap memory and do bounded work.
///
/// Threads: one instance is not thread-safe; use one per thread. A call that enters an object while
/// another thread is inside a call on it is detected (an atomic flag taken at entry and released
/// at exit by every method that writes the object: the solve() overloads, CartToJnt(),
/// setJointAccelerations(), inverseInertiaTimes(), responseColumns(), commandTorquesOf(),
/// setPassThrough(), clearPassThrough(), setRootAcceleration(), setOptions(),
/// updateInternalDataStructures()) and refused with E_CONCURRENT_CALL, leaving the object
/// untouched, so the other call's results stay exact. The lazily computed linkAccelerations() and
/// smallestSingularValue() then return what they hold without computing. The other getters of
/// results (qdd(), nu(), ...) are not guarded: read them in the thread that solved.
///
/// Errors: every failing call returns a code and writes a message (errorMessage()); a successful
/// solve (or other successful call returning a code) empties the message.
///
/// Degenerate joints: a joint's articulated inertia D_j counts as zero when D_j <= 1e-13 s_j, s_j
/// the size of what the joint moves (its rotor plus, over the segments k of its subtree, trace|I_k|
/// + m_k (|c_k| + l_jk)^2, with l_jk the length of the kinematic path from joint j's frame to
/// segment k's frame): relative to the joint's own subtree, so one huge link elsewhere in the robot
/// does not make the others' inertias look like zero. A D_j that round-off made negative
/// (impossible for a physical model), non-finite, or out of a state with |q| > 1e15 (angles without
/// a significant digit) fails with E_STATE_OUT_OF_RANGE instead of E_DEGENERATE_INERTIA.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <kdl/frames.hpp>
#include <kdl/solveri.hpp>

#include "vereshchagin/inertia_check.hpp"

namespace vereshchagin {

/// How the coupling matrix K is inverted (see "Singular tasks" at the top of this file).
enum class SingularityPolicy { TruncatedPseudoInverse, DampedLeastSquares };

/// Options of HdSolver and FrictionSolver (setOptions() changes them).
struct SolverOptions {
  SingularityPolicy policy = SingularityPolicy::TruncatedPseudoInverse;  ///< inversion of K
  /// Truncation threshold relative to the coupling matrix's scale (see above), in [0, 1).
  double rcond = 1e-12;
  /// Damping of the damped-least-squares policy, in the eigenvalues' units (> 0 for that policy).
  double damping = 1e-6;
  /// Which inertial parameters the robot may have (inertia_check.hpp): Physical (default) checks
  /// every segment's rigid-body inertia when the model is built; JointSpace accepts identified
  /// models and instead requires every articulated joint inertia D_j > 0 at each solve.
  /// Changing it through setOptions() rebuilds the model.
  InertiaCheck inertia_check = InertiaCheck::Physical;
  /// Constraint columns one solve may have in all (its coupling workspace is sized for them once:
  /// memory O(n_segments * m + m^2) instead of O(n_segments^2)). 0 (default): the smaller of
  /// 6 per segment and kDefaultConstraintCapacity; larger values are capped at 6 per segment.
  /// A solve with more columns fails with E_TOO_MANY_CONSTRAINTS naming this option. >= 0.
  int max_constraints = 0;
  static constexpr int kDefaultConstraintCapacity = 256;  ///< the default cap of max_constraints
};

namespace detail {
class HdCore;
class FrictionCore;
struct FacadeState;
}  // namespace detail

class FrictionSolver;
class Model;
class Data;

/// Acceleration-constrained hybrid dynamics (see the top of this file): the interface of ChainHdSolver
/// and TreeHdSolver.
class HdSolver : public KDL::SolverI {
 public:
  static constexpr int kMaxConstraints = 6;                   ///< columns per segment
  using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;  ///< 6 x n matrix (spatial vectors as columns)
  /// At most kMaxConstraints x kMaxConstraints, on the stack.
  using MatrixC = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxConstraints, kMaxConstraints>;
  using VectorC = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxConstraints, 1>;  ///< at most kMaxConstraints

  /// Error codes in addition to KDL::SolverI's (E_SIZE_MISMATCH = -4, E_OUT_OF_RANGE = -6, ...).
  enum {
    E_NONFINITE_INPUT = -100,       ///< NaN or Inf in an input
    E_INVALID_MODEL = -101,         ///< negative mass, inertia failing options.inertia_check, negative rotor
                                    ///< inertia, empty tree, unknown root segment, ...
    E_DEGENERATE_INERTIA = -102,    ///< a joint's articulated inertia D_j <= 0: no unique motion (zero),
                                    ///< or H(q) not positive definite here (inertia_check JointSpace);
                                    ///< a state too large for the arithmetic is E_STATE_OUT_OF_RANGE
    E_TOO_MANY_CONSTRAINTS = -103,  ///< more than 6 columns on one segment
    E_NO_SOLUTION = -104,           ///< responseColumns() called before a successful solve
    E_INVALID_OPTIONS = -105,       ///< rcond < 0, damping <= 0 for the damped policy, non-finite
    E_NONFINITE_RESULT = -106,      ///< finite inputs whose results overflow (Inf/NaN or > 1e150)
    E_CONCURRENT_CALL = -107,       ///< another thread is inside a call on this same object: the call was
                                    ///< refused without reading or writing the object (errorMessage()
                                    ///< and KDL's getError() belong to the other call; strError() has the
                                    ///< text). One solver object per thread.
    E_STATE_OUT_OF_RANGE = -108,    ///< the state (q, q_dot) is so large that round-off dominates the
                                    ///< articulated inertias (e.g. a diverged simulation): not a model problem
  };

  ~HdSolver() override;
  HdSolver(HdSolver&&) noexcept;             ///< moves the solver (model, workspace, results)
  HdSolver& operator=(HdSolver&&) noexcept;  ///< moves the solver (model, workspace, results)

  /// Constraints on the last segment (nrOfSegments() - 1: a chain's tip; for a tree, the last
  /// segment of the preorder). alfa: 6 x m, m = 0..6 (0: plain forward dynamics); beta: m entries;
  /// f_ext (6 x n_segments) and ff_torques (n_joints) may be empty (zero). alfa and f_ext may be
  /// any column-major double matrices (a MatrixXd, a Matrix6X, a block); their row count is checked:
  /// E_SIZE_MISMATCH naming the argument unless it has 6 rows (or no columns). Returns 0 or an error
  /// code (message in errorMessage(), emptied by a successful solve).
  int solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
            const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
            const Eigen::Ref<const Eigen::MatrixXd>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  /// Constraints on any segments: column c of alfa (6 x M) acts on segment segments(c) (segment
  /// order above; base axes, moment about that segment's tip origin); beta has M entries. At most 6
  /// columns per segment. On a chain, columns all on the last segment give exactly the solve() above.
  int solve(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
            const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
            const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Eigen::MatrixXd>& f_ext,
            const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  /// Largest total number of constraint columns of a solve: 6 per segment (at least 6), capped by
  /// options().max_constraints (0: SolverOptions::kDefaultConstraintCapacity).
  int maxConstraints() const;

  /// Results of the last successful solve.
  const Eigen::VectorXd& qdd() const;
  const Eigen::VectorXd& commandTorques() const;  ///< tau_cmd (n_joints), see the top of this file
  Eigen::Map<const Eigen::VectorXd> nu() const;   ///< constraint force magnitudes (M, the caller's column order)
  const Matrix6X& linkAccelerations() const;      ///< computed on first request after a solve
  /// Replaces the segment accelerations of the last solve by those of the joint accelerations qdd
  /// (n_joints) at the same state (q, q_dot, root_acc): one outward pass, no new solve. What
  /// linkAccelerations() and linkLocalAcceleration() return afterwards (FrictionSolver: the
  /// accelerations at the friction optimum). E_SIZE_MISMATCH for a wrong size, E_NO_SOLUTION
  /// before a successful solve.
  int setJointAccelerations(const Eigen::Ref<const Eigen::VectorXd>& qdd);
  /// out = H(q)^-1 tau, H the joint-space inertia matrix (rotor inertias included) at the last
  /// successful solve's q: joint accelerations (rad/s^2 or m/s^2) the joint torques tau (N m or N,
  /// n_joints) would add, from the articulated inertias that solve left (one inward and one outward
  /// pass, no allocation). E_SIZE_MISMATCH for wrong sizes, E_NO_SOLUTION before a successful solve.
  int inverseInertiaTimes(const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> out);
  int constraintCount() const;  ///< constraint columns M of the last solve
  /// Segment i's state at the last successful solve (i < nrOfSegments(), unchecked; unspecified before):
  /// the pose of its tip frame in its parent's tip frame (the base for a segment without parent),
  /// and its spatial velocity and acceleration (the latter including root_acc) in its own tip axes
  /// about its own tip origin. (KDL's getLinkPose / getLinkVelocity / getLinkAcceleration.)
  KDL::Frame linkLocalPose(unsigned int i) const;
  KDL::Twist linkLocalVelocity(unsigned int i) const;      ///< segment i's velocity (see linkLocalPose())
  KDL::Twist linkLocalAcceleration(unsigned int i) const;  ///< segment i's acceleration (see linkLocalPose())
  /// Articulated inertia D_j of joint j (its own rotor plus everything it moves, with its parent
  /// held) at the last solve: a lower bound of the unconstrained (H^-1)_jj is 1 / D_j. Unchecked j.
  double articulatedInertia(unsigned int joint) const;
  int constraintRank() const;  ///< rank of K counted by the singularity policy (see the top of this file)
  /// Smallest eigenvalue (= singular value) of K; computed on first request after a solve.
  double smallestSingularValue() const;

  /// KDL-style getters.
  void getTransformedLinkAcceleration(std::vector<KDL::Twist>& x_dotdot) const;
  /// nu = nu().
  void getConstraintForceMagnitude(Eigen::VectorXd& nu) const { nu = this->nu(); }
  /// getConstraintForceMagnitude() with KDL's spelling.
  void getContraintForceMagnitude(Eigen::VectorXd& nu) const { getConstraintForceMagnitude(nu); }

  /// Affine response to unit joint torques, after a successful solve. joints: k joint indices;
  /// dqdd, dtau_cmd: n_joints x k outputs (column c answers joint joints[c]).
  int responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                      Eigen::Ref<Eigen::MatrixXd> dtau_cmd);
  /// The same, plus d(nu)/d(tau_j) into dnu (constraintCount() x k; its storage may be larger:
  /// only the top m rows are written; rows in the order of nu()). Here dtau_cmd may also be empty
  /// (0 x 0): it is then not computed (commandTorquesOf(nu) gives tau_cmd for any nu).
  int responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                      Eigen::Ref<Eigen::MatrixXd> dtau_cmd, Eigen::Ref<Eigen::MatrixXd> dnu);

  /// The command torques that constraint magnitudes nu (constraintCount(), the order of nu())
  /// would need at the last solve's state: tau = -sum_c J_c^T alfa_c nu_c (n_joints, linear in nu;
  /// commandTorques() is commandTorquesOf(nu())). O(n m), no allocation.
  int commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd);

  /// Driver pass-through weights (see above), kept for the following solves: f_ext_pass_through
  /// and ff_pass_through (m entries each in [0, 1], the order of nu(), or empty: all 0). m is then
  /// the number of constraint columns every solve must have (else E_SIZE_MISMATCH) until
  /// clearPassThrough() or new weights. Returns E_OUT_OF_RANGE (weights unchanged) for entries
  /// outside [0, 1] or NaN, E_SIZE_MISMATCH for sizes (different non-zero sizes, or more than
  /// maxConstraints()). All-zero weights are the same as none. Rebuilding the model
  /// (updateInternalDataStructures(), setOptions() changing inertia_check) clears them.
  int setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                     const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through);
  int clearPassThrough();  ///< 0, or E_CONCURRENT_CALL (weights unchanged)
  /// Number of constraint columns the weights are for (-1: no weights set).
  int passThroughColumns() const;

  /// Base acceleration (base axes, [linear; angular]; gravity as +9.81 along up), see above.
  /// Returns 0, or E_CONCURRENT_CALL (unchanged) while another thread is inside a call.
  int setRootAcceleration(const KDL::Twist& root_acc);
  /// Returns E_INVALID_OPTIONS (options unchanged) or, when inertia_check changed, modelError().
  int setOptions(const SolverOptions& options);
  const SolverOptions& options() const;  ///< the current options

  unsigned int nrOfJoints() const;    ///< number of moving joints (n_joints)
  unsigned int nrOfSegments() const;  ///< number of segments (n_segments)

  /// E_NOERROR if the model is valid, else the reason's code (message in errorMessage()).
  int modelError() const;
  /// Human-readable detail of the last error (which argument, which joint, what was expected).
  const char* errorMessage() const;
  /// Text of an error code: this class's codes, else KDL::SolverI's.
  const char* strError(const int error) const override;

  /// The Model and the Data this solver runs on (model.hpp, data.hpp): a C++ caller may solve
  /// with solve(model(), data(), input) between calls of this face (each call of this face sets
  /// its own root acceleration and pass-through weights; the Data keeps the last solve's results).
  /// Both are replaced by updateInternalDataStructures() and by setOptions() changing
  /// inertia_check or max_constraints.
  const Model& model() const;
  Data& data();  ///< see model()

  /// The robot has changed: recompute the model data (KDL::SolverI interface). Called while another
  /// thread is inside a call on this object it cannot rebuild, nor return a code: every later solve
  /// then fails with E_CONCURRENT_CALL (message saying so) until a call of it succeeds.
  void updateInternalDataStructures() override;

 protected:
  /// Construction never throws for a bad model: the error is kept and returned by every solve.
  HdSolver(const Model& model, const KDL::Twist& root_acc, const SolverOptions& options);
  /// solve() without the entry guard, for a caller that holds it (CartToJnt()).
  int solveEntered(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                   const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                   const Eigen::Ref<const Eigen::MatrixXd>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  /// Replaces the model (a changed chain or tree): a new Data, pass-through weights cleared.
  void rebuild(const Model& model);
  detail::HdCore& core();                           ///< the algorithm on this face's Data
  const detail::HdCore& core() const;               ///< the algorithm on this face's Data
  detail::FacadeState& state() { return *state_; }  ///< Model, Data, root acceleration, weights

 private:
  friend class FrictionSolver;  // runs its friction stage on this face's Data
  int record(int rc);           // keeps rc in KDL::SolverI::error when it is an error, else
                                // empties the message
  int solveChecked(int rc);     // a solve's rc: kept in error, message emptied on success
  int solveArgsProblem(const Eigen::Ref<const Eigen::MatrixXd>& alfa, const Eigen::Ref<const Eigen::MatrixXd>& f_ext);
  int setOptionsEntered(const SolverOptions& options);
  std::unique_ptr<detail::FacadeState> state_;  // Model, Data, root acceleration, pass-through weights
};

}  // namespace vereshchagin
