// Data (data.hpp): a workspace and the results of the last solve on one Model.
#include "vereshchagin/data.hpp"

#include <limits>

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "entry_guard.hpp"
#include "friction_core.hpp"
#include "model_impl.hpp"
#include "symplectic_step.hpp"

namespace vereshchagin {

namespace detail {

DataImpl::DataImpl(const Model& m, const SolverOptions& options)
    : model(m), core(m.impl().hd, Vector6::Zero(), options) {
  const int mcap = core.mcap;
  const unsigned int nj = m.nrOfJoints(), ns = m.nrOfSegments();
  alfa = Matrix6X::Zero(6, mcap);
  beta = Eigen::VectorXd::Zero(mcap);
  segments = Eigen::VectorXi::Zero(mcap);
  f_ext = Matrix6X::Zero(6, ns);
  weights.resize(mcap);
  zeros = Eigen::VectorXd::Zero(nj);
  status_per_joint.assign(nj, JointStatus::Moving);
  loads.f_ext = &f_ext;
  loads.alfa = &alfa;
  loads.beta = &beta;
}

DataImpl::~DataImpl() = default;

ContactStage& DataImpl::contacts() {
  if (!contact_stage) contact_stage = std::make_unique<ContactStage>(model);
  return *contact_stage;
}

}  // namespace detail

using detail::EntryGuard;

Data::Data(const Model& model, const SolverOptions& options)
    : impl_(std::make_unique<detail::DataImpl>(model, options)) {}
Data::~Data() = default;
Data::Data(Data&&) noexcept = default;
Data& Data::operator=(Data&&) noexcept = default;

Status Data::status() const noexcept {
  return impl_->status(impl_->core.model_error);
}
const SolverOptions& Data::options() const noexcept {
  return impl_->core.options;
}

int Data::maxConstraints() const noexcept {
  return impl_->core.mcap;
}
void Data::reserveFriction() {
  impl_->friction();
}
const Model& Data::model() const noexcept {
  return impl_->model;
}

const Eigen::VectorXd& Data::qdd() const noexcept {
  return impl_->friction_last ? impl_->friction_core->qdd_ : impl_->core.res.qdd;
}
const Eigen::VectorXd& Data::commandTorques() const noexcept {
  return impl_->friction_last ? impl_->friction_core->tau_cmd_ : impl_->core.res.tau_cmd;
}
Eigen::Map<const Eigen::VectorXd> Data::nu() const noexcept {
  if (impl_->contacts_last) {  // the input's own columns (the set-points' follow them)
    return Eigen::Map<const Eigen::VectorXd>(impl_->core.nu().data(), impl_->contact_stage->user_columns);
  }
  if (!impl_->friction_last) return impl_->core.nu();
  const detail::FrictionCore& f = *impl_->friction_core;
  return Eigen::Map<const Eigen::VectorXd>(f.nu_.data(), f.m_keep_);
}
int Data::constraintRank() const noexcept {
  return impl_->core.res.rank;
}
double Data::smallestSingularValue() const {
  const EntryGuard guard(impl_->core.busy);
  if (!guard) return impl_->core.res.sigma_min;  // another thread is inside: no lazy computation
  return impl_->core.smallestSingularValue();
}
const Matrix6X& Data::linkAccelerations() const {
  const EntryGuard guard(impl_->core.busy);
  if (!guard) return impl_->core.res.link_acc;  // another thread is inside: no lazy computation
  if (impl_->friction_last) return impl_->friction_core->linkAccelerations();
  return impl_->core.linkAccelerations();
}
const Eigen::VectorXd& Data::frictionTorques() const noexcept {
  if (impl_->stage_joints) return impl_->contact_stage->joint_friction;
  return impl_->friction_last ? impl_->friction_core->friction_ : impl_->zeros;
}
const Eigen::VectorXd& Data::limitTorques() const noexcept {
  if (impl_->stage_joints) return impl_->contact_stage->joint_limit;
  return impl_->friction_last ? impl_->friction_core->limit_ : impl_->zeros;
}
const std::vector<JointStatus>& Data::jointStatus() const noexcept {
  return impl_->status_per_joint;
}
double Data::gaussValue() const {
  const EntryGuard guard(impl_->core.busy);
  if (guard && impl_->stage_joints) return impl_->contact_stage->gaussValue(*impl_);
  if (!guard || !impl_->friction_last) return std::numeric_limits<double>::quiet_NaN();
  return impl_->friction_core->gaussValue();
}
int Data::iterations() const noexcept {
  return impl_->friction_last ? impl_->friction_core->iterations_ : 0;
}

Eigen::Map<const Matrix3X> Data::contactForces() const noexcept {
  if (!impl_->contacts_last) return Eigen::Map<const Matrix3X>(nullptr, 3, 0);
  return Eigen::Map<const Matrix3X>(impl_->contact_stage->forces.data(), 3, impl_->contact_stage->count);
}
const std::vector<ContactStatus>& Data::contactStatus() const noexcept {
  static const std::vector<ContactStatus> none;
  return impl_->contacts_last ? impl_->contact_stage->status : none;
}
ContactOutcome Data::contactOutcome() const noexcept {
  return impl_->contacts_last ? impl_->contact_stage->outcome : ContactOutcome::None;
}

Status Data::responseColumns(const Eigen::Ref<const Eigen::VectorXi>& joints, Eigen::Ref<Eigen::MatrixXd> dqdd,
                             Eigen::Ref<Eigen::MatrixXd> dtau_cmd) {
  detail::HdCore& c = impl_->core;
  const EntryGuard guard(c.busy);
  if (!guard) return Status(Error::ConcurrentCall, "another thread is inside a call on this Data");
  return impl_->status(c.responseColumns(joints, dqdd, dtau_cmd, nullptr));
}

Status Data::wrenchResponseColumns(const Eigen::Ref<const Eigen::VectorXi>& segments,
                                   const Eigen::Ref<const Matrix6X>& wrenches, Eigen::Ref<Eigen::MatrixXd> dqdd) {
  detail::HdCore& c = impl_->core;
  const EntryGuard guard(c.busy);
  if (!guard) return Status(Error::ConcurrentCall, "another thread is inside a call on this Data");
  return impl_->status(c.wrenchResponse(segments, wrenches, dqdd, nullptr));
}

Status Data::commandTorquesOf(const Eigen::Ref<const Eigen::VectorXd>& nu, Eigen::Ref<Eigen::VectorXd> tau_cmd) {
  detail::HdCore& c = impl_->core;
  const EntryGuard guard(c.busy);
  if (!guard) return Status(Error::ConcurrentCall, "another thread is inside a call on this Data");
  return impl_->status(c.commandTorquesOf(nu, tau_cmd));
}

Status Data::inverseInertiaTimes(const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> out) {
  detail::HdCore& c = impl_->core;
  const EntryGuard guard(c.busy);
  if (!guard) return Status(Error::ConcurrentCall, "another thread is inside a call on this Data");
  if (!c.res.solved)
    return impl_->status(c.fail(HdSolver::E_NO_SOLUTION, "inverseInertiaTimes() needs a successful solve() first"));
  if (c.model.floating)
    return impl_->status(
        c.fail(HdSolver::E_INVALID_OPTIONS, "inverseInertiaTimes() is not supported on a floating base yet"));
  const auto n = static_cast<Eigen::Index>(c.model.nj);
  if (tau.size() != n || out.size() != n)
    return impl_->status(c.fail(KDL::SolverI::E_SIZE_MISMATCH, "tau has %ld and out %ld entries, expected %u (joints)",
                                (long)tau.size(), (long)out.size(), c.model.nj));
  c.inverseInertia(tau, out);
  return Status();
}

}  // namespace vereshchagin
