// The contact stage (contact_stage.hpp): kinematics and classification of the contacts, the
// base solve, the complementarity problem of the unknown contact forces, the final solve.
#include "contact_stage.hpp"

#include <algorithm>
#include <cmath>

#include "data_impl.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

namespace {

constexpr int E_CONTACT = static_cast<int>(Error::InvalidContact);

// t1 = unit(e x n) for the base axis e least aligned with n (the first on ties), t2 = n x t1.
void tangents(const Vector3& n, Vector3& t1, Vector3& t2) {
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(n(k)) < std::abs(n(axis))) axis = k;
  t1 = Vector3::Unit(axis).cross(n).normalized();
  t2 = n.cross(t1);
}

}  // namespace

Eigen::Vector2d ContactStage::vertexCoords(int j, int facets) {
  const double a = 2.0 * M_PI * j / facets;
  return Eigen::Vector2d(std::cos(a), std::sin(a));
}

Eigen::Vector2d ContactStage::edgeCoords(int i, int facets) {
  const double a = M_PI * (2 * i + 1) / facets;
  return Eigen::Vector2d(std::cos(a), std::sin(a));
}

Vector3 ContactStage::vertex(const Point& p, int j, int facets) {
  const Eigen::Vector2d d = vertexCoords(j, facets);
  return d(0) * p.t1 + d(1) * p.t2;
}

Vector3 ContactStage::mostOpposed(const Point& p, const Vector3& v, int facets) {
  Vector3 best = vertex(p, 0, facets);
  for (int j = 1; j < facets; ++j)
    if (const Vector3 d = vertex(p, j, facets); d.dot(v) < best.dot(v)) best = d;
  return best;
}

Vector3 ContactStage::edgeNormal(const Point& p, int i, int facets) {
  const Eigen::Vector2d e = edgeCoords(i, facets);
  return e(0) * p.t1 + e(1) * p.t2;
}

bool ContactStage::pushes(const Point& p, const Vector3& f) {
  return p.n.dot(f) > 1e-12 * std::max(1.0, f.norm());
}

bool ContactStage::insidePolygon(const Point& p, const Vector3& ft, double fn, double mu, int facets) {
  const double apothem = mu * fn * std::cos(M_PI / facets), tol = 1e-12 * std::max(1.0, std::abs(fn));
  for (int i = 0; i < facets; ++i)  // inside every edge
    if (edgeNormal(p, i, facets).dot(ft) > apothem + tol) return false;
  return true;
}

bool ContactStage::convexProblem(const SolveInput& in) const {
  for (std::size_t k = 0; k < points_.size(); ++k)
    if ((points_[k].kind == kTouching || points_[k].kind == kSliding) && in.contacts[k].mu > 0.0) return false;
  return true;
}

void ContactStage::pointKinematics(const PointContact& pc, Vector6& bias) {
  if (nbv_ > 0) return floatingPointKinematics(pc, bias);
  const FrameRef at{pc.segment, KDL::Frame(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)))};
  (void)frameJacobian(model_, kin_, at, jac_);
  (void)frameBiasAcceleration(model_, kin_, at, bias);
}

Vector3 ContactStage::pointAcceleration(const PointContact& pc, const Eigen::VectorXd& qdd, Vector3& bias) {
  Vector6 b;
  pointKinematics(pc, b);
  bias = b.head<3>();
  return jac_.topRows<3>() * qdd + bias;
}

void ContactStage::addForce(const PointContact& pc, const Vector3& f) {
  work_.wrenches.push_back(FrameWrench{pc.segment, (Vector6() << f, Vector3::Zero()).finished(), pc.point});
}

int ContactStage::solveWithForces(DataImpl& d, const SolveInput& in) {
  buildWorkInput(in, false);  // the set-points' columns and known forces
  for (std::size_t k = 0; k < points_.size(); ++k)
    if (const Vector3 f = forces.col(k) - points_[k].fixed; !f.isZero(0.0)) addForce(in.contacts[k], f);
  return runWork(d);
}

ContactStage::ContactStage(const Model& model) : model_(model), kin_(model), work_(model) {
  const int n = static_cast<int>(model.nrOfJoints());
  nv_ = static_cast<int>(model.nv());  // n on a fixed base
  nbq_ = baseConfigurationSize(model.baseKind());
  nbv_ = baseVelocitySize(model.baseKind());
  joint_friction.setZero(n), joint_limit.setZero(n);
  q_dot_.setZero(nv_), gauss_tau_.setZero(nv_), gauss_out_.setZero(nv_);
  jac_.resize(6, nv_);
  joints_.reserve(n);
  joint_tau_.setZero(nv_), ff_user_.setZero(nv_);
  joint_index_.setZero(n);
  joint_dtau_.resize(nv_, n);
  if (nbv_ > 0) {  // the base's axes (base_kind.hpp): a free-flyer's all six, a planar base's x, y, yaw
    base_S_.setZero(6, nbv_);
    if (nbv_ == 6)
      base_S_.setIdentity();
    else
      base_S_(0, 0) = base_S_(1, 1) = base_S_(5, 2) = 1.0;
    jac_b_.resize(6, n);
    floating_gauss_ = makeFloatingGauss(model);
  }
}

int ContactStage::check(HdCore& c, const SolveInput& in) const {
  for (std::size_t k = 0; k < in.contacts.size(); ++k) {
    const PointContact& p = in.contacts[k];
    if (p.segment < 0 || p.segment >= static_cast<int>(c.model.ns))
      return c.fail(E_CONTACT, "contacts[%zu].segment = %d is out of range [0, %u)", k, p.segment, c.model.ns);
    if (!p.point.allFinite() || !p.normal.allFinite())
      return c.fail(E_CONTACT, "contacts[%zu]: point and normal must be finite", k);
    if (std::abs(p.normal.norm() - 1.0) > 1e-6)
      return c.fail(E_CONTACT, "contacts[%zu].normal must be a unit vector, its norm is %g", k, p.normal.norm());
    if (!(std::isfinite(p.mu) && p.mu >= 0.0))
      return c.fail(E_CONTACT, "contacts[%zu].mu must be finite and >= 0, got %g", k, p.mu);
    if (p.facets < 3 || p.facets > 64)
      return c.fail(E_CONTACT, "contacts[%zu].facets must be in 3 .. 64, got %d", k, p.facets);
    if (!p.isSupport() && !(std::isfinite(p.force) && p.force >= 0.0))
      return c.fail(E_CONTACT,
                    "contacts[%zu].force (a normal-force set-point) must be finite and >= 0, or NaN for a support, "
                    "got %g",
                    k, p.force);
  }
  int extra = 0;  // a column per contact, two more per point with friction (the sticking trial)
  for (const PointContact& p : in.contacts) extra += 1 + (p.mu > 0.0 ? 2 : 0);
  if (in.columns() + extra > c.mcap)
    return c.fail(static_cast<int>(Error::TooManyConstraints),
                  "%d constraint columns and %d more for the contacts (one per contact, two more per point with "
                  "friction): at most %d in all (SolverOptions::max_constraints)",
                  in.columns(), extra, c.mcap);
  if (in.contact_max_pivots == 0 || in.contact_max_pivots < -1)
    return c.fail(E_CONTACT, "contact_max_pivots must be -1 (the default bound) or > 0, got %d", in.contact_max_pivots);
  if (!(std::isfinite(in.contact_velocity_tolerance) && in.contact_velocity_tolerance >= 0.0))
    return c.fail(E_CONTACT, "contact_velocity_tolerance must be finite and >= 0, got %g",
                  in.contact_velocity_tolerance);
  for (int k = 0; k < 3; ++k)
    if (in.base_acceleration.vel(k) != 0.0 || in.base_acceleration.rot(k) != 0.0)
      return c.fail(E_CONTACT, "contacts need a base at rest: base_acceleration must be zero");
  return 0;
}

// Step 1: each contact's state at (q, qd) and the sizes of its unknowns, columns and rows.
int ContactStage::classify(HdCore& c, const SolveInput& in) {
  const int nj = static_cast<int>(model_.nrOfJoints());  // (a floating base's entries first)
  if (!forwardKinematics(model_, kin_, JointPositions(in.q.tail(nj)), JointVelocities(in.q_dot.tail(nj))))
    return c.fail(E_CONTACT, "contacts: the forward kinematics of the state failed");
  if (nbv_ > 0) floatingBase(in);
  const double tol = in.contact_velocity_tolerance;
  points_.resize(in.contacts.size());
  user_columns = in.columns();
  for (std::size_t k = 0; k < in.contacts.size(); ++k) {
    const PointContact& pc = in.contacts[k];
    Point& p = points_[k];
    if (nbv_ > 0) {  // world axes
      floatingPointState(pc, p);
    } else {
      KDL::Frame tip;
      Vector6 twist;
      (void)framePose(model_, kin_, FrameRef{pc.segment, KDL::Frame::Identity()}, tip);
      const KDL::Vector point(pc.point(0), pc.point(1), pc.point(2)), r = tip.M * point;
      (void)frameTwist(model_, kin_, FrameRef{pc.segment, KDL::Frame(point)}, twist);
      p.r = Vector3(r.x(), r.y(), r.z());
      p.v = twist.head<3>();
    }
    p.n = pc.normal.normalized();
    tangents(p.n, p.t1, p.t2);
    const double vn = p.n.dot(p.v);
    const Vector3 vt = p.v - vn * p.n;
    // Sliding: the vertex most opposed to the tangential velocity.
    p.slide_dir = vt.norm() > tol ? mostOpposed(p, vt, pc.facets) : Vector3::Zero();
    if (pc.isSupport()) {
      if (vn < -tol && in.time_step == 0.0)  // (over a time step: an impulse)
        return c.fail(E_CONTACT,
                      "contacts[%zu] approaches its surface at %g m/s: an impact needs an impulse, not a force", k,
                      -vn);
      p.kind = vn > tol ? kSeparating : vt.norm() > tol || pc.mu == 0.0 ? kSliding : kTouching;
    } else {
      p.kind = vt.norm() > tol || pc.mu == 0.0 ? kSetPointSliding : kSetPointRest;
    }
  }
  return 0;
}

void ContactStage::layout(const SolveInput& in, bool stick) {
  nz_ = ncol_ = nrow_ = 0;
  int stick_col = user_columns;
  for (const Point& p : points_) stick_col += p.kind == kSetPointRest || p.kind == kSetPointSliding ? 1 : 0;
  for (std::size_t k = 0; k < points_.size(); ++k) {
    Point& p = points_[k];
    const PointContact& pc = in.contacts[k];
    p.fixed.setZero();
    p.dir = p.n + pc.mu * p.slide_dir;
    p.stick_col = -1;
    p.normal_col = -1;  // the all-active guess's only
    const bool rest_friction = p.kind == kTouching || p.kind == kSetPointRest;
    if (stick && rest_friction) {  // held tangentially by two columns
      p.stick_col = stick_col;
      stick_col += 2;
    }
    if (p.kind == kSetPointRest || p.kind == kSetPointSliding)
      p.fixed = pc.force * (p.kind == kSetPointRest ? p.n : p.dir);
    p.role = p.kind == kSliding || (stick && p.kind == kTouching) ? kNormalOnly
             : p.kind == kTouching                                ? kFull
             : p.kind == kSetPointRest && !stick                  ? kTangentOnly
                                                                  : kNoUnknown;
    p.nvar = p.role == kNormalOnly ? 1 : p.role == kFull ? pc.facets + 2 : p.role == kTangentOnly ? pc.facets + 1 : 0;
    p.ncol = p.role == kNormalOnly ? 1 : p.role == kFull ? 3 : p.role == kTangentOnly ? 2 : 0;
    p.nrow = p.ncol;
    p.var = nz_, p.col = ncol_, p.row = nrow_;
    nz_ += p.nvar, ncol_ += p.ncol, nrow_ += p.nrow;
  }
  layoutJoints();
  reserve(static_cast<int>(in.contacts.size()), nz_, ncol_, nrow_);
  // work_'s blocks: the input's, one per set-point, two per resting point with friction (the
  // sticking trial) or one per support (the fallback's held normals): no allocation after the first.
  work_.constraints.reserve(in.constraints.size() + 3 * in.contacts.size());
}

void ContactStage::reserve(int contacts, int unknowns, int columns, int rows) {
  const int n = nv_;
  status.resize(contacts);  // within its capacity after the first solve of this size
  if (forces.cols() < contacts) forces.resize(3, contacts), saved_forces_.resize(3, contacts);
  count = contacts;
  if (rows_jac_.cols() < rows) rows_jac_.resize(n, rows), rows_bias_.resize(rows), rows0_.resize(rows);
  if (col_wrench_.cols() < columns) {
    col_wrench_.resize(6, columns);
    col_segment_.resize(columns);
    dqdd_.resize(n, columns);
  }
  if (acc_per_col_.rows() < rows || acc_per_col_.cols() < columns) acc_per_col_.resize(rows, columns);
  if (coef_.rows() < columns || coef_.cols() < unknowns) coef_.resize(columns, unknowns);
  if (rows_per_z_.rows() < rows || rows_per_z_.cols() < unknowns) rows_per_z_.resize(rows, unknowns);
  if (lcp_m_.rows() < unknowns) {
    lcp_m_.resize(unknowns, unknowns);
    lcp_q_.resize(unknowns), lcp_qp_.resize(unknowns), z_.resize(unknowns), w_.resize(unknowns);
  }
  lemke_.reserve(unknowns);
}

void ContactStage::addColumn(int segment, const Point& p, const Vector3& point, const Vector3& e) {
  ConstraintBlock b;
  b.segment = segment;
  b.columns = 1;
  b.alfa.col(0) << e, Vector3::Zero();  // the point's acceleration along e ...
  b.point = point;
  b.classical = true;  // ... held at zero (classical: the physical acceleration), over a time step
  if (dt_ > 0.0)       // at the value that ends the step at rest along e: v+ = v + dt a = 0
    b.classical_acceleration.head<3>() = -e.dot(p.v) / dt_ * e;
  work_.constraints.push_back(b);
}

// The input with a constraint column and a known wrench per force set-point and, for the sticking
// trial, two tangential columns per resting point with friction (after all the set-points').
void ContactStage::buildWorkInput(const SolveInput& in, bool stick) {
  work_ = in;
  work_.contacts.clear();
  if (joint_friction_) {  // the friction as known torques (contact_joints.cpp)
    work_.friction = nullptr;
    work_.ff_torques = ff_user_ + joint_tau_;
  }
  const auto column = [this](int segment, const Point& p, const Vector3& point, const Vector3& e) {
    addColumn(segment, p, point, e);
  };
  for (std::size_t k = 0; k < in.contacts.size(); ++k) {
    const Point& p = points_[k];
    const PointContact& pc = in.contacts[k];
    if (p.kind != kSetPointRest && p.kind != kSetPointSliding) continue;
    column(pc.segment, p, pc.point, p.n);
    addForce(pc, p.fixed);
  }
  if (!stick) return;
  for (std::size_t k = 0; k < in.contacts.size(); ++k) {
    if (points_[k].stick_col < 0) continue;
    column(in.contacts[k].segment, points_[k], in.contacts[k].point, points_[k].t1);
    column(in.contacts[k].segment, points_[k], in.contacts[k].point, points_[k].t2);
  }
}

}  // namespace detail
}  // namespace vereshchagin
