// The symplectic step of the Simulator (simulator.hpp, Integrator::Symplectic): symplectic Euler
// in momentum form, the velocity-level conditions of friction, limits and contacts solved exactly
// in every iteration. Internal: the Simulator owns the workspace and the carried momentum.
#pragma once

#include <Eigen/Core>

#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {
namespace detail {

// Sized once for a model (allocates); symplecticStep allocates nothing once `scratch` has held an
// input with as many constraint blocks, wrenches and contacts (std::vector keeps its capacity).
struct SymplecticWorkspace {
  explicit SymplecticWorkspace(const Model& model);
  DynamicsData dynamics;
  SolveInput scratch;        // the input of each iteration's solve
  Eigen::VectorXd fixed;     // c(q, u) - H u / dt + p / dt: the step's constant generalized force
  Eigen::VectorXd gradient;  // dT/dq at the iterate
  Eigen::VectorXd iterate;   // u of the iteration
  Eigen::VectorXd zero;      // n zeros
  int iterations = 0;        // solves of the last step
};

// With state (q, u) = (input.q, input.q_dot), carried momentum p (H(q_prev) u, or H(q) u at the
// start) and dt = input.time_step, finds u+ with
//     H(q) u+ = p + dt (tau - g(q) + dT/dq(q, u+)) + the impulses of friction, limits, contacts,
// the conditions on the impulses those of a velocity-level solve (SolveInput::time_step) taken
// at the start velocity u, by fixed-point iteration on dT/dq(q, u+): each iteration is one exact
// solve. Then q+ = q + dt u+ and p+ = H(q) u+. Stops when max |u+ - previous| <= tol max(1, |u+|)
// or after max_iterations solves: then Error::Degraded, the last iterate taken (the fallback).
Status symplecticStep(const Model& model, Data& data, SymplecticWorkspace& ws, const SolveInput& input,
                      const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> q_next,
                      Eigen::Ref<Eigen::VectorXd> u_next, Eigen::Ref<Eigen::VectorXd> p_next, int max_iterations = 100,
                      double tol = 1e-12);

}  // namespace detail
}  // namespace vereshchagin
