/// @file
/// WholeBodyCall: whole-body least effort (whole_body.hpp) as the Python package calls it,
/// vereshchagin.whole_body.least_effort through the bindings' Solver. The arguments it shares with
/// Solver.solve (q, qd, f_ext as an array or a dict of frame wrenches, tau_ff, and the supports as
/// contacts) arrive as row 0 of a BatchInput that the solve's own parser checked (batch_args.hpp:
/// the same messages); the task blocks and the actuated mask are checked here, with messages that
/// name them. One WholeBodySolver is kept across calls and built at the first one; a call with
/// more supports or task rows than it has room for rebuilds it larger. Its capacities size the
/// workspace only: every call writes all it reads, so a call's results do not depend on the calls
/// before it (tests/unit/test_whole_body_args.py checks that bit for bit).
#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

#include "vereshchagin/array_arg.hpp"
#include "vereshchagin/batch_args.hpp"
#include "vereshchagin/whole_body.hpp"

namespace vereshchagin {

/// One Python Solver's least-effort calls (see the top of this file). Not thread-safe: the caller
/// serializes the calls (the Python Solver's lock).
class WholeBodyCall {
 public:
  WholeBodyCall();   ///< Nothing allocated before the first start().
  ~WholeBodyCall();  ///< (the solver's workspace)
  WholeBodyCall(const WholeBodyCall&) = delete;
  WholeBodyCall& operator=(const WholeBodyCall&) = delete;

  /// Starts a call on `model` (the same one at every call; it must outlive this object; the first
  /// call allocates the input): the input becomes row 0 of `args` (q: nq entries, q_dot: nv, f_ext
  /// and the frame wrenches, ff_torques: nv, a floating base's rows a wrench on it, contacts: the
  /// supports), with `gravity` (physical gravity, base axes, m/s^2) and no task block.
  void start(const Model& model, const BatchInput& args, const KDL::Vector& gravity);

  /// Appends a task block on `segment` (-1: the base body, kCenterOfMass: the centre of mass,
  /// else a segment in segment order): `alpha` (6, m) unit constraint wrenches [force; moment] in
  /// base axes, moment about `point` ((3,), m, in the frame whose pose in the segment's tip frame
  /// is `frame`: a merged link's, identity for the tip itself; for -1 the base's own frame), m <= 6
  /// ((6,): one column), and `beta` (m,) (for m = 1 also a scalar), ConstraintBlock::beta's
  /// set-points. Returns "" or the message, naming the block by `label` ("task[None] alpha must
  /// have shape (6, m) ...", "task[None] beta contains NaN or Inf ...", "task[None] point ...").
  std::string addTask(int segment, const KDL::Frame& frame, const ArrayArg& point, const ArrayArg& alpha,
                      const ArrayArg& beta, const std::string& label);

  /// Solves the started call with `actuated` (nullptr: every joint has a motor; else n_joints
  /// values, non-zero: a motor; a floating base never has one). A mask of another shape or with
  /// NaN is refused with Error::SizeMismatch ("actuated must have shape (n,), got (...)"); the
  /// rest as WholeBodySolver::solve(). The status's message lives in this object until its next call.
  Status solve(const ArrayArg* actuated);

  /// The results of the last successful solve() (tau: nv, forces: 3 x k, qdd: nv; whole_body.hpp).
  const WholeBodyResult& result() const { return result_; }

 private:
  const Model* model_ = nullptr;
  std::unique_ptr<SolveInput> input_;        // the call's input: the arguments, then the task blocks
  BatchArgs task_args_;                      // checks one task block's alpha and beta at a time
  std::unique_ptr<WholeBodySolver> solver_;  // built at the first solve(), rebuilt larger when needed
  WholeBodyOptions options_;                 // solver_'s capacities
  Eigen::VectorXi actuated_;                 // the mask as WholeBodySolver::solve takes it
  WholeBodyResult result_;
  std::string message_;  // the message of a refused mask
};

}  // namespace vereshchagin
