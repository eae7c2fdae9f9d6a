#include "engine.hpp"

#include <algorithm>

namespace vsbind {

Engine::Engine(const vereshchagin::Model& model, const KDL::Vector& gravity, const vereshchagin::SolverOptions& opt)
    : nj(model.nrOfJoints()), ns(model.nrOfSegments()), model_(model), data_(model, opt), input_(model) {
  input_.gravity = gravity;
}

// The row as a SolveInput: blocks (row-major alpha) with their points and this row's weights,
// f_ext, wrenches on merged links, tau_ff and friction.
void Engine::fillInput(const RowInputs& in) {
  using MapV = Eigen::Map<const Eigen::VectorXd>;
  input_.clear();
  input_.q = MapV(in.q, nj);
  input_.q_dot = MapV(in.qd, nj);
  if (in.f_ext) input_.f_ext = Eigen::Map<const vereshchagin::Matrix6X>(in.f_ext, 6, ns);  // (ns, 6) rows
  if (in.tau_ff) input_.ff_torques = MapV(in.tau_ff, nj);
  input_.friction = in.friction;
  int col = 0;
  for (int b = 0; b < in.n_blocks; ++b) {
    const ConstraintBlock& blk = in.blocks[b];
    if (blk.segment < 0) {  // alpha on the last segment of a chain without segments: nothing can move
      col += blk.cols;
      continue;
    }
    vereshchagin::ConstraintBlock& out = input_.constraints.emplace_back();
    out.segment = blk.segment;
    out.columns = blk.cols;
    for (int c = 0; c < blk.cols; ++c, ++col) {
      for (int r = 0; r < 6; ++r) out.alfa(r, c) = blk.alpha[r * blk.cols + c];
      out.beta(c) = blk.beta[c];
      if (in.f_ext_pass_through) out.f_ext_pass_through(c) = in.f_ext_pass_through[col];
      if (in.tau_ff_pass_through) out.ff_pass_through(c) = in.tau_ff_pass_through[col];
    }
    if (blk.has_offset) out.point = vereshchagin::Vector3(blk.offset.x(), blk.offset.y(), blk.offset.z());
  }
  columns_ = col;
  for (int k = 0; k < in.n_link_wrenches; ++k) {
    const LinkWrench& w = in.link_wrenches[k];
    vereshchagin::FrameWrench& out = input_.wrenches.emplace_back();
    out.segment = w.segment;
    out.wrench = Eigen::Map<const vereshchagin::Vector6>(w.wrench);
    out.point = vereshchagin::Vector3(w.offset.x(), w.offset.y(), w.offset.z());
  }
}

int Engine::run(const RowInputs& in) {
  fillInput(in);
  last_friction_ = in.friction != nullptr;
  const vereshchagin::Status s = vereshchagin::solve(model_, data_, input_);
  message_ = s.message();
  return s.value();
}

void Engine::writeCore(double* qdd, double* tau_cmd, double* nu, double* link_acc, int* rank, double* smin) {
  std::copy(data_.qdd().data(), data_.qdd().data() + nj, qdd);
  std::copy(data_.commandTorques().data(), data_.commandTorques().data() + nj, tau_cmd);
  // nu has no entry for columns on a chain without segments (nothing moves): their magnitude is 0.
  std::fill(nu, nu + columns_, 0.0);
  std::copy(data_.nu().data(), data_.nu().data() + data_.nu().size(), nu);
  if (link_acc) {
    const vereshchagin::Matrix6X& acc = data_.linkAccelerations();
    std::copy(acc.data(), acc.data() + 6 * (ns + 1), link_acc);
  }
  *rank = data_.constraintRank();
  *smin = data_.smallestSingularValue();
}

void Engine::writeFriction(double* friction_torque, double* limit_torque, int* status, double* gauss, int* iterations) {
  std::copy(data_.frictionTorques().data(), data_.frictionTorques().data() + nj, friction_torque);
  std::copy(data_.limitTorques().data(), data_.limitTorques().data() + nj, limit_torque);
  for (unsigned int j = 0; j < nj; ++j) status[j] = static_cast<int>(data_.jointStatus()[j]);
  *gauss = data_.gaussValue();
  *iterations = data_.iterations();
}

}  // namespace vsbind
