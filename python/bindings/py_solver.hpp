// The Python Solver: one parser of solve()'s and solve_batch()'s arguments (SolveArgs) into a
// vereshchagin::BatchInput, one BatchWorkspace per thread, and PySolver. solve_args.cpp: the parser;
// solve_run.cpp: solve(), solve_batch() and the benchmark hooks; solver_core.cpp: setup and state;
// solver_bindings.cpp: the Python methods.
#pragma once

#include <atomic>
#include <mutex>
#include <thread>

#include "vereshchagin/batch_args.hpp"       // also <string>, <vector>
#include "vereshchagin/whole_body_call.hpp"  // also <memory>

#include "common.hpp"
#include "model_class.hpp"

namespace vsbind {

// Positions in the argument array of SolveArgs::parse (solve()'s parameter order).
inline constexpr int kOutArg = 10, kADesiredArg = 11, kContactsArg = 12, kTimeStepArg = 13, kVelocityTolArg = 14,
                     kMaxPivotsArg = 15, kNumSolveArgs = 16;

// The arguments of one solve (1 row) or of a batch (B rows, each argument shared or with a leading batch axis) as a
// BatchInput, shapes checked by BatchArgs with messages naming the argument (values: by solve(), per row). friction=:
// read as the tuple of vereshchagin/friction.py's _fields_of; a Friction caches it (its arrays are read-only) until an
// attribute is replaced, so solve()'s SolveArgs reuses its parse while the tuple is the same.
class SolveArgs : public vereshchagin::BatchArgs {
 public:
  // args: solve()'s parameters in kSolveParams order (solver_bindings.cpp; out: not read); nullptr or None: not given.
  void parse(class PySolver& s, PyObject* const* args, bool batch);
  // contacts: a list or tuple of vereshchagin.Contact (`name` in messages), every row's, into input.contacts.
  void parseContacts(PyObject* obj, const char* name);

  bool any_friction = false;
  py::list layout;  // segment_nu's: a (key, first column in nu, columns) tuple per constraints= key

 private:
  F64View view(PyObject* obj, const char* name);  // asF64, its converted copy (if any) kept with the rows
  vereshchagin::StridedRows vector(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok = false);
  void addBlock(int segment, PyObject* alpha, PyObject* set_point, const std::string& label, bool classical = false);
  void parseFExt(PyObject* obj);
  void parseConstraints(PyObject* obj);
  void parseFriction(PyObject* obj);
  // The parsed friction (nullptr: none): the model's values, the cache or `scratch`.
  const vereshchagin::FrictionModel* friction(PyObject* obj, vereshchagin::FrictionModel& scratch);

  const PySolver* solver_ = nullptr;
  std::vector<py::object> keep_;                              // converted copies the rows point into
  vereshchagin::FrictionModel friction_scratch_, cache_;      // a friction= not cached; a Friction's parse
  py::object cache_key_;                                      // the _fields tuple cache_ was parsed from
  std::vector<vereshchagin::FrictionModel> friction_models_;  // friction= per row
};

class PySolver {
 public:
  // model: a Chain or a Tree (copied). inertia_check: 'physical' or 'joint_space' (solver.py passes
  // the model's for None). max_constraints: None (SolverOptions' default) or an int (solver.py checks).
  PySolver(const py::object& model, const py::object& gravity, const py::object& rcond, const py::object& damping,
           const py::object& inertia_check, const py::object& max_constraints);

  // solve(): parses, solves on workspace 0 and returns a SolveResult (new, or `out`); step 1:
  // vereshchagin::step() over args' time_step, (q_next, qd_next, result); step 2: stepSymplectic()
  // from the momentum `out`, (q_next, qd_next, momentum_next, result).
  py::object solve(PyObject* const* args, PyObject* out, int step = 0);
  // Seconds per C++ solve of the parsed row, reading every output solve() returns.
  double timeCpp(PyObject* const* args, long reps);
  // solve_batch(): args as solve()'s (`out` not read); threads: None (1) or an int, 0: one per core.
  py::dict solveBatch(PyObject* const* args, PyObject* threads);
  // whole_body.least_effort (q, qd, f_ext, tau_ff, supports: as solve()'s; task: (label, segment -1 or -2, None, or 0,
  // key as solve()'s constraints keys, point, alpha, beta) tuples; actuated: None or (n_joints,)): tau, forces, ...
  using WholeBodyOut = std::tuple<Eigen::VectorXd, Eigen::MatrixXd, Eigen::VectorXd, double, double>;
  WholeBodyOut wholeBody(O q, O qd, O f_ext, O tau_ff, O actuated, O supports, O task);
  // joints: joint indices in range (solver.py resolves names and negative indices).
  std::pair<Eigen::MatrixXd, Eigen::MatrixXd> responseColumns(const Eigen::VectorXi& joints, bool hold_sticking);

  void setGravity(const py::object& gravity);
  py::array gravity() const { return py::array_t<double>(3, gravity_.data); }
  py::object model() const { return tree_ ? py::cast(*tree_) : py::cast(*chain_); }
  bool isTree() const { return tree_ != nullptr; }
  const vereshchagin::Model& cppModel() const { return cpp_model_; }
  std::string inertiaCheck() const { return vereshchagin::inertiaCheckName(options_.inertia_check); }

  // Holds the solver for one call. Waits with the GIL released while another thread holds it;
  // raises SolverError if this thread already holds it (a call re-entered from inside its own
  // argument conversion, e.g. a q whose __array__ calls the same solver).
  class Lock {
   public:
    explicit Lock(PySolver& s);
    ~Lock() {
      s_.holder_.store(std::thread::id());
      s_.mutex_.unlock();
    }
    Lock(const Lock&) = delete;

   private:
    PySolver& s_;
  };

  unsigned int nj = 0, ns = 0, nq = 0;         // nj: the model's nv, nq: its nq (base_kind.hpp)
  const CompanionModel* addressing = nullptr;  // what the argument parser reads of the model
  vereshchagin::FrictionModel model_friction;  // friction=True's

 private:
  vereshchagin::BatchWorkspace& workspace(std::size_t k);
  // Parses `args` into args_ and solves them on workspace 0 (the caller holds the Lock); given
  // next = {q_next, qd_next, p_next} (nj doubles each), steps instead (step(), stepSymplectic() from p).
  void solveArgs(PyObject* const* args, double* const* next = nullptr, const double* p = nullptr);

  std::unique_ptr<PyChain> chain_;  // the model: one of these two
  std::unique_ptr<PyTree> tree_;
  vereshchagin::Model cpp_model_;  // shared by the workspaces
  KDL::Vector gravity_;
  vereshchagin::SolverOptions options_;
  std::vector<std::unique_ptr<vereshchagin::BatchWorkspace>> workspaces_;
  SolveArgs args_;                          // solve()'s (and least_effort's), reused under the lock
  vereshchagin::WholeBodyCall whole_body_;  // least_effort's (its solver built at its first call)
  std::mutex mutex_;
  std::atomic<std::thread::id> holder_{};  // the thread inside a call, or none
  // Workspace 0 holds the state of the last successful solve() or of the last row of the last
  // successful solve_batch(): response_columns() linearises around it.
  bool last_state_ = false;
};

// vereshchagin.SolveResult (result_type.cpp: every output of a solve in storage allocated with the object, fields are
// views). newResult: a new one for `layout`, or `out` checked to have that layout (a new reference); resultOutput:
// where solve() writes into it (the friction outputs nullptr without friction); setSegmentLayout: segment_nu's (key,
// start, count) tuples.
py::object newResult(const vereshchagin::PackedRow& layout, PyObject* out);
vereshchagin::BatchOutput resultOutput(PyObject* result);
void setSegmentLayout(PyObject* result, py::tuple layout);

// "physical" or "joint_space" (vereshchagin::parseInertiaCheck; raises otherwise, naming `where`).
vereshchagin::InertiaCheck inertiaCheckArg(const std::string& value, const std::string& where);

}  // namespace vsbind
