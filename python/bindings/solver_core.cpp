// The Python Solver's setup and state: construction (model, options, workspace 0), the lock with
// re-entry detection, gravity, response_columns() around workspace 0's last solve.
#include "py_solver.hpp"

namespace vsbind {

vereshchagin::InertiaCheck inertiaCheckArg(const std::string& value, const std::string& where) {
  vereshchagin::InertiaCheck check = vereshchagin::InertiaCheck::Physical;
  if (const vereshchagin::Status s = vereshchagin::parseInertiaCheck(value, check); !s)
    raise(where + s.message() + ", got '" + value + "'");
  return check;
}

PySolver::PySolver(const py::object& model, const py::object& gravity, const py::object& rcond,
                   const py::object& damping, const py::object& inertia_check, const py::object& max_constraints) {
  if (py::isinstance<PyTree>(model))
    tree_ = std::make_unique<PyTree>(model.cast<const PyTree&>());
  else  // a Chain (solver.py refuses other types)
    chain_ = std::make_unique<PyChain>(model.cast<const PyChain&>());
  addressing = tree_ ? static_cast<const CompanionModel*>(tree_.get()) : chain_.get();
  options_.rcond = scalarArg(rcond, "rcond");
  // solver.py passes the check the model was built with for None.
  options_.inertia_check = inertiaCheckArg(py::str(inertia_check).cast<std::string>(), "");
  if (!damping.is_none()) {
    options_.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
    options_.damping = scalarArg(damping, "damping");
  }
  if (!max_constraints.is_none()) options_.max_constraints = max_constraints.cast<int>();  // checked by solver.py
  gravity_ = vec3(gravity, "gravity");
  vereshchagin::ModelOptions model_options{options_.inertia_check};
  if (tree_) model_options.base = tree_->robot.base, model_options.base_inertia = tree_->robot.base_inertia;
  cpp_model_ = tree_ ? vereshchagin::Model(tree_->robot.tree, tree_->robot.root_link, model_options)
                     : vereshchagin::Model(chain_->robot.chain, model_options);
  const char* invalid = tree_ ? "invalid tree: " : "invalid chain: ";
  if (const vereshchagin::Status s = cpp_model_.status(); !s) raise(invalid + std::string(s.message()));
  if (const vereshchagin::Status s = workspace(0).data.status(); !s) raise(invalid + std::string(s.message()));
  nj = cpp_model_.nv();  // the size of qd, tau_ff and the results (= n_joints on a fixed base)
  nq = cpp_model_.nq();
  ns = cpp_model_.nrOfSegments();
  model_friction = vereshchagin::frictionOfJoints(addressing->jointInfos());
}

PySolver::Lock::Lock(PySolver& s) : s_(s) {
  if (s.holder_.load() == std::this_thread::get_id())
    raise(
        "a Solver call re-entered the same Solver while it converts its arguments (an argument's __array__, "
        "property or __index__ calls this solver): convert the arguments first, or use another Solver");
  if (!s.mutex_.try_lock()) {
    py::gil_scoped_release release;  // another thread solves: wait without blocking it
    s.mutex_.lock();
  }
  s.holder_.store(std::this_thread::get_id());
}

vereshchagin::BatchWorkspace& PySolver::workspace(std::size_t k) {
  while (workspaces_.size() <= k)
    workspaces_.push_back(std::make_unique<vereshchagin::BatchWorkspace>(cpp_model_, options_, gravity_));
  return *workspaces_[k];
}

void PySolver::setGravity(const py::object& gravity) {
  const KDL::Vector g = vec3(gravity, "gravity");
  Lock lk(*this);
  gravity_ = g;
  for (auto& w : workspaces_) w->input.gravity = g;
}

std::pair<Eigen::MatrixXd, Eigen::MatrixXd> PySolver::responseColumns(const Eigen::VectorXi& joints,
                                                                      bool hold_sticking) {
  Lock lk(*this);
  if (!last_state_)
    raise(
        "response_columns() linearises around the last successful solve() (or the last row of solve_batch()): "
        "call solve() at the state first");
  vereshchagin::Data& data = workspaces_[0]->data;
  std::pair<Eigen::MatrixXd, Eigen::MatrixXd> cols{Eigen::MatrixXd(nj, joints.size()),
                                                   Eigen::MatrixXd(nj, joints.size())};
  vereshchagin::Status rc;
  {
    py::gil_scoped_release release;
    rc = hold_sticking ? data.responseColumnsHoldingSticking(joints, cols.first, cols.second)
                       : data.responseColumns(joints, cols.first, cols.second);
  }
  if (!rc) raise(rc.message());
  return cols;
}

}  // namespace vsbind
