// The Python Solver: one parser for the arguments of solve() and solve_batch() (SolveArgs, with
// friction in FrictionArg) into a vereshchagin::BatchInput, one BatchWorkspace per thread, and
// PySolver itself. solve_args.cpp: the parser (friction= too); solve_run.cpp:
// solve(), solve_batch() and the benchmark hooks; solver_core.cpp: setup and state;
// solver_bindings.cpp: the Python methods.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "vereshchagin/batch_args.hpp"

#include "common.hpp"
#include "model_class.hpp"

namespace vsbind {

// Positions in the argument array of SolveArgs::parse (solve()'s parameter order).
inline constexpr int kOutArg = 10, kADesiredArg = 11, kNumSolveArgs = 12;

using Rows = vereshchagin::StridedRows;

// The most threads solve_batch starts (threads= beyond it is refused): each costs an OS thread and
// a workspace (a solver's Data), and no machine gains from more.
inline constexpr long kMaxBatchThreads = 256;

// friction=: None/False, True (the model's values), a vereshchagin.Friction (parsed once and
// reused while its attributes are the same objects: its arrays cannot be written) or any object
// with the same attributes. Shapes: vereshchagin::frictionFromArrays; values: vereshchagin::solve.
class FrictionArg {
 public:
  void setModelValues(const std::vector<vereshchagin::JointInfo>& joints);
  // The parsed model (nullptr: none): the cache, the model's values or `scratch`.
  const vereshchagin::FrictionModel* parse(PyObject* obj, unsigned int nj, vereshchagin::FrictionModel& scratch);

 private:
  bool unchanged(PyObject* obj) const;
  vereshchagin::FrictionModel model_values_, cache_;
  py::object cache_key_, cache_attrs_[6];
};

// The arguments of one solve (1 row, no batch axis accepted) or of a batch (B rows, each argument
// shared or with a leading batch axis) as a BatchInput, shapes checked by BatchArgs with messages
// naming the argument (values: by vereshchagin::solve, for each row).
class SolveArgs : public vereshchagin::BatchArgs {
 public:
  // args: q, qd, alpha, beta, f_ext, tau_ff, friction, constraints, f_ext_pass_through,
  // tau_ff_pass_through, (out: not read), a_desired (nullptr or None: not given).
  void parse(class PySolver& s, PyObject* const* args, bool batch);

  bool any_friction = false;
  std::vector<py::object> keys;     // constraints= keys: input.blocks[blocks.size() - keys.size() + k]
  std::vector<py::ssize_t> starts;  // their first column in nu

 private:
  const double* keep(F64View& v);  // keeps v's converted copy (if any) alive with the rows
  Rows vector(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok = false);
  void addBlock(int segment, PyObject* alpha, PyObject* set_point, const std::string& label, bool classical = false);
  void parseFExt(PyObject* obj);
  void parseConstraints(PyObject* obj);
  void parseFriction(FrictionArg& parser, PyObject* obj);

  unsigned int nj_ = 0, ns_ = 0;
  const Addressable* addressing_ = nullptr;
  std::vector<py::object> keep_;                              // converted copies the rows point into
  vereshchagin::FrictionModel friction_scratch_;              // a friction= that is not cached
  std::vector<vereshchagin::FrictionModel> friction_models_;  // friction= per row
};

class PySolver {
 public:
  // model: a Chain or a Tree (copied). inertia_check: None (the model's), 'physical' or
  // 'joint_space'. max_constraints: None (SolverOptions' default) or an int >= 1.
  PySolver(const py::object& model, const py::object& gravity, const py::object& rcond, const py::object& damping,
           const py::object& inertia_check, const py::object& max_constraints);

  // solve(): parses, solves on workspace 0 and returns a SolveResult (new, or `out`).
  py::object solve(PyObject* const* args, PyObject* out);
  // Seconds per C++ solve of the parsed row, reading every output solve() returns.
  double timeCpp(PyObject* const* args, long reps);
  // Benchmarks only (BENCHMARKS.md, "Call mechanism"): solve() returning a dict of new numpy
  // arrays, as a result made of plain arrays would (no friction).
  py::dict solveDict(PyObject* const* args);
  // solve_batch(): args as solve()'s (`out` not read), threads: None or an int >= 0 (0: one per core).
  py::dict solveBatch(PyObject* const* args, const py::object& threads);
  // joints: joint indices in range (solver.py resolves names and negative indices).
  py::tuple responseColumns(const std::vector<int>& joints, bool hold_sticking);

  void setGravity(const py::object& gravity);
  py::array gravity() const;
  py::tuple getState() const;
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

  unsigned int nj = 0, ns = 0;
  const Addressable* addressing = nullptr;
  FrictionArg friction;

 private:
  vereshchagin::BatchWorkspace& workspace(std::size_t k);
  // Parses `args` into args_ and solves them on workspace 0 (the caller holds the Lock).
  void solveArgs(PyObject* const* args, bool frictionless);

  std::unique_ptr<PyChain> chain_;  // the model: one of these two
  std::unique_ptr<PyTree> tree_;
  vereshchagin::Model cpp_model_;  // shared by the workspaces
  KDL::Vector gravity_;
  vereshchagin::SolverOptions options_;
  py::object damping_arg_;
  std::vector<std::unique_ptr<vereshchagin::BatchWorkspace>> workspaces_;
  SolveArgs args_;  // solve()'s, reused under the lock
  std::mutex mutex_;
  std::atomic<std::thread::id> holder_{};  // the thread inside a call, or none
  // Workspace 0 holds the state of the last successful solve() or of the last row of the last
  // successful solve_batch(): response_columns() linearises around it.
  bool last_state_ = false;
};

// An int in lo .. hi (not a bool); messages "<name> must be an int<bound> <hint>, got [type] repr"
// and "<name> must be in lo .. hi <hint>, got str".
long intOption(const py::object& obj, const char* name, long lo, long hi, const char* bound, const char* hint,
               bool with_type);

// "physical" or "joint_space" (raises otherwise, naming `where`).
vereshchagin::InertiaCheck inertiaCheckArg(const std::string& value, const std::string& where);

}  // namespace vsbind
