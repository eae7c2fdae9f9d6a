/// @file
/// Acceleration-constrained hybrid dynamics of a serial KDL::Chain (Popov-Vereshchagin algorithm):
/// the chain face of HdSolver (hd_solver.hpp, where the math, frames, signs, units and outputs are
/// stated), with KDL 1.5.1's ChainHdSolver_Vereshchagin entry point CartToJnt().
///
/// Segment order is the chain's (segment i is chain.getSegment(i), its parent i - 1, the base for
/// i = 0); joint j is the chain's j-th moving joint. The solve() overload without `segments` puts
/// the m <= 6 constraint columns on the last segment (the tip): the chain's fast path, whose
/// per-segment constraint algebra runs on fixed-size m-column blocks.
#pragma once

#include <vector>

#include <kdl/chain.hpp>
#include <kdl/chainidsolver.hpp>  // KDL::Wrenches
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>

#include "vereshchagin/hd_solver.hpp"
#include "vereshchagin/spatial.hpp"

namespace vereshchagin {

/// The hybrid dynamics solver of a serial KDL::Chain (see the top of this file and hd_solver.hpp).
class ChainHdSolver : public HdSolver {
 public:
  /// The chain is copied. root_acc: base acceleration (gravity as +9.81 along up), see hd_solver.hpp.
  /// Construction never throws for a bad model: the error is kept and returned by every solve
  /// (check modelError()).
  ChainHdSolver(const KDL::Chain& chain, const KDL::Twist& root_acc, const SolverOptions& options = SolverOptions());

  /// KDL-compatible entry point. alfa: KDL::Jacobian (6 x m, m = 0..6, on the last segment); beta:
  /// m entries; f_ext: one wrench per segment; command_torques: output tau_cmd (see hd_solver.hpp),
  /// must be sized n_joints like q_dotdot. Returns 0 or an error code.
  int CartToJnt(const KDL::JntArray& q, const KDL::JntArray& q_dot, KDL::JntArray& q_dotdot, const KDL::Jacobian& alfa,
                const KDL::JntArray& beta, const KDL::Wrenches& f_ext, const KDL::JntArray& ff_torques,
                KDL::JntArray& command_torques);

  /// The solver's own copy of the chain.
  const KDL::Chain& chain() const { return chain_; }

  /// The chain has changed: recompute the model data (KDL::SolverI interface).
  void updateInternalDataStructures() override;

 private:
  KDL::Chain chain_;
  Matrix6X f_ext_buf_;  // CartToJnt's f_ext as a 6 x n_segments matrix
};

}  // namespace vereshchagin
