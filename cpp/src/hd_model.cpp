// HdCore's model: built from a ModelSource (segments in preorder with their parents and joint
// indices), validated, and the workspace sized for it; input and result checks. Conventions in
// hd_solver.hpp, types in hd_core.hpp.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

#include "hd_core.hpp"
#include "model_validation.hpp"

namespace vereshchagin {
namespace detail {

HdCore::HdCore(std::shared_ptr<const HdModel> model_in, const Vector6& root_acc_in, const SolverOptions& opts)
    : model_owner(std::move(model_in)), model(*model_owner), options(opts), root_acc(root_acc_in) {
  options.inertia_check = model.inertia_check;
  allocateWorkspace();
  model_error = model.error;
  if (model_error != 0) {
    std::snprintf(message.data(), message.size(), "%s", model.message.c_str());
    return;
  }
  SolverOptions wanted = opts;
  wanted.inertia_check = model.inertia_check;
  const int rc = setOptions(wanted);
  if (rc != 0) model_error = rc;
}

int constraintCapacity(const SolverOptions& opts, unsigned int ns) {
  const int all = std::max<int>(kMaxConstraints, kMaxConstraints * static_cast<int>(ns));  // 6 per segment
  const int wanted = opts.max_constraints > 0 ? opts.max_constraints : SolverOptions::kDefaultConstraintCapacity;
  return std::min(all, wanted);
}

int HdCore::setOptions(const SolverOptions& opts) {
  if (!std::isfinite(opts.rcond) || opts.rcond < 0.0 || opts.rcond >= 1.0) {
    return fail(HdSolver::E_INVALID_OPTIONS, "options.rcond must be finite and in [0, 1), got %g", opts.rcond);
  }
  if (!std::isfinite(opts.damping) || opts.damping < 0.0 ||
      (opts.policy == SingularityPolicy::DampedLeastSquares && opts.damping <= 0.0)) {
    return fail(HdSolver::E_INVALID_OPTIONS,
                "options.damping must be finite and > 0 for the damped least-squares policy, got %g", opts.damping);
  }
  if (opts.max_constraints < 0)
    return fail(HdSolver::E_INVALID_OPTIONS, "options.max_constraints must be >= 0 (0: the default), got %d",
                opts.max_constraints);
  const bool resize = constraintCapacity(opts, model.ns) != mcap;
  options = opts;
  options.inertia_check = model.inertia_check;  // the model's (a model is rebuilt by its owner)
  res.solved = false;
  if (resize) allocateWorkspace();
  return 0;
}

int HdCore::fail(int code, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(message.data(), message.size(), fmt, args);
  va_end(args);
  return code;
}

void HdCore::allocateWorkspace() {
  const unsigned int nj = model.nj, ns = model.ns;
  ws.seg.assign(ns, SegmentState());
  res.qdd = res.tau_cmd = Eigen::VectorXd::Zero(nj + model.nbv);  // nv: a floating base's entries first
  ws.zero_joints = Eigen::VectorXd::Zero(nj);
  ResponseWorkspace& r = ws.response;
  r.width = std::max<long>(1, std::min<long>(nj, ResponseWorkspace::kMaxWidth));
  r.sdp = Eigen::MatrixXd::Zero(ns, r.width);
  r.axis = r.axis_inertia = Matrix6X::Zero(6, ns);
  r.offset = Matrix3X::Zero(3, ns);
  r.force = Matrix6X::Zero(6, std::max<long>(r.width, kMaxConstraints));
  r.tmp3 = Matrix3X::Zero(3, std::max<long>(r.width, kMaxConstraints));
  r.holder = Eigen::VectorXi::Zero(r.width);
  r.branch_acc = Matrix6X::Zero(6, static_cast<Eigen::Index>(r.width) * model.n_branch);
  res.link_acc = Matrix6X::Zero(6, ns + 1);
  res.link_acc_known = true;  // zeros until the first solve
  ws.zero_f_ext = Matrix6X::Zero(6, ns);
  ws.alfa_buf.setZero();
  ws.inertia_force = ws.inertia_acc = Matrix6X::Zero(6, ns);
  ws.inertia_joint = Eigen::VectorXd::Zero(nj);
  mcap = constraintCapacity(options, ns);
  PassThroughState& pt = ws.pt;
  pt.energy = pt.tmp = Eigen::VectorXd::Zero(mcap);
  pt.free = Eigen::VectorXd::Zero(nj);
  pt.used = false;
  res.general = false;
  CouplingGeneral& g = ws.general;
  g.order = Eigen::VectorXi::Zero(mcap);
  g.seg_count = Eigen::VectorXi::Zero(ns);
  g.active.assign(ns + 1, 0);
  g.anew = g.acur = Matrix6X::Zero(6, mcap);
  g.eg = Eigen::MatrixXd::Zero(mcap, std::max<unsigned int>(ns, 1));
  g.ug = g.nug = g.rhs = g.tmp = g.invg = Eigen::VectorXd::Zero(mcap);
  res.nu_user = Eigen::VectorXd::Zero(mcap);
  g.kg = g.cholg = g.vg = g.work_g = Eigen::MatrixXd::Zero(mcap, mcap);
  g.work_v = Eigen::MatrixXd::Zero(mcap, 4);  // smallestEigenvalue's scratch: 4 columns
  g.seg_force = Matrix6X::Zero(6, ns);
  ws.base.e = ws.base.De = Eigen::MatrixXd::Zero(model.nbv, mcap);
  r.cmd_per_nu = Eigen::MatrixXd::Zero(nj + model.nbv, mcap);
  r.base_sdp = Eigen::MatrixXd::Zero(model.nbv, r.width);
  r.base_acc = Matrix6X::Zero(6, model.floating ? r.width : 0);
  r.energy = Eigen::MatrixXd::Zero(mcap, r.width);
  r.dnu = Eigen::MatrixXd::Zero(mcap, r.width);
  res.m = 0;
  res.rank = 0;
  res.sigma_min = 0.0;
  res.sigma_known = true;
}

// Reject robots whose joints have no inertia to move. Checked at a generic configuration (not
// q = 0, where a body may sit on an axis by coincidence); a configuration-dependent loss of
// inertia is reported by solve().
int HdCore::checkGenericConfiguration() {
  Eigen::VectorXd q_generic(model.nj);
  for (unsigned int k = 0; k < model.nj; ++k) q_generic(k) = 0.7 + 0.61 * k;
  state_q = state_q_dot = nullptr;
  outwardSweep(q_generic, ws.zero_joints, ws.zero_f_ext);
  return model.is_chain ? inwardSweep(ws.alfa_buf.leftCols(0), ws.zero_joints)
                        : inwardSweepGeneral(ws.alfa_buf.leftCols(0), ws.zero_joints);
}

int HdCore::checkInputs(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                        const Eigen::Ref<const Matrix6X>& alfa, const Eigen::Ref<const Eigen::VectorXd>& beta,
                        const Eigen::Ref<const Matrix6X>& f_ext, const Eigen::Ref<const Eigen::VectorXd>& ff_torques,
                        int max_columns) {
  if (model_error != 0) return model_error;  // message still holds the model's problem
  const long nj = model.nj, ns = model.ns;
  constexpr int E_SIZE = KDL::SolverI::E_SIZE_MISMATCH, E_NF = HdSolver::E_NONFINITE_INPUT;
  if (q.size() != nj) return fail(E_SIZE, "q has %ld entries, expected %ld (joints)", (long)q.size(), nj);
  if (q_dot.size() != nj) return fail(E_SIZE, "q_dot has %ld entries, expected %ld (joints)", (long)q_dot.size(), nj);
  if (ff_torques.size() != nj && ff_torques.size() != 0)
    return fail(E_SIZE, "ff_torques has %ld entries, expected %ld (joints) or 0", (long)ff_torques.size(), nj);
  if (f_ext.cols() != ns && f_ext.cols() != 0)
    return fail(E_SIZE, "f_ext has %ld wrenches, expected %ld (segments) or 0", (long)f_ext.cols(), ns);
  if (alfa.cols() > max_columns)
    return fail(HdSolver::E_TOO_MANY_CONSTRAINTS,
                "alfa has %ld columns, at most %d constraints are supported (6 per segment, and at most "
                "SolverOptions::max_constraints in all)",
                (long)alfa.cols(), max_columns);
  if (beta.size() != alfa.cols())
    return fail(E_SIZE, "beta has %ld entries, expected %ld (one per alfa column)", (long)beta.size(),
                (long)alfa.cols());
  if (!q.allFinite()) return fail(E_NF, "q contains NaN or Inf");
  if (!q_dot.allFinite()) return fail(E_NF, "q_dot contains NaN or Inf");
  if (!ff_torques.allFinite()) return fail(E_NF, "ff_torques contains NaN or Inf");
  if (!f_ext.allFinite()) return fail(E_NF, "f_ext contains NaN or Inf");
  if (!alfa.allFinite()) return fail(E_NF, "alfa contains NaN or Inf");
  if (!beta.allFinite()) return fail(E_NF, "beta contains NaN or Inf");
  if (!root_acc.allFinite()) return fail(E_NF, "root acceleration contains NaN or Inf");
  return 0;
}

// Finite inputs can still overflow (|q_dot| ~ 1e160 squares to Inf): never return Inf or NaN,
// nor results beyond kMaxResult whose products (energies, powers) would overflow. An overflowing
// coupling matrix (kappa >= trace K; e.g. alfa columns of size 1e200) would be truncated to rank 0,
// silently dropping the task. Inf and NaN propagate outward through the link accelerations: the
// leaves tell (on a chain, the last segment).
int HdCore::checkBounded(const Eigen::Ref<const Eigen::VectorXd>& nu, const Eigen::Ref<const Eigen::VectorXd>& q_dot,
                         const Eigen::Ref<const Eigen::VectorXd>& beta, const Eigen::Ref<const Matrix6X>& f_ext,
                         const Eigen::Ref<const Eigen::VectorXd>& ff_torques) {
  const int ns = static_cast<int>(model.ns);
  bool finite =
      std::isfinite(ws.kappa) && detail::bounded(res.qdd) && detail::bounded(res.tau_cmd) && detail::bounded(nu);
  for (int i = ns - 1; i >= 0 && finite; --i) {
    if (model.subtree_end[i] == i + 1) finite = detail::bounded(ws.seg[i].xdd);  // a leaf
    if (model.is_chain) break;
  }
  if (finite) return 0;
  return fail(HdSolver::E_NONFINITE_RESULT,
              "the results overflow (Inf/NaN or beyond 1e150): inputs too large (max |q_dot| %g, "
              "max |ff_torques| %g, max |f_ext| %g, max |beta| %g)",
              q_dot.size() ? q_dot.cwiseAbs().maxCoeff() : 0.0,
              ff_torques.size() ? ff_torques.cwiseAbs().maxCoeff() : 0.0,
              f_ext.size() ? f_ext.cwiseAbs().maxCoeff() : 0.0, beta.size() ? beta.cwiseAbs().maxCoeff() : 0.0);
}

namespace {

double maxAbs(const Eigen::Ref<const Eigen::VectorXd>* v) {
  return v && v->size() ? v->cwiseAbs().maxCoeff() : 0.0;
}

}  // namespace

// Joint i's articulated inertia failed the test of articulate(). A model problem (the joint moves
// nothing) or a state whose size let round-off take over (hd_solver.hpp, "Degenerate joints").
int HdCore::degenerate(int i) {
  const SegmentState& s = ws.seg[i];
  const int joint = model.seg[i].joint;
  const char* name = model.jointName(i).c_str();
  const double size = model.seg[i].d_tolerance / 1e-13;  // what the joint moves
  const bool physical = options.inertia_check == InertiaCheck::Physical;
  const double q_max = maxAbs(state_q), q_dot_max = maxAbs(state_q_dot);
  if (state_q != nullptr &&
      (!std::isfinite(s.D) || !s.IA.allFinite() || (physical && s.D < -model.seg[i].d_tolerance) || q_max > 1e15 ||
       s.IA.cwiseAbs().maxCoeff() > 1e8 * size))
    return fail(HdSolver::E_STATE_OUT_OF_RANGE,
                "the state is out of range: joint %d ('%s') gets an articulated inertia of %g where what it moves "
                "has size %g; round-off dominates at this state (max |q| %g, max |q_dot| %g): not a model problem, "
                "the state is not physical (a diverged simulation?)",
                joint, name, s.D, size, q_max, q_dot_max);
  if (options.inertia_check == InertiaCheck::JointSpace && s.D < 0.0)
    return fail(HdSolver::E_DEGENERATE_INERTIA,
                "joint %d ('%s') has articulated inertia D = %g <= 0 at this configuration: the model's "
                "joint-space inertia matrix is not positive definite here (inertia_check = joint_space "
                "accepts non-physical link inertias only where it is)",
                joint, name, s.D);
  return fail(HdSolver::E_DEGENERATE_INERTIA,
              "joint %d ('%s') has zero articulated inertia (%g): the bodies it moves have no "
              "mass or inertia about its axis and it has no rotor inertia",
              joint, name, s.D);
}

}  // namespace detail
}  // namespace vereshchagin
