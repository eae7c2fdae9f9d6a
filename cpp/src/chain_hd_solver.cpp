// ChainHdSolver: a KDL::Chain as HdCore's model source (parent i - 1, joints in chain order) and
// KDL's CartToJnt() entry point. Conventions in hd_solver.hpp.
#include "vereshchagin/chain_hd_solver.hpp"

#include "entry_guard.hpp"
#include "facade_state.hpp"
#include "hd_core.hpp"

namespace vereshchagin {

namespace detail {

ModelSource chainModelSource(const KDL::Chain& chain) {
  detail::ModelSource src;
  const unsigned int ns = chain.getNrOfSegments();
  src.segments.reserve(ns);
  int joint = 0;
  for (unsigned int i = 0; i < ns; ++i) {
    const KDL::Segment& seg = chain.getSegment(i);
    src.segments.push_back(seg);
    src.parent.push_back(static_cast<int>(i) - 1);
    src.joint.push_back(seg.getJoint().getType() == KDL::Joint::Fixed ? -1 : joint++);
  }
  return src;
}

}  // namespace detail

namespace {

ModelOptions modelOptions(const SolverOptions& options) {
  ModelOptions m;
  m.inertia_check = options.inertia_check;
  return m;
}

}  // namespace

ChainHdSolver::ChainHdSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options)
    : HdSolver(Model(chain, modelOptions(options)), root_acc, options),
      chain_(chain),
      f_ext_buf_(Matrix6X::Zero(6, chain.getNrOfSegments())) {}

void ChainHdSolver::updateInternalDataStructures() {
  {
    const detail::EntryGuard guard(core().busy);
    if (!guard) {
      state().stale_model.store(true, std::memory_order_relaxed);  // reported by the next solves
      return;
    }
    rebuild(Model(chain_, modelOptions(options())));
    f_ext_buf_.setZero(6, chain_.getNrOfSegments());
    state().stale_model.store(false, std::memory_order_relaxed);
  }
  state().dropRetired();  // the guard above held its flag
}

int ChainHdSolver::CartToJnt(const KDL::JntArray& q, const KDL::JntArray& q_dot, KDL::JntArray& q_dotdot,
                             const KDL::Jacobian& alfa, const KDL::JntArray& beta, const KDL::Wrenches& f_ext,
                             const KDL::JntArray& ff_torques, KDL::JntArray& command_torques) {
  detail::HdCore& c = core();
  const detail::EntryGuard guard(c.busy);
  if (!guard) return E_CONCURRENT_CALL;
  const unsigned int nj = nrOfJoints(), ns = nrOfSegments();
  if (q_dotdot.rows() != nj)
    return error = c.fail(E_SIZE_MISMATCH, "q_dotdot has %u entries, expected %u", q_dotdot.rows(), nj);
  if (command_torques.rows() != nj)
    return error = c.fail(E_SIZE_MISMATCH, "command_torques has %u entries, expected %u", command_torques.rows(), nj);
  if (f_ext.size() != ns)
    return error = c.fail(E_SIZE_MISMATCH, "f_ext has %zu wrenches, expected %u (segments)", f_ext.size(), ns);
  if (ff_torques.rows() != nj)
    return error = c.fail(E_SIZE_MISMATCH, "ff_torques has %u entries, expected %u", ff_torques.rows(), nj);
  for (unsigned int i = 0; i < ns; ++i) {
    for (int k = 0; k < 3; ++k) {
      f_ext_buf_(k, i) = f_ext[i].force(k);
      f_ext_buf_(3 + k, i) = f_ext[i].torque(k);
    }
  }
  const int rc = solveEntered(q.data, q_dot.data, alfa.data, beta.data, f_ext_buf_, ff_torques.data);
  if (rc != E_NOERROR) return rc;
  q_dotdot.data = qdd();
  command_torques.data = commandTorques();
  return E_NOERROR;
}

}  // namespace vereshchagin
