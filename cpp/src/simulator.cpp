// The Simulator (simulator.hpp): its state, one step through step() of data.hpp on a copy of the
// caller's input carrying the simulator's state and dt, and rollout() with a controller callback
// recording into the caller's buffers. Nothing allocates per step once the sizes are settled.
#include "vereshchagin/simulator.hpp"

#include <cmath>

namespace vereshchagin {

namespace {

bool finite(const Eigen::Ref<const Eigen::VectorXd>& v) {
  return v.allFinite();
}

}  // namespace

void RolloutRecord::resize(int n_joints, int n_steps, bool tau_cmd, bool friction, int n_contacts) {
  t.resize(n_steps + 1);
  q.resize(n_joints, n_steps + 1);
  q_dot.resize(n_joints, n_steps + 1);
  tau_command.resize(n_joints, tau_cmd ? n_steps : 0);
  friction_torque.resize(n_joints, friction ? n_steps : 0);
  contact_force.resize(3 * n_contacts, n_contacts > 0 ? n_steps : 0);
}

void RolloutRecord::resize(const Model& model, int n_steps, bool tau_cmd, bool friction, int n_contacts) {
  resize(static_cast<int>(model.nrOfJoints()), n_steps, tau_cmd, friction, n_contacts);
  q.resize(model.nq(), n_steps + 1);
  q_dot.resize(model.nv(), n_steps + 1);
  tau_command.resize(model.nv(), tau_cmd ? n_steps : 0);
}

Simulator::Simulator(const Model& model, double dt, Integrator integrator, const SolverOptions& options)
    : model_(model),
      data_(model_, options),
      work_(model_),
      q_(Eigen::VectorXd::Zero(model_.nq())),
      qd_(Eigen::VectorXd::Zero(model_.nv())),
      p_(Eigen::VectorXd::Zero(model_.nv())),
      q_next_(Eigen::VectorXd::Zero(model_.nq())),
      qd_next_(Eigen::VectorXd::Zero(model_.nv())),
      p_next_(Eigen::VectorXd::Zero(model_.nv())),
      dynamics_(model_),
      dt_(dt),
      integrator_(integrator) {
  setNeutralBase(model_.baseKind(), q_);  // a floating base at the origin, unrotated
  if (!model_.status())
    status_ = model_.status();
  else if (!data_.status())
    status_ = data_.status();
  else if (!(dt > 0.0) || !std::isfinite(dt))
    status_ = Status(Error::OutOfRange, "Simulator: the time step dt must be finite and > 0 (s)");
  else if (integrator != Integrator::SemiImplicitEuler && integrator != Integrator::Symplectic)
    status_ = Status(Error::OutOfRange, "Simulator: unknown integrator");
  else if (integrator == Integrator::Symplectic) {  // its workspace now: no step allocates
    SolveInput rest(model_);
    rest.q = q_;
    rest.time_step = dt_;
    status_ = stepSymplectic(model_, data_, rest, p_, q_next_, qd_next_, p_next_);
  }
}

Status Simulator::status() const noexcept {
  return status_;
}

Status Simulator::setState(const JointPositions& q, const JointVelocities& q_dot, double t) {
  if (q.value().size() != model_.nq() || q_dot.value().size() != model_.nv())
    return Status(Error::SizeMismatch,
                  "Simulator::setState: q and q_dot must have one entry per joint (nq and nv entries on a floating "
                  "base)");
  if (!finite(*q) || !finite(*q_dot) || !std::isfinite(t))
    return Status(Error::NonfiniteInput, "Simulator::setState: q, q_dot and t must be finite");
  if (integrator_ == Integrator::Symplectic) {  // p = H(q) q_dot: Newton-Euler at (q, 0, q_dot), no gravity
    qd_next_.setZero();                         // scratch: the zero velocity
    const Status s = inverseDynamics(model_, dynamics_, q, JointVelocities(qd_next_), JointAccelerations(*q_dot),
                                     Eigen::Map<const Matrix6X>(nullptr, 6, 0), KDL::Vector::Zero(), p_next_);
    if (!s) return s;
    p_ = p_next_;
  }
  q_ = *q;
  qd_ = *q_dot;
  t0_ = t;
  steps_ = 0;
  return Status();
}

Status Simulator::step(const SolveInput& input) {
  if (!status_) return status_;
  work_ = input;  // every field of the caller's input (no allocation at equal sizes and capacity)
  work_.q = q_;
  work_.q_dot = qd_;
  work_.time_step = dt_;
  const Status s = advance(work_);
  if (s) adopt();
  return s;
}

Status Simulator::step(SolveInput& input) {
  if (!status_) return status_;
  // The state and dt lent to the caller's input for the step (the vectors' buffers swapped, no
  // copy), the caller's own q, q_dot and time_step given back after it.
  input.q.swap(q_);
  input.q_dot.swap(qd_);
  const double caller_time_step = input.time_step;
  input.time_step = dt_;
  const Status s = advance(input);
  input.q.swap(q_);
  input.q_dot.swap(qd_);
  input.time_step = caller_time_step;
  if (s) adopt();
  return s;
}

Status Simulator::advance(const SolveInput& at_state) {
  if (integrator_ == Integrator::Symplectic)
    return stepSymplectic(model_, data_, at_state, p_, q_next_, qd_next_, p_next_);
  return vereshchagin::step(model_, data_, at_state, q_next_, qd_next_);  // Integrator::SemiImplicitEuler
}

void Simulator::adopt() noexcept {
  q_.swap(q_next_);
  qd_.swap(qd_next_);
  if (integrator_ == Integrator::Symplectic) p_.swap(p_next_);
  ++steps_;
}

Status Simulator::checkRecord(int n_steps, const SolveInput& input, const RolloutRecord& r) const {
  const long n = static_cast<long>(model_.nrOfJoints()), states = n_steps + 1L;
  const long nq = static_cast<long>(model_.nq()), nv = static_cast<long>(model_.nv());
  if (n_steps < 0) return Status(Error::OutOfRange, "Simulator::rollout: n_steps must be >= 0");
  if (r.t.size() != states || r.q.rows() != nq || r.q.cols() != states || r.q_dot.rows() != nv ||
      r.q_dot.cols() != states)
    return Status(Error::SizeMismatch,
                  "Simulator::rollout: record t, q, q_dot must have n_steps + 1 entries (columns) of n_joints (nq "
                  "and nv on a floating base)");
  const auto optional = [&](const Eigen::MatrixXd& m, long rows) {
    return m.cols() == 0 || (m.rows() == rows && m.cols() == n_steps);
  };
  const long contacts = 3 * static_cast<long>(input.contacts.size());
  if (!optional(r.tau_command, nv) || !optional(r.friction_torque, n) || !optional(r.contact_force, contacts))
    return Status(Error::SizeMismatch,
                  "Simulator::rollout: record tau_command, friction_torque (n_joints rows) and contact_force "
                  "(3 per contact) must have n_steps columns or none");
  return Status();
}

void Simulator::recordStep(int k, RolloutRecord& r) const {
  r.t(k + 1) = time();
  r.q.col(k + 1) = q_;
  r.q_dot.col(k + 1) = qd_;
  if (r.tau_command.cols() > 0) r.tau_command.col(k) = data_.commandTorques();
  if (r.friction_torque.cols() > 0) r.friction_torque.col(k) = data_.frictionTorques();
  if (r.contact_force.cols() > 0)
    r.contact_force.col(k) = Eigen::Map<const Eigen::VectorXd>(data_.contactForces().data(), r.contact_force.rows());
}

Status Simulator::rollout(int n_steps, const Controller& controller, SolveInput& input, RolloutRecord& record,
                          int* steps_done) {
  if (steps_done) *steps_done = 0;
  if (!status_) return status_;
  if (const Status s = checkRecord(n_steps, input, record); !s) return s;
  record.t(0) = time();
  record.q.col(0) = q_;
  record.q_dot.col(0) = qd_;
  for (int k = 0; k < n_steps; ++k) {
    if (controller) controller(q_, qd_, time(), input);
    if (record.contact_force.cols() > 0 && record.contact_force.rows() != 3 * static_cast<long>(input.contacts.size()))
      return Status(Error::SizeMismatch, "Simulator::rollout: the controller changed the number of contacts");
    const Status s = step(input);
    if (!s) return s;
    recordStep(k, record);
    if (steps_done) *steps_done = k + 1;
  }
  return Status();
}

}  // namespace vereshchagin
