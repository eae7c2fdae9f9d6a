// One solve's worth of C++ state for the Python Solver: a Data and a SolveInput on the solver's
// Model. Solver.solve uses engine 0; solve_batch gives each thread its own engine, so every row
// runs the same code as a single solve.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/segment.hpp>
#include <kdl/tree.hpp>

#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/friction_solver.hpp"

namespace vsbind {

using vereshchagin::ChainHdSolver;

// Constraint columns on one segment, from `constraints=` (or the end segment's alpha/beta):
// alpha (6, cols) row-major, beta (cols,). `offset`: the addressed link's origin relative to the
// segment tip, tip axes (zero unless a link merged into the segment by fixed joints was named):
// the moments are then about that link's origin and are moved to the tip at each solve.
struct ConstraintBlock {
  int segment = 0;
  int cols = 0;
  const double* alpha = nullptr;
  const double* beta = nullptr;
  KDL::Vector offset = KDL::Vector::Zero();
  bool has_offset = false;
};

// A wrench on a merged link (f_ext dict keyed by a link name): added to its segment with the
// moment moved from the link origin to the tip at each solve.
struct LinkWrench {
  int segment = 0;
  KDL::Vector offset;
  const double* wrench = nullptr;  // (6,) [force, moment about the link origin], base axes
};

// Everything one solve reads, as raw pointers into numpy memory (row-major).
struct RowInputs {
  const double* q = nullptr;
  const double* qd = nullptr;
  const ConstraintBlock* blocks = nullptr;  // end-segment alpha first (if any), then constraints=
  int n_blocks = 0;
  const double* f_ext = nullptr;  // (n_segments, 6) or nullptr
  const LinkWrench* link_wrenches = nullptr;
  int n_link_wrenches = 0;
  const double* tau_ff = nullptr;  // (n_joints,) or nullptr
  const vereshchagin::FrictionModel* friction = nullptr;
  // Driver pass-through weights per constraint column in nu's order (nullptr: 0), for this row
  // only (ConstraintBlock's weights in input.hpp).
  const double* f_ext_pass_through = nullptr;
  const double* tau_ff_pass_through = nullptr;
};

// One row's solve on a Data of the solver's shared Model: RowInputs are copied into a SolveInput
// (constraint blocks with their points and pass-through weights, frame wrenches, friction) and
// solve(model, data, input) does the rest. No algorithm here.
class Engine {
 public:
  Engine(const vereshchagin::Model& model, const KDL::Vector& gravity, const vereshchagin::SolverOptions& opt);

  // Solves one row; returns 0 or the C++ error code (message in errorMessage()).
  int run(const RowInputs& in);
  const char* errorMessage() const { return message_; }
  void setGravity(const KDL::Vector& gravity) { input_.gravity = gravity; }

  // Results of the last run(), in the numpy layouts of SolveResult.
  int columns() const { return columns_; }
  void writeCore(double* qdd, double* tau_cmd, double* nu, double* link_acc, int* rank, double* smin);
  void writeFriction(double* friction_torque, double* limit_torque, int* status, double* gauss, int* iterations);
  bool lastHadFriction() const { return last_friction_; }
  vereshchagin::Data& data() { return data_; }

  unsigned int nj, ns;

 private:
  void fillInput(const RowInputs& in);

  vereshchagin::Model model_;  // shared with the solver's other engines
  vereshchagin::Data data_;
  vereshchagin::SolveInput input_;
  const char* message_ = "";
  int columns_ = 0;
  bool last_friction_ = false;
};

}  // namespace vsbind
