// The friction stage over a time step (SolveInput::time_step > 0) by a slide guess
// (FrictionCore::optimiseStep): every joint with friction is a bounded unknown of the step's box
// QP (docs/time-step.md), but a moving joint usually keeps sliding through the step, its friction
// then the kinetic bound against its velocity, known as at the instant. So each moving joint is
// first guessed sliding (its friction -xg_ = -F sign(qd) in hd_'s solve, not an unknown); a guess
// is refuted when the joint's end velocity does not keep the sign of qd strictly beyond the Stick
// band of frictionOutputs, and the refuted joints join the resting ones as unknowns of the box QP
// (their guessed friction taken back out of the base through their response columns: no new
// solve). Rounds repeat until no standing guess is refuted. The answer is then a KKT point of the
// full problem, so its optimum: an unknown's conditions are the QP's; a standing guess sits on its
// bound x = F sign(qd) with the gradient -(qdd + qd / dt) pointing outward (its end velocity keeps
// the sign of qd). Each round adds one joint at least: at most (moving joints + 1) rounds. One
// iteration budget serves all rounds, the full problem's (iterationEnd); when a round's box QP
// spends it, the documented fallback (boxQpFallback) is taken on the full problem from the last
// iterate (the round's x, the standing guesses elsewhere: inside the box), as without the guess.
#include <algorithm>
#include <cmath>

#include "friction_core.hpp"

namespace vereshchagin {
namespace detail {

int FrictionCore::refuteSlides() {
  const double acc_scale = std::max(1.0, nj_ ? qdd_.cwiseAbs().maxCoeff() : 0.0);  // as frictionOutputs'
  const double band = 1e-9 * acc_scale;
  int refuted = 0;
  for (unsigned int j = 0; j < nj_; ++j) {
    // The end velocity over dt along qd: it must stay strictly outside the Stick band (a joint that
    // ends the step at rest, or within round-off of it, is an unknown of the QP). Without branches
    // on the data (the signs are as good as random).
    const double row = (qdd_(j) + shift_(j)) * std::copysign(1.0, xg_(j));  // (xg_ != 0 on a guess)
    const int refute = (slide_[j] == 1) & !(row > band);
    slide_[j] = static_cast<char>(slide_[j] + refute);
    refuted += refute;
  }
  return refuted;
}

int FrictionCore::mergeRefuted(int k) {
  int added = 0;
  for (unsigned int j = 0; j < nj_; ++j) added += slide_[j] == 2 ? 1 : 0;
  // From the back: rest_ stays in joint order (frictionOutputs walks it alongside the joints).
  int a = k - 1, b = k + added - 1;
  for (int j = static_cast<int>(nj_) - 1; j >= 0 && b > a; --j) {
    if (slide_[static_cast<std::size_t>(j)] == 2) {
      slide_[static_cast<std::size_t>(j)] = 0;
      lo_(b) = -fbound_(j);  // (a moving joint has no limit side)
      hi_(b) = fbound_(j);
      rest_(b--) = j;
    } else if (a >= 0 && rest_(a) == j) {
      lo_(b) = lo_(a);
      hi_(b) = hi_(a);
      rest_(b--) = rest_(a--);
    }
  }
  return k + added;
}

int FrictionCore::stepFallback(int& k) {
  auto x_joint = p_.head(nj_);  // the last iterate per joint
  x_joint = xg_;
  for (int a = 0; a < k; ++a) x_joint(rest_(a)) = x_(a);
  for (unsigned int j = 0; j < nj_; ++j)
    if (slide_[j] == 1) slide_[j] = 2;
  k = mergeRefuted(k);  // every joint with friction or on a limit
  for (int a = 0; a < k; ++a) x_(a) = x_joint(rest_(a));
  const int rc = restingProblem(k);
  if (rc != ChainHdSolver::E_NOERROR) return rc;
  boxQpFallback(k);
  tau_cmd_known_ = false;
  applyResting(k);
  return ChainHdSolver::E_NOERROR;
}

int FrictionCore::optimiseStep(int& k) {
  qdd_ = hd_->res.qdd;
  for (unsigned int j = 0; j < nj_; ++j)
    if (slide_[j] == 1) row_scale_ = std::max(row_scale_, std::abs(qdd_(j) + shift_(j)));
  for (bool first = true;; first = false) {
    const int refuted = refuteSlides();
    if (!first && refuted == 0) return ChainHdSolver::E_NOERROR;
    if (refuted > 0) k = mergeRefuted(k);
    if (k == 0) {  // every guess stands and no joint rests: hd_'s solve is the answer
      tau_cmd_ = hd_->res.tau_cmd;
      nu_.head(hd_->res.m) = hd_->nu();
      return ChainHdSolver::E_NOERROR;
    }
    degraded_ = 0;  // (a tie-break bound hit in an earlier round is that round's)
    const int rc = optimiseResting(k);
    if (rc != ChainHdSolver::E_NOERROR) return rc;
    if (degraded_ == 1) {  // the budget is spent: the fallback on the full problem
      return stepFallback(k);
    }
  }
}

}  // namespace detail
}  // namespace vereshchagin
