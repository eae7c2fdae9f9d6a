// SolveInput (input.hpp): one solve's inputs, sized for a model once.
#include <algorithm>

#include "vereshchagin/input.hpp"

namespace vereshchagin {

SolveInput::SolveInput(const Model& model, int blocks, int wrench_count)
    : q(Eigen::VectorXd::Zero(model.nq())),
      q_dot(Eigen::VectorXd::Zero(model.nv())),
      f_ext(Matrix6X::Zero(6, model.nrOfSegments())),
      ff_torques(Eigen::VectorXd::Zero(model.nv())),
      segments_(static_cast<int>(model.nrOfSegments())) {
  reserve(blocks, wrench_count);
}

void SolveInput::setState(const JointPositions& q_in, const JointVelocities& q_dot_in) {
  q = q_in.value();
  q_dot = q_dot_in.value();
}

Status SolveInput::addConstraint(int segment, const Eigen::Ref<const Eigen::MatrixXd>& alfa,
                                 const Eigen::Ref<const Eigen::VectorXd>& beta, const Vector3& point) {
  if (alfa.cols() > 6 || (alfa.rows() != 6 && alfa.cols() != 0))
    return Status(Error::SizeMismatch, "addConstraint: alfa must be 6 x m with m <= 6");
  if (beta.size() != alfa.cols())
    return Status(Error::SizeMismatch, "addConstraint: beta must have one entry per alfa column");
  if (segment < 0 || segment >= segments_)
    return Status(Error::OutOfRange,
                  "addConstraint: the segment is not one of the model's (0 <= segment < n_segments)");
  ConstraintBlock block;
  block.segment = segment;
  block.columns = static_cast<int>(alfa.cols());
  block.alfa.leftCols(block.columns) = alfa;
  block.beta.head(block.columns) = beta;
  block.point = point;
  constraints.push_back(block);
  return Status();
}

Status SolveInput::addConstraint(const FrameRef& frame, const Eigen::Ref<const Eigen::MatrixXd>& alfa,
                                 const Eigen::Ref<const Eigen::VectorXd>& beta) {
  const KDL::Vector& p = frame.in_tip.p;
  return addConstraint(frame.segment, alfa, beta, Vector3(p.x(), p.y(), p.z()));
}

Status SolveInput::addWrench(const FrameRef& frame, const Vector6& wrench) {
  if (frame.segment < 0 || frame.segment >= segments_)
    return Status(Error::OutOfRange,
                  "addWrench: the frame is not on one of the model's segments (the base takes none)");
  FrameWrench w;
  w.segment = frame.segment;
  w.wrench = wrench;
  w.point = Vector3(frame.in_tip.p.x(), frame.in_tip.p.y(), frame.in_tip.p.z());
  wrenches.push_back(w);
  return Status();
}

int SolveInput::columns() const {
  int m = 0;
  for (const ConstraintBlock& b : constraints) m += b.columns;
  return m;
}

void SolveInput::clear() {
  f_ext.setZero();
  ff_torques.setZero();
  constraints.clear();
  wrenches.clear();
  contacts.clear();
  friction = nullptr;
}

void SolveInput::reserve(int blocks, int wrench_count) {
  constraints.reserve(static_cast<std::size_t>(std::max(blocks, 0)));
  wrenches.reserve(static_cast<std::size_t>(std::max(wrench_count, 0)));
  contacts.reserve(static_cast<std::size_t>(std::max(wrench_count, 0)));
}

}  // namespace vereshchagin
