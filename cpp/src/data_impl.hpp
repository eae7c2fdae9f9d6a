// The private side of a Data (data.hpp): one HdCore on the Model's shared HdModel, the buffers
// that turn a SolveInput into the core's arguments, and the friction stage once it is needed.
#pragma once

#include <memory>
#include <vector>

#include "vereshchagin/data.hpp"

#include "hd_core.hpp"

namespace vereshchagin {
namespace detail {

class FrictionCore;
class ContactStage;
struct SymplecticWorkspace;

struct DataImpl {
  DataImpl(const Model& model, const SolverOptions& options);
  ~DataImpl();

  // Sets the status of a failed call: code and the core's message.
  Status status(int code) const { return Status(static_cast<Error>(code), code ? core.message.data() : ""); }
  // The friction stage on this Data's core, built at first use (O(n^2) memory).
  FrictionCore& friction();
  // The contact stage, built at the first solve with contacts.
  ContactStage& contacts();

  Model model;
  HdCore core;
  // One solve's inputs as the core reads them (sized once: maxConstraints() columns).
  Matrix6X alfa;             // the blocks' columns in order; moments moved to the tips in the sweep
  Eigen::VectorXd beta;      // their set-points
  Eigen::VectorXi segments;  // each column's segment
  Matrix6X f_ext;            // input f_ext plus the frame wrenches (when there are any)
  PassThroughWeights weights;
  FrameLoads loads;
  // Results of a solve with friction (zero / Moving without one).
  std::unique_ptr<FrictionCore> friction_core;
  bool friction_last = false;  // the last successful solve had friction
  Eigen::VectorXd zeros;       // n_joints
  std::vector<JointStatus> status_per_joint;
  std::unique_ptr<ContactStage> contact_stage;
  bool contacts_last = false;  // the last successful solve had contacts (or friction over a time step)
  bool stage_joints = false;   // ... with joint friction or over a time step: the joint outputs are the stage's
  std::unique_ptr<SymplecticWorkspace> symplectic;  // stepSymplectic()'s, built at its first call
};

// Assembles `in` into the core's arguments and runs the sweeps (with the friction stage when it
// has friction), without its contacts; 0 or an error code with the core's message (solve.cpp).
int runInput(DataImpl& d, const SolveInput& in);

/// `s` if q_next and qd_next are finite, else Error::NonfiniteResult with `message` (a literal):
/// a step whose position update overflows (step() in contact_step.cpp, stepSymplectic()).
Status finiteStep(const Eigen::Ref<const Eigen::VectorXd>& q_next, const Eigen::Ref<const Eigen::VectorXd>& qd_next,
                  const Status& s, const char* message);

}  // namespace detail
}  // namespace vereshchagin
