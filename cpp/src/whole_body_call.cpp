// WholeBodyCall (whole_body_call.hpp): the Python face's least-effort call on a kept
// WholeBodySolver, its input filled from the solve's checked arguments and the task blocks.
#include "vereshchagin/whole_body_call.hpp"

#include <algorithm>

namespace vereshchagin {

WholeBodyCall::WholeBodyCall() = default;
WholeBodyCall::~WholeBodyCall() = default;

void WholeBodyCall::start(const Model& model, const BatchInput& args, const KDL::Vector& gravity) {
  if (!input_) input_ = std::make_unique<SolveInput>(model, 4, 4);
  model_ = &model;
  args.fillRow(0, *input_);  // clears the input (task blocks included), then row 0 of the arguments
  input_->gravity = gravity;
}

std::string WholeBodyCall::addTask(int segment, const KDL::Frame& frame, const ArrayArg& point, const ArrayArg& alpha,
                                   const ArrayArg& beta, const std::string& label) {
  if (std::string why = vectorMessage(point, (label + " point").c_str(), 3); !why.empty()) return why;
  task_args_.start(/*batch=*/false, *model_);
  const std::string alpha_name = label + " alpha", beta_name = label + " beta";
  if (std::string why = task_args_.block(segment, alpha, alpha_name.c_str()); !why.empty()) return why;
  if (std::string why = task_args_.setPoint(&beta, false, beta_name.c_str(), ""); !why.empty()) return why;
  const BlockRows& rows = task_args_.input.blocks.back();
  ConstraintBlock& block = input_->constraints.emplace_back();
  block.segment = segment;
  const KDL::Vector at = frame * KDL::Vector(point.data[0], point.data[1], point.data[2]);
  block.point = Vector3(at.x(), at.y(), at.z());
  block.columns = rows.columns;
  for (int c = 0; c < rows.columns; ++c) {
    for (int r = 0; r < 6; ++r) block.alfa(r, c) = rows.alpha.data[r * rows.columns + c];  // (6, m) row-major
    block.beta(c) = rows.beta.data[c];
  }
  return {};
}

Status WholeBodyCall::solve(const ArrayArg* actuated) {
  const long nj = static_cast<long>(model_->nrOfJoints());
  actuated_.resize(actuated ? nj : 0);
  if (actuated) {
    if (message_ = vectorMessage(*actuated, "actuated", nj); !message_.empty())
      return Status(Error::SizeMismatch, message_.c_str());
    for (long j = 0; j < nj; ++j) actuated_(j) = actuated->data[j] != 0.0 ? 1 : 0;
  }
  int rows = 0;
  for (const ConstraintBlock& block : input_->constraints) rows += block.columns;
  const int supports = static_cast<int>(input_->contacts.size());
  if (!solver_ || rows > options_.max_task_rows || supports > options_.max_contacts) {
    options_.max_task_rows = std::max(options_.max_task_rows, rows);
    options_.max_contacts = std::max(options_.max_contacts, supports);
    solver_ = std::make_unique<WholeBodySolver>(*model_, options_);
  }
  return solver_->solve(*input_, actuated_, result_);
}

}  // namespace vereshchagin
