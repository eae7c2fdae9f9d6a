// The companions on row-major arrays (companion_call.hpp): each argument's shape and values
// checked with the Python face's messages, the result's shape, and one dispatch to the kinematics
// and dynamics functions, whose overflow is reported under the companion's Python name.
#include "vereshchagin/companion_call.hpp"

#include <cmath>
#include <limits>

#include "dynamics_impl.hpp"
#include "vereshchagin/momentum.hpp"

namespace vereshchagin {

namespace {

Eigen::Map<const Eigen::VectorXd> vec(const ArrayArg& a) {
  return Eigen::Map<const Eigen::VectorXd>(a.data, a.size());
}

// q or qd of fk and twist: one state per row (a vector is one row).
Eigen::Map<const JointRows> rows(const ArrayArg& a, long n) {
  return Eigen::Map<const JointRows>(a.data, a.ndim == 2 ? a.shape[0] : 1, n);
}

long rowCount(const ArrayArg& a) {
  return a.ndim == 2 ? a.shape[0] : 1;
}

// The flat index of the first Inf or NaN of `a`, -1 if none: first a scan without early exit
// (|x| <= DBL_MAX fails for both), which vectorizes, since every call's arguments pass it.
long firstNonfinite(const ArrayArg& a) {
  const long size = a.data ? a.size() : 0;
  bool finite = true;
  for (long i = 0; i < size; ++i) finite &= std::abs(a.data[i]) <= std::numeric_limits<double>::max();
  for (long i = 0; !finite; ++i)
    if (!std::isfinite(a.data[i])) return i;
  return -1;
}

// The dynamics companions take the whole state on a floating base (q: nq, qd and qdd: nv
// entries) and return nv rows; the kinematics companions the joints' (base_kind.hpp).
bool wholeState(Companion kind) {
  return kind == Companion::InverseDynamics || kind == Companion::MassMatrix || kind == Companion::GravityTorques ||
         kind == Companion::CoriolisTorques || kind >= Companion::CenterOfMass;
}

bool hasShape(const ArrayArg& a, long rows, long cols) {
  return rows < 0 ? a.ndim == 1 && a.shape[0] == cols : a.ndim == 2 && a.shape[0] == rows && a.shape[1] == cols;
}

// The 6 x n_segments f_ext of inverse_dynamics: the rows of args[FExt], or the frame wrenches
// summed onto the tips at q in dd's scratch.
Status wrenchColumns(const Model& model, DynamicsData& dd, const CompanionCall& c, Eigen::Map<const Matrix6X>& f_ext) {
  const ArrayArg& f = c.args[static_cast<int>(CompanionArg::FExt)];
  const long ns = dd.kinematics().impl().ns;
  if (!c.frame_wrenches_given) {
    new (&f_ext) Eigen::Map<const Matrix6X>(f.data, 6, f.data ? ns : 0);
    return Status();
  }
  Matrix6X& sums = dd.impl().f_frames;
  sums.setZero();
  const detail::DynamicsImpl& di = dd.impl();
  const Eigen::Map<const Eigen::VectorXd> q = vec(c.args[0]);
  if (di.nb != 0)  // a floating base: q's base part read and checked; the wrenches in world axes
    if (const Status s = dd.impl().start(model, q); !s) return s;
  if (const Status s = forwardKinematics(model, dd.kinematics(), JointPositions(q.tail(q.size() - di.nbq))); !s)
    return s;
  for (const auto& [frame, wrench] : c.frame_wrenches) {
    Vector6 w = wrench;  // base axes for addFrameWrench, then back to world axes
    if (di.nb != 0) w << di.R_b.transpose() * wrench.head<3>(), di.R_b.transpose() * wrench.tail<3>();
    if (const Status s = addFrameWrench(model, dd.kinematics(), frame, w, sums); !s) return s;
  }
  for (long i = 0; di.nb != 0 && i < 2 * ns; ++i) {
    Eigen::Map<Vector3> half(sums.data() + 3 * i);
    half = (di.R_b * half).eval();
  }
  new (&f_ext) Eigen::Map<const Matrix6X>(sums.data(), 6, ns);
  return Status();
}

Status dispatch(const Model& model, DynamicsData& dd, const CompanionCall& c, double* out) {
  KinematicsData& kd = dd.kinematics();
  const long n = kd.impl().nj, ns = kd.impl().ns, nv = n + dd.impl().nb;
  const ArrayArg &q = c.args[0], &qd = c.args[1], &g = c.args[3];
  const KDL::Vector gravity = g.data ? KDL::Vector(g.data[0], g.data[1], g.data[2]) : KDL::Vector::Zero();
  Eigen::Map<Eigen::VectorXd> tau(out, nv);
  switch (c.kind) {
    case Companion::InverseDynamics: {
      Eigen::Map<const Matrix6X> f_ext(nullptr, 6, 0);
      if (const Status s = wrenchColumns(model, dd, c, f_ext); !s) return s;
      return inverseDynamics(model, dd, JointPositions(vec(q)), JointVelocities(vec(qd)),
                             JointAccelerations(vec(c.args[2])), f_ext, gravity, tau);
    }
    case Companion::MassMatrix:
      return massMatrix(model, dd, JointPositions(vec(q)), Eigen::Map<Eigen::MatrixXd>(out, nv, nv));
    case Companion::GravityTorques:
      return gravityTorques(model, dd, JointPositions(vec(q)), gravity, tau);
    case Companion::CoriolisTorques:
      return coriolisTorques(model, dd, JointPositions(vec(q)), JointVelocities(vec(qd)), tau);
    case Companion::Fk:
      return framePoses(model, kd, rows(q, n), c.frame, Eigen::Map<PoseRows>(out, rowCount(q), 16));
    case Companion::FkAll:
      return segmentPoses(model, kd, JointPositions(vec(q)), Eigen::Map<PoseRows>(out, ns, 16));
    case Companion::Twist:
      return frameTwists(model, kd, rows(q, n), rows(qd, n), c.frame, Eigen::Map<TwistRows>(out, rowCount(q), 6));
    case Companion::Jacobian:
      if (const Status s = forwardKinematics(model, kd, JointPositions(vec(q))); !s) return s;
      return frameJacobian(model, kd, c.frame, Eigen::Map<Eigen::MatrixXd>(out, 6, n));
    case Companion::JacobianDotTimesQd: {
      if (const Status s = forwardKinematics(model, kd, JointPositions(vec(q)), JointVelocities(vec(qd))); !s) return s;
      Vector6 bias;
      const Status s = frameBiasAcceleration(model, kd, c.frame, bias);
      Eigen::Map<Vector6>{out} = bias;
      return s;
    }
    case Companion::CenterOfMass:
      return centerOfMass(model, dd, JointPositions(vec(q)), Eigen::Map<Eigen::Vector3d>(out));
    case Companion::CenterOfMassJacobian:
      return centerOfMassJacobian(model, dd, JointPositions(vec(q)), Eigen::Map<Eigen::MatrixXd>(out, 3, nv));
    case Companion::CenterOfMassVelocity:
      return centerOfMassVelocity(model, dd, JointPositions(vec(q)), JointVelocities(vec(qd)),
                                  Eigen::Map<Eigen::Vector3d>(out));
    case Companion::CentroidalMomentum:
      return centroidalMomentum(model, dd, JointPositions(vec(q)), JointVelocities(vec(qd)), Eigen::Map<Vector6>(out));
    case Companion::Integrate: {
      if (const Status s = dd.impl().start(model, vec(q)); !s) return s;
      integrateConfiguration(model.baseKind(), vec(q), vec(qd), 1.0, Eigen::Map<Eigen::VectorXd>(out, q.size()));
      return kd.impl().checkResult(Eigen::Map<Eigen::VectorXd>(out, q.size()));
    }
  }
  return kd.impl().fail(Error::InvalidOptions, "unknown companion %d", static_cast<int>(c.kind));
}

}  // namespace

const char* companionName(Companion kind) noexcept {
  static const char* const names[] = {"inverse_dynamics",
                                      "mass_matrix",
                                      "gravity_torques",
                                      "coriolis_torques",
                                      "fk",
                                      "fk_all",
                                      "jacobian",
                                      "twist",
                                      "jacobian_dot_times_qd",
                                      "center_of_mass",
                                      "center_of_mass_jacobian",
                                      "center_of_mass_velocity",
                                      "centroidal_momentum",
                                      "integrate"};
  const int k = static_cast<int>(kind);
  return k >= 0 && k < 14 ? names[k] : "unknown companion";
}

Status checkCompanionArg(KinematicsData& kdata, const CompanionCall& call, CompanionArg arg) {
  detail::KinematicsImpl& k = kdata.impl();
  const ArrayArg& a = call.args[static_cast<int>(arg)];
  const char* name = companionArgName(arg);
  const bool state_rows = (call.kind == Companion::Fk || call.kind == Companion::Twist) && arg != CompanionArg::Qdd;
  if (arg == CompanionArg::FExt) {
    if (a.data && !hasShape(a, k.ns, 6))
      return k.fail(Error::SizeMismatch, "f_ext must have shape (%d, 6) or be a dict {segment: wrench (6,)}, got %s",
                    k.ns, a.shapeString().c_str());
  } else if (arg == CompanionArg::Gravity) {
    if (!hasShape(a, -1, 3))
      return k.fail(Error::SizeMismatch, "gravity must have shape (3,), got %s", a.shapeString().c_str());
  } else if (wholeState(call.kind) && k.nj != static_cast<int>(arg == CompanionArg::Q ? k.model.nq() : k.model.nv())) {
    const long want = arg == CompanionArg::Q ? k.model.nq() : k.model.nv();  // a floating base
    if (!hasShape(a, -1, want))
      return k.fail(Error::SizeMismatch, "%s must have shape (%ld,) (the base's entries, then the joints'), got %s",
                    name, want, a.shapeString().c_str());
  } else if (!hasShape(a, -1, k.nj) && !(state_rows && a.ndim == 2 && a.shape[1] == k.nj)) {
    return k.fail(Error::SizeMismatch, "%s must have shape (%d,), got %s", name, k.nj, a.shapeString().c_str());
  }
  if (const long i = firstNonfinite(a); i >= 0)
    return k.fail(Error::NonfiniteInput, "%s contains NaN or Inf (flat index %ld)", name, i);
  return Status();
}

Status companionShape(KinematicsData& kdata, const CompanionCall& call, int& ndim, long shape[3]) {
  const detail::KinematicsImpl& k = kdata.impl();
  const ArrayArg &q = call.args[0], &qd = call.args[1];
  const long rows = q.ndim == 2 ? q.shape[0] : -1;  // -1: one state, no row dimension
  if (call.kind == Companion::Twist && (q.ndim != qd.ndim || rowCount(q) != rowCount(qd)))
    return kdata.impl().fail(Error::SizeMismatch, "q and qd must have the same shape, got %ld and %ld rows",
                             rowCount(q), rowCount(qd));
  const auto set = [&](std::initializer_list<long> dims) {
    ndim = 0;
    for (const long d : dims)
      if (d >= 0) shape[ndim++] = d;
    return Status();
  };
  switch (call.kind) {
    case Companion::MassMatrix:
      return set({static_cast<long>(k.model.nv()), static_cast<long>(k.model.nv())});
    case Companion::Fk:
      return set({rows, 4, 4});
    case Companion::FkAll:
      return set({k.ns, 4, 4});
    case Companion::Jacobian:
      return set({6, k.nj});
    case Companion::Twist:
      return set({rows, 6});
    case Companion::JacobianDotTimesQd:
    case Companion::CentroidalMomentum:
      return set({6});
    case Companion::CenterOfMass:
    case Companion::CenterOfMassVelocity:
      return set({3});
    case Companion::CenterOfMassJacobian:
      return set({3, static_cast<long>(k.model.nv())});
    case Companion::Integrate:
      return set({static_cast<long>(k.model.nq())});
    default:  // the dynamics companions' nv rows
      return set({static_cast<long>(k.model.nv())});
  }
}

Status callCompanion(const Model& model, DynamicsData& ddata, const CompanionCall& call, double* out) {
  const Status s = dispatch(model, ddata, call, out);
  if (s.code() != Error::NonfiniteResult) return s;
  return ddata.kinematics().impl().fail(Error::NonfiniteResult, "%s: the result overflows the double range",
                                        companionName(call.kind));
}

}  // namespace vereshchagin
