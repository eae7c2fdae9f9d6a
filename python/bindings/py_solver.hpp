// The Python Solver: one parser for the arguments of solve() and solve_batch() (SolveArgs, with
// friction in FrictionArg), one engine (a Data and a SolveInput) per thread, and PySolver itself.
// solve_args.cpp: the parser; solve_friction.cpp: friction=; solve_row.cpp: a row on an engine and
// solve(); solve_batch.cpp: solve_batch(); solver_core.cpp: setup and state; solver_bindings.cpp:
// the Python methods.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "vereshchagin/data.hpp"
#include "vereshchagin/friction_solver.hpp"

#include "common.hpp"
#include "model_class.hpp"

namespace vsbind {

// Positions in the argument array of SolveArgs::parse (solve()'s parameter order).
inline constexpr int kOutArg = 10, kADesiredArg = 11, kNumSolveArgs = 12;

// The most threads solve_batch starts (threads= beyond it is refused): each costs an OS thread and
// an engine (a solver's workspace), and no machine gains from more.
inline constexpr long kMaxBatchThreads = 256;

// Raised for alpha/beta (the end segment's constraint) on a tree solver.
inline constexpr const char* kTreeAlpha =
    "alpha and beta constrain a chain's last segment; a Tree has no last segment: pass constraints={segment or "
    "link name: (alpha, beta)}";

// One argument's rows in numpy memory (row-major): row b starts at data + b * stride (0: every
// row reads the same values).
struct Rows {
  const double* data = nullptr;
  py::ssize_t stride = 0;
  const double* row(py::ssize_t b) const { return data + b * stride; }
};

// A constraint block: alpha (6, cols) row-major and beta (cols,) per row, on `segment` (-1: the
// last segment of a chain without segments, nothing moves), moments about `point` (the frame's
// origin in the segment's tip frame; zero unless a merged link was named).
struct BlockArg {
  int segment = 0, cols = 0;
  vereshchagin::Vector3 point = vereshchagin::Vector3::Zero();
  KDL::Vector frame;  // the named frame's origin in the tip frame (one constraints= entry per frame)
  Rows alpha, beta;
  Rows classical;  // a_desired (6,) instead of beta: ConstraintBlock::classical (data nullptr: beta)
};

// An f_ext dict entry: (6,) [force, moment] per row, base axes, moment about the frame's origin.
struct WrenchArg {
  int segment = 0;
  bool merged = false;  // on a merged link: a SolveInput frame wrench; else added to f_ext
  vereshchagin::Vector3 point = vereshchagin::Vector3::Zero();
  Rows wrench;
};

// friction=: None/False, True (the model's values), a vereshchagin.Friction (parsed once and
// reused while its attributes are the same objects: its arrays cannot be written) or any object
// with the same attributes. Messages name friction.static, friction.kinetic, ...
class FrictionArg {
 public:
  void setModelValues(const std::vector<vereshchagin::JointInfo>& joints);
  // The parsed model (nullptr: none): the cache, the model's values or `scratch`.
  const vereshchagin::FrictionModel* parse(PyObject* obj, unsigned int nj, vereshchagin::FrictionModel& scratch);

 private:
  bool unchanged(PyObject* obj) const;
  void remember(PyObject* obj);
  vereshchagin::FrictionModel model_values_, cache_;
  py::object cache_key_, cache_attrs_[6];
};

// The arguments of one solve (1 row, no batch axis accepted) or of a batch (B rows, each argument
// shared or with a leading batch axis), checked with messages naming the argument; fillRow writes
// one row into a SolveInput without allocating once warm.
class SolveArgs {
 public:
  // args: q, qd, alpha, beta, f_ext, tau_ff, friction, constraints, f_ext_pass_through,
  // tau_ff_pass_through, (out: not read), a_desired (nullptr or None: not given).
  void parse(class PySolver& s, PyObject* const* args, bool batch);
  void fillRow(py::ssize_t b, vereshchagin::SolveInput& in) const;
  const vereshchagin::FrictionModel* friction(py::ssize_t b) const {
    return row_friction_.empty() ? friction_ : row_friction_[static_cast<std::size_t>(b)];
  }

  py::ssize_t rows = 1;  // B
  int columns = 0;       // constraint columns of every row (the size of nu)
  bool any_friction = false;
  std::vector<BlockArg> blocks;     // end-segment alpha first (if any), then constraints= entries
  std::vector<py::object> keys;     // constraints= keys: blocks[blocks.size() - keys.size() + k]
  std::vector<py::ssize_t> starts;  // their first column in nu

 private:
  enum Hint { kNoHint, kAlphaHint, kFExtHint };  // what a shape message adds
  Rows arg(const char* name, F64View v, int ndim, const py::ssize_t* shape, Hint hint = kNoHint);
  Rows vector(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok = false);
  Rows weights(PyObject* obj, const char* name);
  void batchAxis(py::ssize_t n, const char* name, const std::string& shape);
  void addBlock(int segment, PyObject* alpha, PyObject* beta, const std::string& label, PyObject* classical = nullptr);
  void parseFExt(PyObject* obj);
  void parseConstraints(PyObject* obj);
  void parseFriction(FrictionArg& parser, PyObject* obj);

  bool batch_ = false;
  unsigned int nj_ = 0, ns_ = 0;
  const Addressable* addressing_ = nullptr;
  std::string first_;  // the argument that set the batch size, and its shape
  Rows q_, qd_, f_ext_, tau_, f_ext_pass_, tau_pass_;
  std::vector<WrenchArg> wrenches_;
  std::vector<int> segment_cols_;  // constraint columns per segment
  std::vector<py::object> keep_;   // converted copies the rows point into
  const vereshchagin::FrictionModel* friction_ = nullptr;
  vereshchagin::FrictionModel friction_scratch_;                  // a friction= that is not cached
  std::vector<vereshchagin::FrictionModel> friction_models_;      // friction= per row
  std::vector<const vereshchagin::FrictionModel*> row_friction_;  // empty: friction_ for all
};

// Where the results go: row b of each output starts at its pointer + b * (the row's size). The
// friction outputs are left out when friction_torque is nullptr.
struct RowOut {
  double *qdd, *tau_command, *nu, *link_acc, *smin, *friction_torque, *limit_torque, *gauss;
  int *rank, *status, *iterations;
};

// A thread's workspace on the solver's Model.
struct Engine {
  Engine(const vereshchagin::Model& m, const KDL::Vector& g, const vereshchagin::SolverOptions& o)
      : data(m, o), input(m) {
    input.gravity = g;
  }
  vereshchagin::Data data;
  vereshchagin::SolveInput input;
};

class PySolver {
 public:
  // model: a Chain or a Tree (copied). inertia_check: None (the model's), 'physical' or
  // 'joint_space'. max_constraints: None (SolverOptions' default) or an int >= 1.
  PySolver(const py::object& model, const py::object& gravity, const py::object& rcond, const py::object& damping,
           const py::object& inertia_check, const py::object& max_constraints);

  // Row b of `a` on engine k (GIL released by the caller); returns the error message or nullptr.
  const char* runRow(const SolveArgs& a, py::ssize_t b, std::size_t k);
  // Writes engine k's results as row b of `out` (a's layout); false when gauss_value overflowed.
  bool writeRow(const SolveArgs& a, py::ssize_t b, std::size_t k, const RowOut& out) const;
  // solve(): parses, solves on engine 0 and returns a SolveResult (new, or `out`).
  py::object solve(PyObject* const* args, PyObject* out);
  double timeCpp(PyObject* const* args, long reps);
  // Benchmarks only (BENCHMARKS.md, "Call mechanism"): solve() returning a dict of new numpy
  // arrays, as a result made of plain arrays would (no friction).
  py::dict solveDict(PyObject* const* args);
  // solve_batch(): args as solve()'s (`out` not read), threads: None or an int >= 0 (0: one per core).
  py::dict solveBatch(PyObject* const* args, const py::object& threads);
  py::tuple responseColumns(const py::object& joints, bool hold_sticking);

  void setGravity(const py::object& gravity);
  py::array gravity() const;
  py::tuple getState() const;
  py::object model() const { return tree_ ? py::cast(*tree_) : py::cast(*chain_); }
  bool isTree() const { return tree_ != nullptr; }
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
  py::ssize_t max_columns = 0;  // Data::maxConstraints() of every engine

 private:
  Engine& engine(std::size_t k);
  // Parses `args` into args_ and solves them on engine 0 (the caller holds the Lock).
  void solveArgs(PyObject* const* args, bool frictionless);

  std::unique_ptr<PyChain> chain_;  // the model: one of these two
  std::unique_ptr<PyTree> tree_;
  vereshchagin::Model cpp_model_;  // shared by the engines
  KDL::Vector gravity_;
  vereshchagin::SolverOptions options_;
  py::object damping_arg_;
  std::vector<std::unique_ptr<Engine>> engines_;
  SolveArgs args_;  // solve()'s, reused under the lock
  std::mutex mutex_;
  std::atomic<std::thread::id> holder_{};  // the thread inside a call, or none
  // Engine 0 holds the state of the last successful solve() or of the last row of the last
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
