// The Python Solver: argument parsing (argument-naming messages), the engines that solve, and the
// result type. Solver.solve is a METH_FASTCALL entry point (solver_bindings.cpp); solve_batch runs
// rows on one engine per thread with the GIL released (solve_batch.cpp).
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "chain_bindings.hpp"
#include "common.hpp"
#include "engine.hpp"
#include "numpy_fast.hpp"
#include "result_type.hpp"
#include "tree_bindings.hpp"

namespace vsbind {

// The arguments of one solve, checked: views into the caller's arrays plus the blocks, wrenches
// and friction model that RowInputs points at.
struct ParsedSolve {
  F64View q, qd, alpha, beta, f_ext, tau, f_ext_pass_through, tau_ff_pass_through;
  std::vector<F64View> block_views;  // alpha_i, beta_i of constraints= entries (kept alive)
  std::vector<ConstraintBlock> blocks;
  std::vector<py::object> block_keys;  // constraints= keys, in order (for segment_nu)
  std::vector<double> f_ext_dense;     // f_ext given as a dict: (n_segments, 6)
  std::vector<LinkWrench> link_wrenches;
  py::object friction_owner;  // keeps a parsed friction's arrays alive
  vereshchagin::FrictionModel friction_model;
  const vereshchagin::FrictionModel* friction = nullptr;
  RowInputs row;
  void clear();
};

struct BatchRunner;  // solve_batch.cpp

// The keys of a constraints= dict, for solve and solve_batch alike: each resolved by the model's
// addressing rule, one entry per frame, at most 6 columns per segment (alpha counts on the last).
class ConstraintKeys {
 public:
  ConstraintKeys(const Addressable& model, int n_segments, int alpha_columns);
  // constraints[key]'s target; raises for a frame given twice.
  FrameTarget resolve(PyObject* key, const std::string& label);
  // Counts `cols` more columns on `segment`; raises past 6.
  void count(int segment, int cols, const std::string& label);
  // The pair (alpha, beta) of one entry; raises unless a tuple or list of two.
  static std::pair<PyObject*, PyObject*> pair(PyObject* value, const std::string& label, const std::string& shapes);
  const std::vector<py::object>& keys() const { return keys_; }

 private:
  const Addressable& model_;
  std::vector<int> per_segment_;
  std::vector<FrameTarget> targets_;
  std::vector<py::object> keys_;
};

// The most threads solve_batch starts (threads= beyond it is refused): each costs an OS thread and
// an engine (a solver's workspace), and no machine gains from more.
inline constexpr long kMaxBatchThreads = 256;

// Raised for alpha/beta (the end segment's constraint) on a tree solver.
inline constexpr const char* kTreeAlpha =
    "alpha and beta constrain a chain's last segment; a Tree has no last segment: pass constraints={segment or "
    "link name: (alpha, beta)}";

class PySolver {
 public:
  // model: a Chain or a Tree (copied).
  // inertia_check: None (the model's, see PyChain::inertia_check), 'physical' or 'joint_space'.
  // max_constraints: None (SolverOptions' default) or an int >= 1.
  PySolver(const py::object& model, const py::object& gravity, const py::object& rcond, const py::object& damping,
           const py::object& inertia_check, const py::object& max_constraints);

  // Parses solve()'s arguments (objects may be null for "not given") into `p`.
  // args: q, qd, alpha, beta, f_ext, tau_ff, friction, constraints, f_ext_pass_through,
  // tau_ff_pass_through (the order of solve()'s parameters; `out` is not parsed here).
  void parse(PyObject* const* args, ParsedSolve& p);
  // Solves the parsed row on engine 0 with the GIL released; raises SolverError on failure.
  void runParsed(const ParsedSolve& p);
  // The result of the last runParsed(): new arrays, or written into `out` (a SolveResult).
  py::object result(const ParsedSolve& p, PyObject* out);

  py::dict solveBatch(const py::object& q, const py::object& qd, const py::object& alpha, const py::object& beta,
                      const py::object& f_ext, const py::object& tau_ff, const py::object& friction,
                      const py::object& constraints, const py::object& f_ext_pass_through,
                      const py::object& tau_ff_pass_through, const py::object& threads);
  py::tuple responseColumns(const py::object& joints, bool hold_sticking);
  double timeCpp(const ParsedSolve& p, long reps);

  void setGravity(const py::object& gravity);
  py::array gravity() const;
  py::tuple getState() const;

  // Holds the solver for one call. Waits with the GIL released while another thread holds it;
  // raises SolverError if this thread already holds it (a call re-entered from inside its own
  // argument conversion, e.g. a q whose __array__ calls the same solver).
  class Lock {
   public:
    explicit Lock(PySolver& s);
    ~Lock();
    Lock(const Lock&) = delete;
    Lock& operator=(const Lock&) = delete;

   private:
    PySolver& s_;
  };
  Lock lock() { return Lock(*this); }
  // Starts a call that replaces the solver's state: response_columns() raises until it succeeds.
  void beginStateCall() { last_state_ = false; }

  // The solver's model: a copy of its Chain or Tree.
  py::object model() const;
  bool isTree() const { return tree_ != nullptr; }
  std::string inertiaCheck() const { return vereshchagin::inertiaCheckName(options_.inertia_check); }
  unsigned int nj = 0, ns = 0;
  ParsedSolve parsed;  // scratch of solve(), reused under the lock

 private:
  friend struct BatchRunner;
  void parseFExt(PyObject* f_ext, ParsedSolve& p) const;
  void parseConstraints(PyObject* constraints, ParsedSolve& p) const;
  bool parseFriction(PyObject* friction, ParsedSolve& p);
  // Raises unless a solve's constraint columns fit the engines' workspace.
  void checkColumnCount(py::ssize_t columns) const;
  bool frictionUnchanged(PyObject* friction) const;
  void rememberFriction(PyObject* friction);
  Engine& engine(std::size_t k);
  void keepLastRow(BatchRunner& br, long threads);

  std::unique_ptr<PyChain> chain_;  // the model: one of these two
  std::unique_ptr<PyTree> tree_;
  const Addressable* model_ = nullptr;
  vereshchagin::Model cpp_model_;  // shared by the engines
  KDL::Vector gravity_;
  vereshchagin::SolverOptions options_;
  py::object damping_arg_;
  std::vector<std::unique_ptr<Engine>> engines_;
  py::ssize_t max_columns_ = 0;                 // Data::maxConstraints() of every engine
  vereshchagin::FrictionModel chain_friction_;  // friction=True
  // The last vereshchagin.Friction parsed and its six attribute objects: reused only while every
  // attribute is the same object (the arrays cannot be written: friction.py).
  py::object friction_cache_key_;
  py::object friction_cache_attrs_[6];
  vereshchagin::FrictionModel friction_cache_;
  std::mutex mutex_;
  std::atomic<std::thread::id> holder_{};  // the thread inside a call, or none
  // Engine 0 holds the state of the last successful solve() or of the last row of the last
  // successful solve_batch(): response_columns() linearises around it.
  bool last_state_ = false;
};

// "physical" or "joint_space" (raises otherwise, naming `where`).
vereshchagin::InertiaCheck inertiaCheckArg(const std::string& value, const std::string& where);

// Checked pass-through weights: (m,) in [0, 1].
void checkWeights(const double* w, py::ssize_t m, const std::string& name);

// Checked alpha: (6, m) or (6,) (one column), m <= 6, finite.
F64View alphaView(PyObject* obj, const std::string& name);

}  // namespace vsbind
