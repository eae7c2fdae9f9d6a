// Symplectic Euler in momentum form over the exact velocity-level solve (symplectic_step.hpp).
// With the Lagrangian L = T - V, d/dt (H q_dot) = dT/dq - dV/dq + tau; symplectic Euler takes
// the momentum p = H(q) u over a step with q held and dT/dq at the END velocity u+ (implicit),
// then moves q with u+. Its energy error stays bounded (no drift), where semi-implicit Euler in
// the velocities gains energy wherever light links spin (docs/time-step.md). The solve supplies
// the rest: the solver's own velocity terms c(q, u) are cancelled by adding them back, and its
// step starts from u, so the added generalized force is c(q, u) + (p - H u) / dt + dT/dq(q, u+).
#include <algorithm>
#include <cmath>

#include "symplectic_step.hpp"

#include "data_impl.hpp"
#include "vereshchagin/energy.hpp"

namespace vereshchagin {
namespace detail {

SymplecticWorkspace::SymplecticWorkspace(const Model& model)
    : dynamics(model),
      scratch(model),
      fixed(Eigen::VectorXd::Zero(model.nv())),
      gradient(Eigen::VectorXd::Zero(model.nv())),
      iterate(Eigen::VectorXd::Zero(model.nv())),
      zero(Eigen::VectorXd::Zero(model.nv())) {}

namespace {

const Eigen::Map<const Matrix6X> kNoWrenches(nullptr, 6, 0);
const KDL::Vector kNoGravity(0.0, 0.0, 0.0);
const char* const kSymplecticOverflow =
    "the symplectic step: the state after the step overflows (finite inputs, q_next or u_next not finite): the "
    "velocities or the time step are too large";

// ws.fixed = c(q, u) - H u / dt + p / dt: one Newton-Euler pass at (q, u, -u / dt) without gravity.
Status fixedForce(const Model& model, SymplecticWorkspace& ws, const SolveInput& in,
                  const Eigen::Ref<const Eigen::VectorXd>& p) {
  const double dt = in.time_step;
  ws.iterate = -in.q_dot / dt;  // iterate: scratch for the acceleration argument
  const Status s = inverseDynamics(model, ws.dynamics, JointPositions(in.q), JointVelocities(in.q_dot),
                                   JointAccelerations(ws.iterate), kNoWrenches, kNoGravity, ws.fixed);
  if (!s) return s;
  ws.fixed += p / dt;
  return s;
}

// One exact solve with dT/dq at ws.iterate added; u_next = u + dt qdd (stuck joints exactly 0).
Status iterateOnce(const Model& model, Data& data, SymplecticWorkspace& ws, const SolveInput& in,
                   Eigen::Ref<Eigen::VectorXd> u_next) {
  Status s = kineticEnergyGradient(model, ws.dynamics, JointPositions(in.q), JointVelocities(ws.iterate), ws.gradient);
  if (!s) return s;
  ws.scratch.ff_torques = in.ff_torques + ws.fixed + ws.gradient;
  if (s = solve(model, data, ws.scratch); !s) return s;
  const std::vector<JointStatus>& status = data.jointStatus();
  const Eigen::VectorXd& qdd = data.qdd();
  const Eigen::Index nb = u_next.size() - static_cast<Eigen::Index>(model.nrOfJoints());  // a floating base's rows
  for (Eigen::Index j = 0; j < u_next.size(); ++j)
    u_next(j) = j >= nb && status[static_cast<std::size_t>(j - nb)] == JointStatus::Stick
                    ? 0.0
                    : in.q_dot(j) + in.time_step * qdd(j);
  return s;
}

}  // namespace

Status symplecticStep(const Model& model, Data& data, SymplecticWorkspace& ws, const SolveInput& input,
                      const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> q_next,
                      Eigen::Ref<Eigen::VectorXd> u_next, Eigen::Ref<Eigen::VectorXd> p_next, int max_iterations,
                      double tol) {
  const Eigen::Index n = static_cast<Eigen::Index>(model.nv());
  const double dt = input.time_step;
  if (!(dt > 0.0) || !std::isfinite(dt))
    return Status(Error::OutOfRange, "the symplectic step needs a finite time step > 0 (s)");
  if (p.size() != n || q_next.size() != model.nq() || u_next.size() != n || p_next.size() != n)
    return Status(Error::SizeMismatch,
                  "the symplectic step: p, q_next, u_next and p_next need one entry per joint (on a floating base "
                  "q_next nq, the others nv entries)");
  if (!p.allFinite()) return Status(Error::NonfiniteInput, "the symplectic step: the momentum is not finite");
  Status s = fixedForce(model, ws, input, p);
  if (!s) return s;
  ws.scratch = input;
  ws.iterate = input.q_dot;
  bool converged = false;
  for (ws.iterations = 1; ws.iterations <= max_iterations; ++ws.iterations) {
    if (s = iterateOnce(model, data, ws, input, u_next); !s) return s;
    const double change = (u_next - ws.iterate).lpNorm<Eigen::Infinity>();
    ws.iterate = u_next;
    if (change <= tol * std::max(1.0, u_next.lpNorm<Eigen::Infinity>())) {
      converged = true;
      break;
    }
  }
  ws.iterations = std::min(ws.iterations, max_iterations);
  s = inverseDynamics(model, ws.dynamics, JointPositions(input.q), JointVelocities(ws.zero), JointAccelerations(u_next),
                      kNoWrenches, kNoGravity, p_next);
  if (!s) return s;
  if (model.baseKind() != BaseKind::Fixed) {
    integrateConfiguration(model.baseKind(), input.q, u_next, dt, q_next);  // on SE(3) / SE(2)
  } else {
    for (Eigen::Index j = 0; j < n; ++j) q_next(j) = input.q(j) + dt * u_next(j);
  }
  const Status finite = detail::finiteStep(q_next, u_next, Status(), kSymplecticOverflow);
  if (!finite) return finite;
  if (!converged)
    return Status(Error::Degraded,
                  "the symplectic step did not converge within its iteration bound: the last "
                  "iterate is taken");
  return Status();
}

}  // namespace detail
Status stepSymplectic(const Model& model, Data& data, const SolveInput& input,
                      const Eigen::Ref<const Eigen::VectorXd>& momentum, Eigen::Ref<Eigen::VectorXd> q_next,
                      Eigen::Ref<Eigen::VectorXd> qd_next, Eigen::Ref<Eigen::VectorXd> momentum_next) {
  if (!data.model().sameAs(model))
    return Status(Error::NotUpToDate, "stepSymplectic(): the Data was built for another model");
  detail::DataImpl& d = data.impl();
  if (!d.symplectic) d.symplectic = std::make_unique<detail::SymplecticWorkspace>(model);
  return detail::symplecticStep(model, data, *d.symplectic, input, momentum, q_next, qd_next, momentum_next);
}

}  // namespace vereshchagin
