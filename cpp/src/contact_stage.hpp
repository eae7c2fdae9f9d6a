// The contact stage of solve() (input.contacts, contact.hpp), built in a Data at its first solve
// with contacts. Per solve:
//   0. the all-active guess (contact_active.cpp): when every touching support held and every
//      resting point with friction stuck is consistent and its forces are admissible (the
//      least-effort ones where they are not unique), that is the answer (one solve, the held
//      directions' responses, then the results linear in the forces, or step 4: finishHeld);
//   1. the contact points' kinematics at (q, qd) (KinematicsData): each contact is separating,
//      touching at rest, or sliding; a force set-point becomes a constraint column (zero normal
//      acceleration, held by the motors) plus its normal force as a known wrench;
//   2. the base solve of the input with those columns and wrenches;
//   3. the contact forces: one wrench response column per unknown force direction
//      (Data::wrenchResponseColumns, O(n) each) gives the affine map from the unknowns to the
//      contact points' accelerations; the conditions (normal complementarity, the friction
//      polygon with maximum dissipation) form a linear complementarity problem in the small space
//      of the unknowns (the acceleration-level formulation of Stewart and Trinkle), solved exactly
//      by Lemke's pivoting (lemke.hpp) and checked (the certificate);
//   4. the final solve with the contact forces as wrenches: every result comes from it.
// With joint friction (input.friction, contact_joints.cpp) every solve of steps 0-3 runs without
// the friction stage: moving joints get their kinetic friction as known torques and each resting
// joint with static friction or on a limit one more unknown torque (bounded, maximum dissipation)
// in the same complementarity problem; the all-active guess is skipped. Step 4 then runs the
// friction stage with the contact forces as wrenches: its max-min has the same unique qdd, and it
// picks the joints' friction torques by its least-command rule.
// On a floating base (floating_contact_points.cpp) the points' kinematics are in world axes with
// the base's columns first (nv columns, the joints' rows of q_dot, qdd and the torques after the
// base's nbv_), and joint friction without contacts runs here too (solve.cpp).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "vereshchagin/contact.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/kinematics.hpp"

#include "lemke.hpp"

namespace vereshchagin {
namespace detail {

struct DataImpl;
class HdCore;

// step() on a floating base (floating_contact_points.cpp): qd_next = q_dot + dt qdd, exactly zero
// for a joint friction holds (JointStatus::Stick) and, with every joint held, for the base too
// when the sticking contacts fix it (ContactStage::baseHeld).
void floatingEndVelocity(DataImpl& d, const SolveInput& in, Eigen::Ref<Eigen::VectorXd> qd_next);
// The workspace of floatingInverseInertiaDot for `model` (floating_contact_points.cpp).
std::shared_ptr<struct FloatingGauss> makeFloatingGauss(const Model& model);

class ContactStage {
 public:
  explicit ContactStage(const Model& model);

  // The contacts of `in` (segments, points, normals, coefficients, set-points, and what they
  // cannot be combined with); 0 or an error code with the core's message.
  int check(HdCore& c, const SolveInput& in) const;
  // Steps 1-4 above; 0 or an error code with the core's message.
  int solve(DataImpl& d, const SolveInput& in);

  Matrix3X forces;  // per contact (the first count columns), base axes, N: ON the robot BY the surface
  int count = 0;    // contacts of the last solve
  std::vector<ContactStatus> status;
  ContactOutcome outcome = ContactOutcome::None;
  int user_columns = 0;  // the input's own constraint columns (nu's size)
  // With joint friction or over a time step (contact_joints.cpp): the joints' friction and limit
  // torques (n) and the Gauss value, Z0(qdd) + sum_j f_j |row_j| (row_j = qdd_j, or the end
  // velocity over dt; Z0 as friction_solver.hpp's with the unknown joints' torques in dtau), by one
  // articulated pass.
  Eigen::VectorXd joint_friction, joint_limit;
  double gaussValue(DataImpl& d);
  // A floating base (floating_contact_points.cpp): the last solve's sticking points fix the base
  // (their base columns have full rank), so with every joint held the robot ends a step at rest.
  bool baseHeld(const SolveInput& in);
  // gaussValue's 1/2 tau^T H^-1 tau on a floating base: H from the companions (dynamics.hpp).
  double floatingInverseInertiaDot(const Eigen::VectorXd& tau);

 private:
  // The contact's state at (q, qd); a frictionless point at rest counts as sliding (kSliding).
  enum Kind : signed char { kSeparating, kTouching, kSliding, kSetPointRest, kSetPointSliding };
  // Its unknowns in one complementarity problem: none, the normal force along `dir`, the full
  // polygonal force (f_n, beta, gamma) or the tangential polygon of a set-point (beta, gamma).
  enum Role : signed char { kNoUnknown, kNormalOnly, kFull, kTangentOnly };
  struct Point {
    Kind kind = kSeparating;
    Role role = kNoUnknown;
    Vector3 n, t1, t2, r, v;  // normal, tangents, point - tip origin, point velocity (base axes)
    Vector3 slide_dir;        // sliding: the polygon vertex direction most opposed to v_t (else 0)
    Vector3 dir;              // kNormalOnly: the force per unit normal force
    Vector3 fixed;            // the known part of the force (set-points)
    int var = 0, nvar = 0;    // its unknowns in z
    int col = 0, ncol = 0;    // its response columns
    int row = 0, nrow = 0;    // its acceleration rows
    int stick_col = -1;       // the sticking trial: its first tangential constraint column in nu
    int normal_col = -1;      // the all-active guess: a support's normal column in nu
    bool dropped = false;     // the all-active guess: a support left out (it separates)
    bool held = false;        // least effort: it sticks, its force free inside its polygon
  };

  // The polygon of a point with `facets` facets: vertex direction d_j, the vertex most opposed to
  // `v` (the first on ties), the outward normal of edge i (at (2 i + 1) pi / facets; the polygon
  // mu f_n conv{d_j} lies where e_i . f_t <= mu f_n cos(pi / facets)).
  static Eigen::Vector2d vertexCoords(int j, int facets);  // d_j in (t1, t2): cos, sin of 2 pi j / facets
  static Eigen::Vector2d edgeCoords(int i, int facets);    // e_i in (t1, t2)
  static Vector3 vertex(const Point& p, int j, int facets);
  static Vector3 mostOpposed(const Point& p, const Vector3& v, int facets);
  static Vector3 edgeNormal(const Point& p, int i, int facets);
  // A support's force pushes (f_n above round-off), i.e. it does not separate.
  static bool pushes(const Point& p, const Vector3& f);
  // The tangential force ft lies in the polygon mu fn conv{d_j} (to round-off of fn).
  static bool insidePolygon(const Point& p, const Vector3& ft, double fn, double mu, int facets);
  // No touching support has friction: the accelerations are unique (ContactOutcome::Unique).
  bool convexProblem(const SolveInput& in) const;
  // jac_ and `bias` of the contact point (linear rows 0..2: its velocity Jacobian and classical
  // acceleration at qdd = 0, base axes), from kin_ at the solve's state.
  void pointKinematics(const PointContact& pc, Vector6& bias);
  // The contact point's acceleration (base axes) at joint accelerations qdd; `bias`: its part at
  // qdd = 0 (pointKinematics; jac_ holds the point's Jacobian afterwards).
  Vector3 pointAcceleration(const PointContact& pc, const Eigen::VectorXd& qdd, Vector3& bias);
  // A floating base (floating_contact_points.cpp): its pose and LOCAL twist from in.q, in.q_dot
  // (classify); a point's r and v (world axes) and its Jacobian (jac_, 6 x nv) and bias.
  void floatingBase(const SolveInput& in);
  void floatingPointState(const PointContact& pc, Point& p);
  void floatingPointKinematics(const PointContact& pc, Vector6& bias);
  // A force on the contact point as one more wrench of work_.
  void addForce(const PointContact& pc, const Vector3& f);
  // The final sweep: the input with every contact force (`forces`) as a wrench.
  int solveWithForces(DataImpl& d, const SolveInput& in);

  int classify(HdCore& c, const SolveInput& in);
  // Joint friction with contacts (contact_joints.cpp). A resting joint's unknown torque on the
  // joint (N m or N), bounded by [lo, hi] (-f_j .. f_j, opened to +inf at a lower limit and to -inf
  // at an upper one): its unknowns in z, its response column and its row (qdd_j).
  struct JointUnknown {
    int joint = 0;
    double lo = 0.0, hi = 0.0;
    double f = 0.0;         // its friction bound (static at rest, kinetic while moving over a step)
    double row_bias = 0.0;  // its row at qdd = 0: 0 at the instant, qd_j / dt over a time step
    int var = 0, nvar = 0, col = 0, row = 0;
  };
  // The input's friction model checked (the friction stage's messages); 0 or an error code.
  int checkJointFriction(DataImpl& d, const SolveInput& in);
  // Kinetic friction of the moving joints and the offsets of the resting ones into joint_tau_,
  // the resting joints into joints_.
  void classifyJoints(const SolveInput& in);
  // The joints' unknowns after the contacts' in z, columns and rows (layout()).
  void layoutJoints();
  static double offset(const JointUnknown& u);  // tau_j at z = 0: lo, else hi, else 0
  void prepareJointColumns(DataImpl& d);
  void jointCoefficients();
  void assembleJointLcp();
  void applyJointTorques();
  // runInput on work_ with the input's ff_torques alone as the pass-through driver.
  int runWork(DataImpl& d);
  // A time step (contact_step.cpp): every support and set-point's kind from its end velocity (the
  // polygon's vertex chosen by the problem).
  void stepKinds(const SolveInput& in);
  // The joints' outputs and statuses (into d.status_per_joint) of the last sweep.
  void jointOutputs(DataImpl& d, const SolveInput& in);
  // The least-effort programme (at the instant and over a time step), then the joints' outputs.
  int finish(DataImpl& d, const SolveInput& in);
  // Roles and sizes of one problem: the sticking trial (every resting point with friction held
  // tangentially by two constraint columns) or the full polygonal problem.
  void layout(const SolveInput& in, bool stick);
  void buildWorkInput(const SolveInput& in, bool stick);
  // One constraint column on work_: the point's acceleration along e (base axes) held at zero, over
  // a time step at the value that ends the step at rest along e.
  void addColumn(int segment, const Point& p, const Vector3& point, const Vector3& e);
  void prepareColumns(DataImpl& d, const SolveInput& in);
  void assembleLcp(const SolveInput& in);
  int solveLcp(HdCore& c, bool convex);
  Lemke::Result perturbedLcp(int limit);  // solveLcp's second try after a ray (contact_forces.cpp)
  // The real-time fallback when the general problem's pivoting reached its bound
  // (contact_fallback.cpp): Error::Degraded with its result, or an error code.
  int degradedForces(DataImpl& d, const SolveInput& in);
  int heldNormalsRound(DataImpl& d, const SolveInput& in, int& worst, double& penetration);
  int forcesOfLcp(DataImpl& d, const SolveInput& in, bool convex);
  // The general problem (not the sticking trial) and, over a time step when it has no answer, the
  // velocity-level retry (step_without_bias_): 0 or an error code.
  int generalForces(DataImpl& d, const SolveInput& in);
  void applyForces(const SolveInput& in);
  // The sticking trial: 1 if every resting point with friction sticks (forces and the final solve
  // done), 0 if not (fall back to the full problem), or an error code.
  int trySticking(DataImpl& d, const SolveInput& in);
  void reportStatus(const SolveInput& in, bool stuck);
  // The all-active guess (contact_active.cpp): 1 if it holds (forces, final sweep and statuses
  // done), 0 if not (go on with the general method), or an error code of the final sweep.
  int tryAllActive(DataImpl& d, const SolveInput& in);
  int activeForces(const SolveInput& in, const Eigen::Ref<const Eigen::VectorXd>& nu);
  bool heldPointsStill(const SolveInput& in, const Eigen::VectorXd& qdd);
  void reserveActive(int directions, int rows);
  // Least motor effort among the force distributions that keep qdd (contact_effort.cpp): 0 or an
  // error code of the final sweep.
  int leastEffort(DataImpl& d, const SolveInput& in);
  int effortCoordinates(const SolveInput& in, const Eigen::VectorXd& qdd);
  void reserveEffort(int coordinates, int rows, int columns);
  void reserve(int contacts, int unknowns, int columns, int rows);

  Model model_;
  // nv (q_dot's size) and a floating base's entries of q and q_dot (0 on a fixed base): the
  // joints' rows of q_dot, qdd and the torques start at nbv_.
  int nv_ = 0, nbq_ = 0, nbv_ = 0;
  KinematicsData kin_;
  // A floating base at the solve's state: its orientation and origin in the world, its LOCAL
  // twist S qd_b (base axes), its axes S (6 x nbv_); jac_b_: a point's joint columns (base frame).
  Matrix3 base_R_ = Matrix3::Identity();
  Vector3 base_p_ = Vector3::Zero();
  Vector6 base_v_ = Vector6::Zero();
  Eigen::MatrixXd base_S_, jac_b_;
  std::shared_ptr<struct FloatingGauss> floating_gauss_;  // (floatingInverseInertiaDot)
  SolveInput work_;  // the input with the set-point columns and the contact wrenches
  Lemke lemke_;
  std::vector<Point> points_;
  Eigen::MatrixXd jac_;                 // 6 x nv: one contact point's Jacobian
  Eigen::MatrixXd rows_jac_;            // nv x rows: each acceleration row per joint acceleration
  Eigen::VectorXd rows_bias_;           // rows: their value at qdd = 0
  Eigen::VectorXi col_segment_;         // columns: the segment of each force direction
  Matrix6X col_wrench_;                 // columns: unit force direction as a wrench about the tip origin
  Eigen::MatrixXd dqdd_;                // nv x columns: wrench response
  Eigen::MatrixXd acc_per_col_;         // rows x columns: acceleration rows per unit column force
  Eigen::MatrixXd coef_;                // columns x unknowns: column force per unit unknown
  Eigen::MatrixXd lcp_m_, rows_per_z_;  // N x N; rows x N
  Eigen::VectorXd lcp_q_, z_, w_, rows0_;
  Eigen::VectorXd lcp_qp_;  // N: perturbedLcp's q
  int nz_ = 0, ncol_ = 0, nrow_ = 0;
  // Least effort (contact_effort.cpp): per free force coordinate its direction, contact, value,
  // wrench and responses; the validity rows in the coordinates; the programme's matrices.
  LexicographicQp lqp_;  // least effort, then least contact force (both paths)
  Matrix3X eff_dir_;
  Eigen::VectorXi eff_contact_, eff_seg_, eff_joint_;  // eff_contact_: -1 - i for joints_[i]
  int eff_contacts_ = 0;                               // the contacts' coordinates (the joints' follow)
  Eigen::VectorXd eff_x_, eff_c_, eff_dx_, eff_r_, eff_rhs_;
  Matrix6X eff_wrench_;
  Eigen::MatrixXd eff_dqdd_, eff_dnu_, eff_dtau_, eff_gtg_, eff_l_, eff_q_, eff_rows_, eff_r_all_;
  int eff_k_ = 0;
  // The all-active guess with redundant columns (contact_active.cpp): K's null directions, the
  // multipliers, the motors' torques per direction, the programme in the null coordinates.
  Eigen::MatrixXd act_null_, act_cmd_, act_q_, act_r_;
  Eigen::VectorXd act_tau_, act_lin_, act_y_, act_rhs_;
  // Joint friction (contact_joints.cpp): the resting joints' unknowns, the known joint torques of
  // the solves (kinetic friction, the resting joints' offsets, then their solved torques), the
  // input's ff_torques (zero if empty), the resting joints' indices.
  std::vector<JointUnknown> joints_;
  Eigen::VectorXd joint_tau_, ff_user_;
  Eigen::VectorXi joint_index_;
  Eigen::MatrixXd joint_dtau_;   // n x n: responseColumns' command-torque columns (not used)
  int ncol_contacts_ = 0;        // the contacts' response columns (the joints' follow)
  bool joint_friction_ = false;  // this solve has joint friction
  double dt_ = 0.0;              // SolveInput::time_step (0: the instant)
  // Over a time step, the retry when the problem with the points' bias accelerations (J' qd in
  // their rows) has no answer: rows v+ / dt = J qdd + v / dt alone, the velocity-level problem of
  // Stewart-Trinkle and Anitescu-Potra, which always has one (contact_step.cpp). Reset per solve.
  bool step_without_bias_ = false;
  double lcp_scale_ = 1.0;  // the last complementarity problem's scale (accelerations)
  int max_pivots_ = -1;     // SolveInput::contact_max_pivots of this solve
  int capped_ = 0;          // the general problem reached this pivot bound (0: not); reset per solve
  Matrix3X saved_forces_;   // the fallback's last accepted forces
  Eigen::VectorXd q_dot_;   // the input's q_dot (jointOutputs); gaussValue's buffers
  Eigen::VectorXd gauss_tau_, gauss_out_;
  // speed: the all-active guess on one base solve and the held directions' response
  // (contact_active.cpp). reserveActive(directions, rows) sizes these.
  // Per held direction h: its unit force (base axes), segment, wrench about the tip origin,
  // acceleration row J^T e (n_joints), value a0 at the base solve, response dqdd, dnu and motors'
  // torques; the Delassus matrix A (h x h). Per round: the active directions (act_idx_), A's
  // pivoted Cholesky factor, the held values x, A's null directions (act_null_). Per contact: its
  // normal's and first tangent's direction index (-1: none).
  int heldDirections(DataImpl& d, const SolveInput& in);
  int heldResponse(DataImpl& d, int h);
  int activeDirections();
  int factorActive(int k, double rcond);
  int activeRows(const SolveInput& in, int k, int dn);
  bool droppedSeparate(const Eigen::Ref<const Eigen::VectorXd>& x, int k);
  bool heldRowsStill(const Eigen::Ref<const Eigen::VectorXd>& x, int k);
  int redundantGuess(DataImpl& d, const SolveInput& in, int k, int dn);
  int finishHeld(DataImpl& d, const SolveInput& in);  // the results of `forces`: linear update or final sweep
  Eigen::VectorXi act_seg_, act_idx_, act_piv_, act_normal_, act_tangent_;
  Matrix3X act_dirs_;
  Matrix6X act_wrench_;
  Eigen::MatrixXd act_rows_, act_dqdd_, act_dnu_, act_del_, act_v_, act_tk_, act_c_;
  Eigen::MatrixXd act_tnu_;  // the motors' torques per unit constraint force nu_i (heldResponse)
  Eigen::VectorXd act_enu_;
  Eigen::VectorXd act_a0_, act_x_, act_w_, act_diag_, act_tau0_;
  double act_scale_ = 0.0;     // A's scale without the constraints (rank decisions)
  double act_edge_tol_ = 0.0;  // activeForces: a sticking force may lie this far (x max(1, f_n)) outside
  static double polygonExcess(const Point& p, const Vector3& ft, double fn, const PointContact& pc);
};

}  // namespace detail
}  // namespace vereshchagin
