// One solve's worth of C++ state for the Python Solver: a solver of the chain or tree (HdSolver),
// a FrictionSolver and the buffers that turn numpy rows into their inputs. Solver.solve uses engine 0; solve_batch
// gives each thread its own engine, so every row runs the same code as a single solve.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/segment.hpp>
#include <kdl/tree.hpp>

#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"
#include "vereshchagin/tree_hd_solver.hpp"

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
  bool general = false;           // constraints= given: the segment-constraint entry point
  const double* f_ext = nullptr;  // (n_segments, 6) or nullptr
  const LinkWrench* link_wrenches = nullptr;
  int n_link_wrenches = 0;
  const double* tau_ff = nullptr;  // (n_joints,) or nullptr
  const vereshchagin::FrictionModel* friction = nullptr;
  // Driver pass-through weights per constraint column in nu's order (nullptr: 0), see
  // ChainHdSolver::setPassThrough.
  const double* f_ext_pass_through = nullptr;
  const double* tau_ff_pass_through = nullptr;
};

// The robot of a solver: a chain, or the tree below its root segment (segment order: preorder,
// robot_tree.hpp).
struct EngineModel {
  const KDL::Chain* chain = nullptr;
  const KDL::Tree* tree = nullptr;
  std::string root;  // the tree's root segment (the base)
};

// Pose of a segment's tip in the base frame from the segments and the parent array (for moving
// moments from merged links to tips before a solve); no allocation per call.
class SegmentKinematics {
 public:
  // solver: the engine's solver of `model` (its segment order and parents).
  SegmentKinematics(const EngineModel& model, const vereshchagin::HdSolver& solver);
  KDL::Rotation tipRotation(int segment, const double* q) const;

 private:
  std::vector<KDL::Segment> segments_;
  std::vector<int> parent_, q_index_;  // q_index_: -1 for a fixed joint
};

class Engine {
 public:
  Engine(const EngineModel& model, const KDL::Vector& gravity, const vereshchagin::SolverOptions& opt);

  // Solves one row; returns 0 or the C++ error code (message in errorMessage()).
  int run(const RowInputs& in);
  // run() with the row's pass-through weights set for this solve only.
  int runWeighted(const RowInputs& in);
  const char* errorMessage() const;
  void setGravity(const KDL::Vector& gravity);

  // Results of the last run(), in the numpy layouts of SolveResult.
  int columns() const { return columns_; }
  void writeCore(double* qdd, double* tau_cmd, double* nu, double* link_acc, int* rank, double* smin);
  void writeFriction(double* friction_torque, double* limit_torque, int* status, double* gauss, int* iterations);
  bool lastHadFriction() const { return last_friction_; }
  vereshchagin::HdSolver& answered() { return last_friction_ ? friction_->hdSolver() : *hd_; }
  vereshchagin::FrictionSolver& frictionSolver();  // built at first use

  unsigned int nj, ns;

 private:
  void assembleColumns(const RowInputs& in);
  const double* assembleExternal(const RowInputs& in);
  KDL::Vector tipOffsetInBase(int segment, const KDL::Vector& offset) const;

  EngineModel model_;  // pointers into the PySolver's model, which outlives its engines
  KDL::Vector gravity_;
  vereshchagin::SolverOptions options_;
  std::unique_ptr<vereshchagin::HdSolver> hd_;
  std::unique_ptr<vereshchagin::FrictionSolver> friction_;  // nullptr until a friction-aware solve
  SegmentKinematics kinematics_;
  const double* q_ = nullptr;     // the row being solved
  ChainHdSolver::Matrix6X alfa_;  // constraint columns of a solve (6 x maxConstraints())
  Eigen::VectorXd beta_;
  Eigen::VectorXi segs_;
  ChainHdSolver::Matrix6X fext_;  // f_ext when wrenches on merged links must be added
  int columns_ = 0;
  bool last_friction_ = false;
  bool last_general_ = false;
};

}  // namespace vsbind
