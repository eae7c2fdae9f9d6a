// What an HdSolver face (hd_solver.hpp) holds: a Model and a Data, plus the KDL-style state the
// face keeps between its calls (root acceleration, pass-through weights), installed into the
// Data's core at each of its solves.
#pragma once

#include <atomic>
#include <optional>
#include <utility>

#include "vereshchagin/data.hpp"
#include "vereshchagin/model.hpp"

#include "data_impl.hpp"
#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

struct FacadeState {
  FacadeState(Model m, const Vector6& root, const SolverOptions& options)
      : model(std::move(m)), data(model, options), root_acc(root) {
    weights.resize(core().mcap);
  }
  HdCore& core() { return data.impl().core; }
  const HdCore& core() const { return data.impl().core; }
  // The face's root acceleration and weights for the coming solve.
  void install() {
    HdCore& c = core();
    c.root_acc = root_acc;
    c.ws.pt.weights = &weights;
    c.loads = nullptr;
  }
  // A new model (or the same one anew): a new Data with the current options, weights cleared.
  // The old Data is kept in `retired` (its entry flag may be held by the caller's guard) until
  // the caller has left it: then dropRetired().
  void reset(Model m, const SolverOptions& options) {
    model = std::move(m);
    retired.emplace(std::move(data));
    data = Data(model, options);
    weights.m = -1;
    weights.f_any = weights.t_any = false;
    weights.resize(core().mcap);
  }

  void dropRetired() { retired.reset(); }

  Model model;
  Data data;
  std::optional<Data> retired;
  Vector6 root_acc;
  PassThroughWeights weights;
  std::atomic<bool> stale_model{false};  // a rebuild was refused (updateInternalDataStructures())
};

}  // namespace detail
}  // namespace vereshchagin
