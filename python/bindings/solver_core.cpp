// The Python Solver's setup and state: construction (model, options, engine 0), the lock with
// re-entry detection, gravity, response_columns() around engine 0's last solve, pickling state.
#include "py_solver.hpp"

namespace vsbind {

long intOption(const py::object& obj, const char* name, long lo, long hi, const char* bound, const char* hint,
               bool with_type) {
  if (PyBool_Check(obj.ptr()) || !PyIndex_Check(obj.ptr()))
    raise(std::string(name) + " must be an int" + bound + " " + hint + ", got " +
          (with_type ? std::string(Py_TYPE(obj.ptr())->tp_name) + " " : "") + py::repr(obj).cast<std::string>());
  const std::optional<long long> v = intWithin(obj.ptr(), lo, hi);
  if (!v)
    raise(std::string(name) + " must be in " + std::to_string(lo) + " .. " + std::to_string(hi) + " " + hint +
          ", got " + py::str(obj).cast<std::string>());
  return static_cast<long>(*v);
}

vereshchagin::InertiaCheck inertiaCheckArg(const std::string& value, const std::string& where) {
  if (value == "physical") return vereshchagin::InertiaCheck::Physical;
  if (value == "joint_space") return vereshchagin::InertiaCheck::JointSpace;
  raise(where +
        "inertia_check must be 'physical' (every body a rigid body) or 'joint_space' (identified models: "
        "any symmetric inertia, H(q) positive definite at each solve), got '" +
        value + "'");
}

PySolver::PySolver(const py::object& model, const py::object& gravity, const py::object& rcond,
                   const py::object& damping, const py::object& inertia_check, const py::object& max_constraints)
    : damping_arg_(damping) {
  if (py::isinstance<PyChain>(model)) {
    chain_ = std::make_unique<PyChain>(model.cast<const PyChain&>());
    addressing = chain_.get();
  } else if (py::isinstance<PyTree>(model)) {
    tree_ = std::make_unique<PyTree>(model.cast<const PyTree&>());
    addressing = tree_.get();
  } else {
    throw py::type_error("Solver(model): model must be a vereshchagin.Chain or vereshchagin.Tree, got " +
                         std::string(Py_TYPE(model.ptr())->tp_name));
  }
  options_.rcond = scalarArg(rcond, "rcond");
  if (inertia_check.is_none())  // the check the model was built with
    options_.inertia_check = tree_ ? tree_->inertia_check : chain_->inertia_check;
  else
    options_.inertia_check = inertiaCheckArg(py::str(inertia_check).cast<std::string>(), "");
  if (!damping.is_none()) {
    options_.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
    options_.damping = scalarArg(damping, "damping");
  }
  if (!max_constraints.is_none())
    options_.max_constraints = static_cast<int>(
        intOption(max_constraints, "max_constraints", 1, 1 << 24, " >= 1", "(None: the default)", false));
  gravity_ = vec3(gravity, "gravity");
  const vereshchagin::ModelOptions model_options{options_.inertia_check};
  cpp_model_ = tree_ ? vereshchagin::Model(tree_->robot.tree, tree_->robot.root_link, model_options)
                     : vereshchagin::Model(chain_->robot.chain, model_options);
  const char* invalid = tree_ ? "invalid tree: " : "invalid chain: ";
  if (const vereshchagin::Status s = cpp_model_.status(); !s) raise(invalid + std::string(s.message()));
  auto probe = std::make_unique<Engine>(cpp_model_, gravity_, options_);
  if (const vereshchagin::Status s = probe->data.status(); !s) raise(invalid + std::string(s.message()));
  max_columns = probe->data.maxConstraints();
  engines_.push_back(std::move(probe));
  nj = cpp_model_.nrOfJoints();
  ns = cpp_model_.nrOfSegments();
  friction.setModelValues(addressing->jointInfos());
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

Engine& PySolver::engine(std::size_t k) {
  while (engines_.size() <= k) engines_.push_back(std::make_unique<Engine>(cpp_model_, gravity_, options_));
  return *engines_[k];
}

void PySolver::setGravity(const py::object& gravity) {
  const KDL::Vector g = vec3(gravity, "gravity");
  Lock lk(*this);
  gravity_ = g;
  for (auto& e : engines_) e->input.gravity = g;
}

py::array PySolver::gravity() const {
  py::array g = newDoubles({3});
  for (int k = 0; k < 3; ++k) doubles(g)[k] = gravity_(k);
  return g;
}

namespace {

Eigen::VectorXi jointList(const Addressable& chain, const py::object& joints) {
  const char* what = "joints must be a sequence of joint names or int indices";
  if (joints.is_none() || py::isinstance<py::str>(joints)) raise(what);
  py::sequence seq;
  if (py::isinstance<py::array>(joints)) {
    py::array a = joints.cast<py::array>();
    const char kind = a.dtype().kind();
    if (a.ndim() != 1 || (a.size() > 0 && kind != 'i' && kind != 'u' && kind != 'U'))
      raise(std::string(what) + ", got an array of shape " + std::string(py::str(a.attr("shape"))) + " and dtype " +
            std::string(py::str(a.dtype())));
    seq = a.attr("tolist")();
  } else if (py::isinstance<py::sequence>(joints)) {
    seq = joints.cast<py::sequence>();
  } else {
    raise(what);
  }
  Eigen::VectorXi j(static_cast<Eigen::Index>(seq.size()));
  for (Eigen::Index c = 0; c < j.size(); ++c)
    j(c) = chain.resolveJoint(seq[c].ptr(), "joints[" + std::to_string(c) + "]");
  return j;
}

}  // namespace

py::tuple PySolver::responseColumns(const py::object& joints, bool hold_sticking) {
  const Eigen::VectorXi requested = jointList(*addressing, joints);
  Lock lk(*this);
  if (!last_state_)
    raise(
        "response_columns() linearises around the last successful solve() (or the last row of solve_batch()): "
        "call solve() at the state first");
  Engine& e = *engines_[0];
  const Eigen::Index k = requested.size();
  Eigen::MatrixXd dq(nj, k), dt(nj, k);
  vereshchagin::Status rc;
  {
    py::gil_scoped_release release;
    rc = hold_sticking ? e.data.responseColumnsHoldingSticking(requested, dq, dt)
                       : e.data.responseColumns(requested, dq, dt);
  }
  if (!rc) raise(rc.message());
  auto toNumpy = [&](const Eigen::MatrixXd& M) {
    py::array a = newDoubles({static_cast<py::ssize_t>(nj), static_cast<py::ssize_t>(k)});
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(doubles(a), nj, k) = M;
    return a;
  };
  return py::make_tuple(toNumpy(dq), toNumpy(dt));
}

py::tuple PySolver::getState() const {
  return py::make_tuple(model(), gravity(), options_.rcond, damping_arg_,
                        vereshchagin::inertiaCheckName(options_.inertia_check),
                        options_.max_constraints > 0 ? py::object(py::int_(options_.max_constraints)) : py::none());
}

}  // namespace vsbind
