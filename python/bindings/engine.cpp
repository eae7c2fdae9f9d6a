#include "engine.hpp"

#include <algorithm>
#include <cmath>

namespace vsbind {

namespace {

std::unique_ptr<vereshchagin::HdSolver> makeSolver(const EngineModel& m, const KDL::Twist& up,
                                                   const vereshchagin::SolverOptions& opt) {
  if (m.chain) return std::make_unique<ChainHdSolver>(*m.chain, up, opt);
  return std::make_unique<vereshchagin::TreeHdSolver>(*m.tree, up, opt, m.root);
}

std::unique_ptr<vereshchagin::FrictionSolver> makeFriction(const EngineModel& m, const KDL::Twist& up,
                                                           const vereshchagin::SolverOptions& opt) {
  if (m.chain) return std::make_unique<vereshchagin::FrictionSolver>(*m.chain, up, opt);
  return std::make_unique<vereshchagin::FrictionSolver>(*m.tree, up, opt, m.root);
}

KDL::Twist upward(const KDL::Vector& gravity) {
  return KDL::Twist(-gravity, KDL::Vector::Zero());
}

}  // namespace

SegmentKinematics::SegmentKinematics(const EngineModel& model, const vereshchagin::HdSolver& solver) {
  if (model.chain) {
    for (unsigned int i = 0; i < model.chain->getNrOfSegments(); ++i) {
      segments_.push_back(model.chain->getSegment(i));
      parent_.push_back(static_cast<int>(i) - 1);
    }
  } else {
    // The segment order and parents of the engine's own tree solver (solver is a TreeHdSolver).
    const auto& tree_solver = dynamic_cast<const vereshchagin::TreeHdSolver&>(solver);
    for (const std::string& name : tree_solver.segmentNames())
      segments_.push_back(model.tree->getSegments().at(name).segment);
    parent_ = tree_solver.parent();
  }
  int joints = 0;  // joints are numbered in segment order, fixed joints skipped (hd_solver.hpp)
  for (const KDL::Segment& s : segments_)
    q_index_.push_back(s.getJoint().getType() == KDL::Joint::Fixed ? -1 : joints++);
}

KDL::Rotation SegmentKinematics::tipRotation(int segment, const double* q) const {
  KDL::Rotation R = KDL::Rotation::Identity();
  for (int i = segment; i >= 0; i = parent_[static_cast<std::size_t>(i)]) {
    const int j = q_index_[static_cast<std::size_t>(i)];
    R = segments_[static_cast<std::size_t>(i)].pose(j < 0 ? 0.0 : q[j]).M * R;
  }
  return R;
}

Engine::Engine(const EngineModel& model, const KDL::Vector& gravity, const vereshchagin::SolverOptions& opt)
    : model_(model),
      gravity_(gravity),
      options_(opt),
      hd_(makeSolver(model, upward(gravity), opt)),
      kinematics_(model, *hd_) {
  nj = hd_->nrOfJoints();
  ns = hd_->nrOfSegments();
  alfa_ = ChainHdSolver::Matrix6X::Zero(6, hd_->maxConstraints());
  beta_ = Eigen::VectorXd::Zero(hd_->maxConstraints());
  segs_ = Eigen::VectorXi::Zero(hd_->maxConstraints());
  fext_ = ChainHdSolver::Matrix6X::Zero(6, ns);
}

void Engine::setGravity(const KDL::Vector& gravity) {
  gravity_ = gravity;
  const KDL::Twist up = upward(gravity);  // the base accelerates against gravity
  hd_->setRootAcceleration(up);
  if (friction_) friction_->setRootAcceleration(up);
}

// Built at the first friction-aware solve: its dense joint-space workspace (n x n matrices) costs
// nothing for solvers that never see friction.
vereshchagin::FrictionSolver& Engine::frictionSolver() {
  if (!friction_) friction_ = makeFriction(model_, upward(gravity_), options_);
  return *friction_;
}

const char* Engine::errorMessage() const {
  return last_friction_ ? friction_->errorMessage() : hd_->errorMessage();
}

// r = p_link - p_tip in base axes at the row's q (forward kinematics of the segment's tip).
KDL::Vector Engine::tipOffsetInBase(int segment, const KDL::Vector& offset) const {
  return kinematics_.tipRotation(segment, q_) * offset;
}

// Copies every block's columns into alfa_/beta_/segs_, moving moments from named links to tips.
void Engine::assembleColumns(const RowInputs& in) {
  int col = 0;
  for (int b = 0; b < in.n_blocks; ++b) {
    const ConstraintBlock& blk = in.blocks[b];
    const KDL::Vector r = blk.has_offset ? tipOffsetInBase(blk.segment, blk.offset) : KDL::Vector::Zero();
    for (int c = 0; c < blk.cols; ++c, ++col) {
      for (int row = 0; row < 6; ++row) alfa_(row, col) = blk.alpha[row * blk.cols + c];
      if (blk.has_offset) {
        const KDL::Vector f(alfa_(0, col), alfa_(1, col), alfa_(2, col));
        const KDL::Vector shift = r * f;  // m_tip = m_link + (p_link - p_tip) x f
        for (int k = 0; k < 3; ++k) alfa_(3 + k, col) += shift(k);
      }
      beta_(col) = blk.beta[c];
      segs_(col) = blk.segment;
    }
  }
  columns_ = col;
}

// f_ext as the solver reads it: the caller's array as is, or a copy with merged-link wrenches added.
const double* Engine::assembleExternal(const RowInputs& in) {
  if (in.n_link_wrenches == 0) return in.f_ext;
  if (in.f_ext)
    std::copy(in.f_ext, in.f_ext + 6 * ns, fext_.data());
  else
    fext_.setZero();
  for (int k = 0; k < in.n_link_wrenches; ++k) {
    const LinkWrench& w = in.link_wrenches[k];
    const KDL::Vector r = tipOffsetInBase(w.segment, w.offset);
    const KDL::Vector f(w.wrench[0], w.wrench[1], w.wrench[2]);
    const KDL::Vector shift = r * f;
    for (int j = 0; j < 3; ++j) {
      fext_(j, w.segment) += w.wrench[j];
      fext_(3 + j, w.segment) += w.wrench[3 + j] + shift(j);
    }
  }
  return fext_.data();
}

int Engine::run(const RowInputs& in) {
  if (in.f_ext_pass_through == nullptr && in.tau_ff_pass_through == nullptr) return runWeighted(in);
  using MapV = Eigen::Map<const Eigen::VectorXd>;
  int columns = 0;
  for (int b = 0; b < in.n_blocks; ++b) columns += in.blocks[b].cols;
  const MapV pf(in.f_ext_pass_through, in.f_ext_pass_through ? columns : 0);
  const MapV pt(in.tau_ff_pass_through, in.tau_ff_pass_through ? columns : 0);
  last_friction_ = in.friction != nullptr;  // errorMessage() of the right solver
  int rc = in.friction ? frictionSolver().setPassThrough(pf, pt) : hd_->setPassThrough(pf, pt);
  if (rc == ChainHdSolver::E_NOERROR) rc = runWeighted(in);
  if (in.friction)  // the weights hold for this row only
    friction_->clearPassThrough();
  else
    hd_->clearPassThrough();
  return rc;
}

int Engine::runWeighted(const RowInputs& in) {
  using Map6X = Eigen::Map<const ChainHdSolver::Matrix6X>;
  using MapV = Eigen::Map<const Eigen::VectorXd>;
  const MapV q(in.q, nj), qd(in.qd, nj);
  q_ = in.q;
  assembleColumns(in);
  const double* fp = assembleExternal(in);
  const Map6X f(fp, 6, fp ? ns : 0);
  const MapV tau(in.tau_ff, in.tau_ff ? nj : 0);
  const auto A = alfa_.leftCols(columns_);
  const auto b = beta_.head(columns_);
  last_friction_ = in.friction != nullptr;
  last_general_ = in.general;
  if (in.general) {
    const auto sg = segs_.head(columns_);
    return last_friction_ ? frictionSolver().solve(q, qd, A, b, sg, f, tau, *in.friction)
                          : hd_->solve(q, qd, A, b, sg, f, tau);
  }
  return last_friction_ ? frictionSolver().solve(q, qd, A, b, f, tau, *in.friction) : hd_->solve(q, qd, A, b, f, tau);
}

void Engine::writeCore(double* qdd, double* tau_cmd, double* nu, double* link_acc, int* rank, double* smin) {
  const vereshchagin::HdSolver& s = answered();
  if (last_friction_) {  // outputs at the friction optimum
    std::copy(friction_->qdd().data(), friction_->qdd().data() + nj, qdd);
    std::copy(friction_->commandTorques().data(), friction_->commandTorques().data() + nj, tau_cmd);
    std::copy(friction_->nu().data(), friction_->nu().data() + columns_, nu);
  } else {
    std::copy(s.qdd().data(), s.qdd().data() + nj, qdd);
    std::copy(s.commandTorques().data(), s.commandTorques().data() + nj, tau_cmd);
    std::copy(s.nu().data(), s.nu().data() + columns_, nu);
  }
  if (link_acc) {
    const ChainHdSolver::Matrix6X& acc = last_friction_ ? friction_->linkAccelerations() : s.linkAccelerations();
    std::copy(acc.data(), acc.data() + 6 * (ns + 1), link_acc);
  }
  *rank = s.constraintRank();
  *smin = s.smallestSingularValue();
}

void Engine::writeFriction(double* friction_torque, double* limit_torque, int* status, double* gauss, int* iterations) {
  std::copy(friction_->frictionTorques().data(), friction_->frictionTorques().data() + nj, friction_torque);
  std::copy(friction_->limitTorques().data(), friction_->limitTorques().data() + nj, limit_torque);
  for (unsigned int j = 0; j < nj; ++j) status[j] = friction_->status()[j];
  *gauss = friction_->gaussValue();
  *iterations = friction_->iterations();
}

}  // namespace vsbind
