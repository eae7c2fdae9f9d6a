// solve(model, data, input) (data.hpp): one validation of the whole input, its assembly into the
// core's arguments (blocks -> columns, frame wrenches -> f_ext, pass-through weights, gravity ->
// root acceleration), then the sweeps, with the friction stage when the input has friction.
#include <cmath>

#include "vereshchagin/data.hpp"

#include "contact_stage.hpp"
#include "data_impl.hpp"
#include "entry_guard.hpp"
#include "friction_core.hpp"
#include "hd_core.hpp"

namespace vereshchagin {

namespace {

using detail::DataImpl;
using detail::HdCore;
constexpr int E_SIZE = KDL::SolverI::E_SIZE_MISMATCH, E_RANGE = KDL::SolverI::E_OUT_OF_RANGE,
              E_NF = HdSolver::E_NONFINITE_INPUT;
constexpr const char* kWeights = "(0: the constraint compensates that driver, 1: its effect passes through)";

// A block's shape, segment, point and weights (its alfa and beta are checked assembled, with
// HdSolver's messages); `first` is its first column in nu's order, the index the messages give.
int checkBlock(HdCore& c, std::size_t b, const ConstraintBlock& k, int first) {
  if (k.columns < 0 || k.columns > HdSolver::kMaxConstraints)
    return c.fail(E_SIZE, "constraints[%zu] has %d columns, expected 0 to %d", b, k.columns, HdSolver::kMaxConstraints);
  if (k.segment < 0 || k.segment >= static_cast<int>(c.model.ns))
    return c.fail(E_RANGE, "constraints[%zu].segment = %d is out of range [0, %u)", b, k.segment, c.model.ns);
  if (!k.point.allFinite()) return c.fail(E_NF, "constraints[%zu].point contains NaN or Inf", b);
  if (k.classical && !k.classical_acceleration.allFinite())
    return c.fail(E_NF, "constraints[%zu].classical_acceleration contains NaN or Inf", b);
  for (int j = 0; j < k.columns; ++j) {
    const double pf = k.f_ext_pass_through(j), pt = k.ff_pass_through(j);
    if (!(pf >= 0.0 && pf <= 1.0))
      return c.fail(E_RANGE, "f_ext_pass_through[%d] must be in [0, 1] %s, got %g", first + j, kWeights, pf);
    if (!(pt >= 0.0 && pt <= 1.0))
      return c.fail(E_RANGE, "tau_ff_pass_through[%d] (ff_pass_through) must be in [0, 1] %s, got %g", first + j,
                    kWeights, pt);
  }
  return 0;
}

// What the core does not check itself: blocks, frame wrenches, gravity. 0 or an error code.
int checkInput(HdCore& c, const SolveInput& in) {
  int columns = 0;
  for (std::size_t b = 0; b < in.constraints.size(); ++b) {
    if (const int rc = checkBlock(c, b, in.constraints[b], columns)) return rc;
    columns += in.constraints[b].columns;
  }
  if (columns > c.mcap)
    return c.fail(HdSolver::E_TOO_MANY_CONSTRAINTS,
                  "this solve has %d constraint columns; the solver takes at most %d in all (6 per segment, and "
                  "SolverOptions::max_constraints, Solver(..., max_constraints=) in Python, sizes its workspace)",
                  columns, c.mcap);
  for (std::size_t k = 0; k < in.wrenches.size(); ++k) {
    const FrameWrench& w = in.wrenches[k];
    if (w.segment < 0 || w.segment >= static_cast<int>(c.model.ns))
      return c.fail(E_RANGE, "wrenches[%zu].segment = %d is out of range [0, %u)", k, w.segment, c.model.ns);
    if (!w.wrench.allFinite() || !w.point.allFinite()) return c.fail(E_NF, "wrenches[%zu] contains NaN or Inf", k);
  }
  bool classical = false, moving_base = false;
  for (const ConstraintBlock& b : in.constraints) classical = classical || b.classical;
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(in.gravity(k))) return c.fail(E_NF, "gravity contains NaN or Inf");
    if (!std::isfinite(in.base_acceleration.vel(k)) || !std::isfinite(in.base_acceleration.rot(k)))
      return c.fail(E_NF, "base_acceleration contains NaN or Inf");
    moving_base = moving_base || in.base_acceleration.vel(k) != 0.0 || in.base_acceleration.rot(k) != 0.0;
  }
  if (!(std::isfinite(in.time_step) && in.time_step >= 0.0))
    return c.fail(E_RANGE, "time_step must be finite and >= 0 (s; 0: the instant), got %g", in.time_step);
  if (c.model.floating && moving_base)
    return c.fail(E_RANGE,
                  "on a floating base, base_acceleration must be zero: a moving world is not supported yet "
                  "(docs/floating-base.md)");
  if (classical && moving_base)
    return c.fail(E_RANGE,
                  "a classical set-point (ConstraintBlock::classical) needs a base at rest: base_acceleration "
                  "must be zero");
  return 0;
}

// The blocks as columns (caller's order), their pass-through weights, the frame loads and the
// root acceleration base_acceleration - [gravity; 0]; returns the column count.
int assemble(DataImpl& d, const SolveInput& in) {
  int col = 0;
  bool f_any = false, t_any = false, points = false, classical = false;
  for (const ConstraintBlock& b : in.constraints) {
    classical = classical || b.classical;
    for (int j = 0; j < b.columns; ++j, ++col) {
      d.alfa.col(col) = b.alfa.col(j);
      d.beta(col) = b.classical ? 0.0 : b.beta(j);  // classical: set in the sweep (frame_loads.cpp)
      d.segments(col) = b.segment;
      d.weights.f(col) = b.f_ext_pass_through(j);
      d.weights.t(col) = b.ff_pass_through(j);
      f_any = f_any || b.f_ext_pass_through(j) != 0.0;
      t_any = t_any || b.ff_pass_through(j) != 0.0;
    }
    points = points || !b.point.isZero(0.0);
  }
  d.weights.m = f_any || t_any ? col : -1;
  d.weights.f_any = f_any;
  d.weights.t_any = t_any;
  d.loads.input = &in;
  d.loads.points = points;
  d.loads.classical = classical;
  d.loads.wrenches = !in.wrenches.empty();
  if (d.loads.wrenches) d.f_ext = in.f_ext;  // the wrenches are added in the sweep
  HdCore& c = d.core;
  for (int k = 0; k < 3; ++k) {
    c.root_acc(k) = in.base_acceleration.vel(k) - in.gravity(k);
    c.root_acc(3 + k) = in.base_acceleration.rot(k);
  }
  c.ws.pt.weights = &d.weights;
  c.loads = d.loads.points || d.loads.wrenches || d.loads.classical ? &d.loads : nullptr;
  return col;
}

// The sweeps (and the friction stage) on the assembled input.
int run(DataImpl& d, const SolveInput& in, int m) {
  HdCore& c = d.core;
  const bool f_zero = !d.loads.wrenches && (in.f_ext.array() == 0.0).all();
  const Eigen::Ref<const Matrix6X> f_ext = d.loads.wrenches ? Eigen::Ref<const Matrix6X>(d.f_ext)
                                           : f_zero         ? Eigen::Ref<const Matrix6X>(c.ws.zero_f_ext.leftCols(0))
                                                            : Eigen::Ref<const Matrix6X>(in.f_ext);
  const auto alfa = d.alfa.leftCols(m);
  const auto beta = d.beta.head(m);
  const Eigen::Ref<const Eigen::VectorXi> segments = d.segments.head(m);
  if (in.friction == nullptr) return c.solveSegments(in.q, in.q_dot, alfa, beta, segments, f_ext, in.ff_torques);
  return d.friction().solveImpl(in.q, in.q_dot, alfa, beta, &segments, f_ext, in.ff_torques, *in.friction,
                                in.time_step);
}

// Joint status of the friction stage (or all Moving after a frictionless solve); with contacts
// and friction, or over a time step, the contact stage writes them (stage_joints).
void recordStatus(DataImpl& d, bool with_friction) {
  if (!with_friction && !d.friction_last && !d.stage_joints) return;
  for (std::size_t j = 0; j < d.status_per_joint.size(); ++j)
    d.status_per_joint[j] = with_friction ? static_cast<JointStatus>(d.friction_core->status_[j]) : JointStatus::Moving;
}

}  // namespace

Status solve(const Model& model, Data& data, const SolveInput& input) {
  DataImpl& d = data.impl();
  HdCore& c = d.core;
  const detail::EntryGuard guard(c.busy);
  if (!guard)
    return Status(Error::ConcurrentCall,
                  "another thread is inside a call on this Data: the call was refused (use one Data per thread)");
  if (!model.sameAs(d.model)) {
    c.res.solved = false;
    return d.status(c.fail(KDL::SolverI::E_NOT_UP_TO_DATE, "this Data was built for another Model"));
  }
  int rc = c.model_error;
  if (rc == 0) rc = checkInput(c, input);
  if (rc != 0) {
    c.res.solved = false;
    recordStatus(d, false);
    d.friction_last = false;
    d.contacts_last = false;
    d.stage_joints = false;
    return d.status(rc);
  }
  // The contact stage with contacts (joint friction, at the instant or over a time step, alone:
  // the friction stage).
  const bool with_friction = input.friction != nullptr;
  // (On a floating base the contact stage also takes joint friction alone: the friction stage has
  // no base step.)
  const bool with_contacts = !input.contacts.empty() || (c.model.floating && with_friction);
  if (with_contacts) rc = d.contacts().check(c, input);
  if (rc == 0) rc = with_contacts ? d.contacts().solve(d, input) : detail::runInput(d, input);
  d.contacts_last = with_contacts && rc >= 0;  // (rc 1: Degraded, a result)
  const bool stage_joints = with_contacts && rc >= 0 && (with_friction || input.time_step > 0.0);
  if (!stage_joints) recordStatus(d, with_friction && rc >= 0);  // (else written by the stage)
  d.stage_joints = stage_joints;
  d.friction_last = with_friction && rc >= 0 && !stage_joints;  // (rc 1: Degraded, a result)
  if (rc == 0) {
    c.message[0] = '\0';
    return Status();
  }
  if (with_friction && !with_contacts) return Status(static_cast<Error>(rc), d.friction_core->message_.data());
  return d.status(rc);
}

namespace detail {

int runInput(DataImpl& d, const SolveInput& in) {
  const int m = assemble(d, in);
  const int rc = run(d, in, m);
  d.core.loads = nullptr;
  d.core.ws.pt.weights = nullptr;
  return rc;
}

FrictionCore& DataImpl::friction() {
  if (!friction_core) friction_core = std::make_unique<FrictionCore>(core);
  return *friction_core;
}

}  // namespace detail

}  // namespace vereshchagin
