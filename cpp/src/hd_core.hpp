// The private side of HdSolver: the model (constant per robot), the per-solve workspace, the
// results, and HdCore, the algorithm on them. Math and conventions in hd_solver.hpp.
//
// Notation in the comments: segment i has tip frame i and parent lambda(i) = model.parent[i]
// (-1: the base); X_i is the pose of frame i in frame lambda(i), S_i the joint axis in frame i,
// IA_i / pA_i the articulated inertia / bias force, A_i the constraint wrenches felt by segment i
// (6 x columns), U the acceleration energy already produced by bias forces and torques along the
// columns, K the coupling matrix (acceleration energy per unit constraint force).
//
// Segments are in depth-first preorder, so the subtree of i is [i, subtree_end[i]). On the
// several-segment path the constraint columns are sorted by segment, the highest index first:
// the columns felt by segment i (those on its subtree) are then the contiguous range
// [active[subtree_end[i]], active[i]) of the sorted order, with active[i] the number of columns on
// segments >= i. Children's ranges are disjoint, so one 6 x M buffer of felt wrenches serves every
// branch and K accumulates block-wise. On a chain the range is [0, active[i]).
#pragma once

#include <array>
#include <atomic>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/segment.hpp>

#include "vereshchagin/base_kind.hpp"
#include "vereshchagin/hd_solver.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/spatial.hpp"

namespace vereshchagin {
namespace detail {

constexpr int kMaxConstraints = HdSolver::kMaxConstraints;
using Matrix6X = HdSolver::Matrix6X;
using Matrix3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;
using MatrixC = HdSolver::MatrixC;
using VectorC = HdSolver::VectorC;

// A 6-row view of a caller's matrix with 6 rows or no columns (then 6 x 0), keeping its outer
// stride: the public entry points check the rows, the algorithm reads fixed-row blocks.
using Map6X = Eigen::Map<const Matrix6X, 0, Eigen::OuterStride<>>;
inline Map6X sixRows(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  if (m.cols() == 0) return Map6X(nullptr, 6, 0, Eigen::OuterStride<>(6));
  return Map6X(m.data(), 6, m.cols(), Eigen::OuterStride<>(m.outerStride()));
}

// What a model is built from: the segments in preorder, each one's parent (-1: the base) and its
// joint index (-1 for a fixed joint; moving joints numbered 0..n_joints-1 in the caller's order).
struct ModelSource {
  std::vector<KDL::Segment> segments;
  std::vector<int> parent;
  std::vector<int> joint;
  std::string problem;              // non-empty: the source itself is invalid (unknown root, ...)
  BaseKind base = BaseKind::Fixed;  // how the base moves (base_kind.hpp)
  KDL::RigidBodyInertia base_inertia = KDL::RigidBodyInertia::Zero();  // the floating base body's
};

// The floating base joint (base_kind.hpp): its motion axes in the base frame, 6 x k (k = 6: the
// identity, a free-flyer; k = 3: x, y translation and z rotation, planar).
using BaseAxes = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;
using BaseSquare = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
using BaseVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

// Constant data of one segment.
struct SegmentModel {
  Pose X0;                    // pose of this tip frame in the parent tip frame at q = 0
  Vector6 S;                  // joint motion axis in the tip frame (zero for fixed joints)
  Matrix6 I;                  // rigid-body inertia about the tip origin, tip frame
  double rotor = 0.0;         // rotor inertia of the joint
  double w_norm = 0.0;        // |angular part of S| (0 for prismatic joints)
  double v2 = 0.0, w2 = 0.0;  // |linear part of S|^2, |angular part of S|^2
  double d_tolerance = 0.0;   // articulated inertias of this joint at or below this are degenerate
  int joint = -1;             // joint index or -1 for a fixed joint
  int axis = -1;              // S has one nonzero entry (a coordinate axis): its index, else -1
  // S^T x, on a coordinate axis the one product (the others are exact zeros: the same value).
  template <typename V>
  double dotS(const V& x) const {
    return axis >= 0 ? S(axis) * x(axis) : S.dot(x);
  }
  // The screw motion of screwPose() with X0 folded in (model_build.cpp), for S = [v; w], unit
  // axis k = w / |w|, K = [k]x: X(q).R = X0.R + sin(|w| q) RK + (1 - cos(|w| q)) RKK and
  // X(q).p = X0.p - sin(|w| q) pK - (1 - cos(|w| q)) pKK + q pq, with RK = X0.R K,
  // RKK = X0.R K K, pK = RK (k x v) / |w|, pKK = RKK (k x v) / |w|, pq = X0.R k (k . v) (zero
  // but pq = X0.R v for a prismatic joint, |w| = 0).
  Matrix3 RK = Matrix3::Zero(), RKK = Matrix3::Zero();
  Vector3 pK = Vector3::Zero(), pKK = Vector3::Zero(), pq = Vector3::Zero();
};

// The robot: constant per robot, validated when built.
struct HdModel {
  ModelSource source;
  std::vector<SegmentModel> seg;
  std::vector<int> subtree_end;    // one past the last segment of i's subtree
  std::vector<int> branch_slot;    // per segment with >= 2 children: its slot in branch buffers, else -1
  int n_branch = 0;                // segments with >= 2 children
  std::vector<int> joint_segment;  // segment index of each joint
  unsigned int nj = 0, ns = 0;
  // The base (floating_base.cpp): fixed, or a floating body of inertia I_base (base frame, about
  // its origin) on a k-DOF joint to the world with axes S_base; q and q_dot start with its
  // nbq / nbv entries, the joints follow (qdd, tau_cmd: joint j at nbv + j).
  bool floating = false;
  BaseKind base = BaseKind::Fixed;
  int nbq = 0, nbv = 0;
  Matrix6 I_base = Matrix6::Zero();
  BaseAxes S_base;
  bool is_chain = true;                                 // parent[i] = i - 1 for every i: the chain's fast path applies
  InertiaCheck inertia_check = InertiaCheck::Physical;  // what the segments were validated against
  int error = 0;                                        // 0, or why the robot is invalid (message)
  std::string message;
  int parent(int i) const { return source.parent[i]; }
  const std::string& jointName(int segment) const { return source.segments[segment].getJoint().getName(); }
};

// Per-solve state of one segment.
struct SegmentState {
  Pose X;                                       // pose of this tip frame in the parent tip frame at q
  Matrix3 R_base;                               // orientation of this tip frame in the base frame
  Matrix6 IA;                                   // articulated inertia, then (after passToParent) apparent
  Vector6 v, c, pA;                             // velocity, velocity-product acceleration, articulated bias force
  Vector6 u;                                    // IA * S
  Vector6 xdd;                                  // spatial acceleration (tip frame)
  Eigen::Matrix<double, 6, kMaxConstraints> A;  // constraint wrenches felt by this segment (fast path)
  Eigen::Matrix<double, 1, kMaxConstraints> e;  // S^T A (fast path)
  double D = 0.0, Dinv = 0.0;                   // articulated joint inertia and its inverse
};

// Coupling matrix of the fast path (m <= 6 columns on the last segment of a chain).
struct CouplingFast {
  VectorC U0;
  MatrixC L0, K;  // L0 = -K accumulated by the inward sweep
  MatrixC chol;   // lower Cholesky factor of K on the certified path
  Eigen::SelfAdjointEigenSolver<MatrixC> eig;
  VectorC inv_eigen;  // per-eigenvalue multiplier of the policy
};

// The several-segment path (storage sized at construction, mcap columns).
struct CouplingGeneral {
  Eigen::VectorXi order;      // sorted position -> caller's column (highest segment first)
  Eigen::VectorXi seg_count;  // per segment: its number of columns, then the next free position
  std::vector<int> active;    // active[i]: columns on segments >= i (n_segments + 1)
  Matrix6X anew;              // each column's wrench in its own segment's tip axes (sorted)
  Matrix6X acur;              // wrenches felt by the current segment, then passed to the parent
  Eigen::MatrixXd eg;         // mcap x n_segments: column i = (S_i^T A_i)^T on i's felt range (only)
  Eigen::VectorXd ug, nug, rhs;
  mutable Eigen::VectorXd tmp;
  Eigen::MatrixXd kg, cholg, vg;           // coupling matrix (its diagonal blocks), Cholesky factor, eigenvectors
  Eigen::VectorXd invg;                    // policy multiplier per eigenvalue
  mutable Eigen::MatrixXd work_g, work_v;  // smallest eigenvalue (both paths): matrix (mcap x mcap), scratch (mcap x 4)
  mutable Matrix6X seg_force;              // per-segment wrench accumulators
  int lo(const HdModel& model, int i) const  // first sorted column felt by segment i
  {
    return active[model.subtree_end[i]];
  }
};

// Workspace of responseColumns().
struct ResponseWorkspace {
  // Requested columns are computed in chunks of `width` = min(n_joints, kMaxWidth): the workspace
  // stays O(n) for long robots (a full n x n response is computed chunk by chunk).
  static constexpr long kMaxWidth = 64;
  long width = 1;
  Eigen::MatrixXd cmd_per_nu;   // d tau_cmd / d nu (nv x mcap)
  Eigen::MatrixXd energy;       // d U per requested column (mcap x width)
  Eigen::MatrixXd dnu;          // d nu per requested column (mcap x width)
  Eigen::MatrixXd sdp;          // S_i^T (apparent force change from the child), n_segments x width
  Matrix6X axis, axis_inertia;  // joint axes S and IA S per segment, base axes, about each tip origin
  Matrix3X offset;              // tip origin - parent's tip origin, base axes
  Matrix6X force;               // per requested column: apparent force change, then acceleration change
  Matrix3X tmp3;
  Eigen::VectorXi holder;    // per requested column: the segment whose tip its force change is about
  Matrix6X branch_acc;       // per branching segment: its accelerations of every column (6 x width slots)
  Eigen::MatrixXd base_sdp;  // floating base: per column S^T (its force change at the base), base axes (nbv x width)
  Matrix6X base_acc;         // floating base: per column its acceleration change, world axes, base origin
};

// Driver pass-through weights per constraint column (hd_solver.hpp): a facade's state
// (HdSolver::setPassThrough) or one SolveInput's blocks; a solve reads them through
// PassThroughState::weights.
struct PassThroughWeights {
  Eigen::VectorXd f, t;               // weights per caller's column (mcap)
  int m = -1;                         // columns they are for; -1: none
  bool f_any = false, t_any = false;  // some weight is non-zero
  void resize(int mcap) { f = t = Eigen::VectorXd::Zero(mcap); }
};

// Workspace of the driver pass-through.
struct PassThroughState {
  const PassThroughWeights* weights = nullptr;  // of the current solve (nullptr: none)
  bool used = false;                            // the last solve applied energy
  Eigen::VectorXd free;                         // driverFree() per joint (n_joints)
  Eigen::VectorXd energy, tmp;                  // p_f .* a_fext + p_t .* a_ff, and one driver's a (mcap)
  const Eigen::VectorXd* driver = nullptr;      // ff driver if not ff_torques (FrictionSolver)
};

// Cholesky factor D = L L^T of the floating base's k x k articulated inertia (k = nbv <= 6), with
// the reciprocals of its diagonal, and its solves (floating_base.cpp). Fixed storage and plain
// loops: at this size a general factorisation's blocking and dispatch cost more than its flops.
struct BaseFactor {
  Matrix6 L = Matrix6::Zero();    // lower triangle (k x k) used
  Vector6 inv = Vector6::Zero();  // 1 / L(j, j)
  int k = 0;
  bool compute(const Matrix6& D, int size);  // false: D is not positive definite (or not finite)
  template <typename V>
  void forward(V&& x) const;  // x <- L^-1 x (k entries)
  template <typename V>
  void backward(V&& x) const;  // x <- L^-T x
  template <typename V>
  void solve(V&& x) const {  // x <- D^-1 x
    forward(x);
    backward(x);
  }
};

// Per-solve state of the floating base body (floating_base.cpp), base axes.
struct BaseState {
  Pose X;                             // pose of the base frame in the world frame at q
  Vector6 v = Vector6::Zero();        // its velocity
  Vector6 a_world = Vector6::Zero();  // the world's acceleration (root_acc) in base axes
  Vector6 xdd = Vector6::Zero();      // its acceleration (with the world's, as the segments')
  Matrix6 IA = Matrix6::Zero();       // articulated inertia, closed over every root segment
  Vector6 pA = Vector6::Zero();       // articulated bias force
  BaseAxes U;                         // IA S
  Matrix6 D = Matrix6::Zero();        // S^T IA S (top-left k x k)
  BaseFactor factor;                  // of D
  BaseVector free;                    // D^-1 (tau - S^T pA): the base's acceleration, world at rest
  Eigen::MatrixXd e, De;              // S^T A_base and L^-1 S^T A_base, then D^-1 S^T A_base (k x mcap)
};

struct HdWorkspace {
  BaseState base;
  std::vector<SegmentState> seg;
  CouplingFast fast;
  CouplingGeneral general;
  ResponseWorkspace response;
  PassThroughState pt;
  double kappa = 0.0;         // scale of K: 2 sum_i D_i^-1 (|v_i|^2 |F_i|^2 + |w_i|^2 |N_i|^2) (>= trace K)
  bool use_cholesky = false;  // K certified of full rank and factorised by Cholesky
  Matrix6X zero_f_ext;        // 6 x n_segments zeros
  Eigen::VectorXd zero_joints;
  Matrix6 alfa_buf;
  Matrix6X inertia_force, inertia_acc;  // inverseInertia(): per segment, bias force and acceleration
  Eigen::VectorXd inertia_joint;        // inverseInertia(): (tau_j - S^T f) / D per joint
};

struct HdResults {
  Eigen::VectorXd qdd, tau_cmd;
  VectorC nu;                 // fast path
  Eigen::VectorXd nu_user;    // several-segment path, caller's order
  mutable Matrix6X link_acc;  // 6 x (n_segments + 1), on request
  mutable bool link_acc_known = false;
  int m = 0, rank = 0;
  bool solved = false;
  bool general = false;  // the last solve used the several-segment path
  mutable bool sigma_known = false;
  mutable double sigma_min = 0.0;
};

// Loads of the (model, data, input) API given about points of segment frames (input.hpp):
// moved to the tip origins with the outward sweep's own rotations (frame_loads.cpp).
struct FrameLoads {
  const SolveInput* input = nullptr;  // its frame wrenches and its constraint blocks with a point
  Matrix6X* f_ext = nullptr;          // the solve's f_ext: a copy of the input's, the wrenches added
  Matrix6X* alfa = nullptr;           // the solve's columns (the blocks in order)
  Eigen::VectorXd* beta = nullptr;    // their set-points: written for classical blocks
  bool wrenches = false, points = false, classical = false;
};

// The base of a model from its source's kind and inertia (floating_base.cpp): 0, or model.error
// and model.message. Construction-time only.
int buildBase(HdModel& model);

// Constraint columns a solve may have (SolverOptions::max_constraints, hd_solver.hpp): the
// workspace of the coupling matrix is sized for them.
int constraintCapacity(const SolverOptions& opts, unsigned int ns);

// Builds the model of a source (segment data, topology, degeneracy tolerances) and validates it
// against `check`, including a sweep at a generic configuration; model.error and model.message
// say why it is invalid. Construction-time only (allocates).
std::shared_ptr<const HdModel> buildHdModel(ModelSource source, InertiaCheck check);

// The workspace and results of solves on one shared, immutable model (many HdCore per model).
class HdCore {
 public:
  // options.inertia_check is the model's (ignored). model_error: the model's error, or
  // E_INVALID_OPTIONS for invalid options.
  HdCore(std::shared_ptr<const HdModel> model, const Vector6& root_acc, const SolverOptions& options);
  // The generic-configuration sweep of buildHdModel(): 0 or an error code (message).
  int checkGenericConfiguration();

  int solveLast(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  int solveSegments(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                    const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
                    const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  int responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                      Eigen::Ref<Eigen::MatrixXd> dtau_cmd, Eigen::Ref<Eigen::MatrixXd>* dnu);
  // The affine response of the last solve to wrenches: column c of dqdd (n_joints x k) is the
  // change of qdd per wrench wrenches.col(c) ([force; moment] ON segment segments(c), base axes,
  // moment about its tip origin), with the constraints held; dnu (caller's column order) likewise.
  int wrenchResponse(const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& wrenches,
                     Eigen::Ref<Eigen::MatrixXd> dqdd, Eigen::Ref<Eigen::MatrixXd>* dnu);
  int commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd);
  // After a solve on the several-segment path whose coupling matrix K was rank-deficient under the
  // truncated pseudo-inverse (res.rank < res.m): K's null directions (the truncated eigenvectors)
  // into out's first columns (res.m rows, caller's column order), multiplier changes that change
  // no joint torque and so no motion. Returns their number, or -1 on any other path.
  int nullMultipliers(Eigen::Ref<Eigen::MatrixXd> out) const;
  // Validates weights (messages of HdSolver::setPassThrough) into `out`; 0 or an error code.
  int setPassThrough(const Eigen::Ref<const Eigen::VectorXd>& f_ext_pass_through,
                     const Eigen::Ref<const Eigen::VectorXd>& ff_pass_through, PassThroughWeights& out);
  int setOptions(const SolverOptions& options);
  const Matrix6X& linkAccelerations() const;
  // Segment accelerations of given joint accelerations at the last solve's state (poses and
  // velocity products kept): one outward pass; link accelerations follow on request.
  void accelerationsOf(const Eigen::Ref<const Eigen::VectorXd>& qdd);
  // out = H(q)^-1 tau at the last solve's q (its articulated inertias kept): one inward and one
  // outward pass without velocity, gravity or constraints (inverse_inertia.cpp).
  void inverseInertia(const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> out);
  double smallestSingularValue() const;
  // The constraint columns segment i feels, [first, second) in the last solve's column order (the
  // sorted order on the several-segment path): where eg.col(i) and e_i are defined.
  std::pair<int, int> feltColumns(int i) const {
    if (!res.general) return {0, res.m};
    return {ws.general.lo(model, i), ws.general.active[i]};
  }
  Eigen::Map<const Eigen::VectorXd> nu() const {
    return Eigen::Map<const Eigen::VectorXd>(res.general ? res.nu_user.data() : res.nu.data(), res.m);
  }
  int fail(int code, const char* fmt, ...);

  std::shared_ptr<const HdModel> model_owner;
  const HdModel& model;
  HdWorkspace ws;
  HdResults res;
  SolverOptions options;
  Vector6 root_acc = Vector6::Zero();
  FrameLoads* loads = nullptr;  // of the current solve (the API's), applied after the outward sweep
  int model_error = 0;
  int mcap = kMaxConstraints;  // constraint columns of a solve: constraintCapacity(options, ns)
  std::array<char, 512> message{};
  mutable std::atomic<bool> busy{false};  // a call is inside (entry_guard.hpp)
  // The state of the current solve, for the messages of degenerate() (nullptr: the generic
  // configuration of checkGenericConfiguration()).
  const Eigen::Ref<const Eigen::VectorXd>* state_q = nullptr;
  const Eigen::Ref<const Eigen::VectorXd>* state_q_dot = nullptr;

 private:
  // Workspace and checks (hd_model.cpp).
  void allocateWorkspace();
  int checkInputs(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                  const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                  const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques,
                  int max_columns);
  int checkBounded(const Eigen::Ref<const Eigen::VectorXd>& nu, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                   const Eigen::Ref<const Eigen::VectorXd>& beta, const Eigen::Ref<const Matrix6X>& f_ext,
                   const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  int degenerate(int i);

  // Frame loads after the outward sweep (frame_loads.cpp).
  void applyFrameLoads();
  void classicalSetPoints();  // beta of ConstraintBlock::classical blocks

  // Sweeps shared by both paths (hd_core.cpp, articulated_step.hpp).
  void screwPose(const SegmentModel& sm, SegmentState& s, double q) const;
  void outwardSweep(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Matrix6X>& f_ext);
  // Joint part of segment i's inward step: u, D, 1/D; returns the free joint acceleration (parent
  // at rest, no constraint) and the apparent bias force pa; false if D is degenerate.
  inline bool articulate(int i, double tau, Vector6& pa, double& free);
  // Apparent inertia and bias force of segment i added to its parent (which must exist).
  inline void passToParent(int i, const Vector6& pa);
  // The same for a root segment on a floating base: into the base body's (floating_base.cpp).
  inline void passToBase(int i, const Vector6& pa);
  inline Vector6 incomingAcceleration(int i) const;
  // Final outward sweep; constraint_force(i) gives segment i's S^T A nu.
  template <typename ConstraintForce>
  inline void finalSweep(const Eigen::Ref<const Eigen::VectorXd>& ff_torques, const ConstraintForce& constraint_force);

  // Floating base (floating_base.cpp): the several-segment path closed at the base body.
  int solveFloating(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                    const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                    const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
                    const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  int checkFloatingInputs(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                          const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void basePose(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot);
  int closeAtBase(const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void finalBaseStep(const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  // Response columns [0, kc) at the base: the inward pass's base step (energy changes) and the
  // outward pass's start (the base's acceleration changes into dqdd's first rows and ACC).
  void responseBaseInward(long kc);
  void responseBaseOutward(long c0, long kc, Eigen::Ref<Eigen::MatrixXd> dqdd);

  // Fast path: m <= 6 columns on the last segment of a chain (hd_core.cpp).
  int inwardSweep(const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  template <int M>
  int inwardSweepT(const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  template <int M>
  void finalSweepT(const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void finalSweepFast(const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void factorizeCoupling();
  bool choleskyFullRank();
  void applyCouplingInverse(const VectorC& rhs, VectorC& out) const;  // K^+ rhs under the policy
  void commandFromNu(const VectorC& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) const;

  // Several-segment path, chains and trees (segment_constraints.cpp).
  int solveGeneral(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                   const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                   const Eigen::Ref<const Eigen::VectorXi>& segments, const Eigen::Ref<const Matrix6X>& f_ext,
                   const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  int sortColumns(const Eigen::Ref<const Eigen::VectorXi>& segments);
  int inwardSweepGeneral(const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void addOwnColumns(int i, const Eigen::Ref<const Matrix6X>& alfa);
  void projectColumns(int i, int lo, int w, double free);
  void moveColumnsToParent(int i, int lo, int w);
  void factorizeCouplingGeneral();
  template <typename F>
  void forEachCouplingBlock(const F& f) const;  // f(lo, w) per diagonal block of K
  bool choleskyBlocks();
  double smallestEigenvalueGeneral() const;
  void finalSweepGeneral(const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void commandFromNuGeneral(const Eigen::Ref<const Eigen::VectorXd>& nu_sorted,
                            Eigen::Ref<Eigen::VectorXd> tau_cmd) const;
  // out = K^+ rhs for either path (vectors of length m, sorted order on the general path).
  void couplingSolve(const Eigen::Ref<const Eigen::VectorXd>& rhs, Eigen::Ref<Eigen::VectorXd> out) const;
  // B <- K^-1 B column by column through the certified Cholesky factor of either path (m rows).
  void couplingSolveColumns(Eigen::Ref<Eigen::MatrixXd> B) const;

  // Pass-through (pass_through.cpp).
  int passThroughEnergy(const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques);
  void driverFree(const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& tau);
  void driverEnergy(Eigen::Ref<Eigen::VectorXd> out) const;

  // Response columns (response_columns.cpp).
  int checkResponseArgs(const Eigen::Ref<const Eigen::VectorXi>& joints, const Eigen::Ref<Eigen::MatrixXd>& dqdd,
                        const Eigen::Ref<Eigen::MatrixXd>& dtau_cmd, bool want_tau);
  void commandPerNu();
  void baseAxes();
  // Sources: JointTorqueSources or WrenchSources (response_columns.cpp).
  template <typename Sources>
  void responseInward(const Sources& src, long c0, long kc);
  void responseCoupling(long c0, long kc, Eigen::Ref<Eigen::MatrixXd>* dnu_out);
  template <typename Sources>
  void responseOutward(const Sources& src, long c0, long kc, Eigen::Ref<Eigen::MatrixXd> dqdd);
  // At most kLocalColumns joint columns on a fixed-base chain on the fast path, both passes in
  // the segments' own frames (response_local.cpp).
  static constexpr int kLocalColumns = 4;
  void localResponse(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                     Eigen::Ref<Eigen::MatrixXd>* dnu_out);
  template <int K>
  void localResponseT(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                      Eigen::Ref<Eigen::MatrixXd>* dnu_out);
};

}  // namespace detail
}  // namespace vereshchagin
