#include "engine.hpp"

#include <algorithm>
#include <cmath>

namespace vsbind {

Engine::Engine(const KDL::Chain& chain, const KDL::Vector& gravity, const vereshchagin::SolverOptions& opt)
    : nj(chain.getNrOfJoints()),
      ns(chain.getNrOfSegments()),
      hd_(chain, KDL::Twist(-gravity, KDL::Vector::Zero()), opt),
      friction_(chain, KDL::Twist(-gravity, KDL::Vector::Zero()), opt),
      fk_(chain),
      q_kdl_(chain.getNrOfJoints()) {
  alfa_ = ChainHdSolver::Matrix6X::Zero(6, hd_.maxConstraints());
  beta_ = Eigen::VectorXd::Zero(hd_.maxConstraints());
  segs_ = Eigen::VectorXi::Zero(hd_.maxConstraints());
  fext_ = ChainHdSolver::Matrix6X::Zero(6, ns);
}

void Engine::setGravity(const KDL::Vector& gravity) {
  const KDL::Twist up(-gravity, KDL::Vector::Zero());  // the base accelerates against gravity
  hd_.setRootAcceleration(up);
  friction_.setRootAcceleration(up);
}

const char* Engine::errorMessage() const {
  return last_friction_ ? friction_.errorMessage() : hd_.errorMessage();
}

// r = p_link - p_tip in base axes at the row's q (forward kinematics of the segment's tip).
KDL::Vector Engine::tipOffsetInBase(int segment, const KDL::Vector& offset) {
  KDL::Frame tip;
  fk_.JntToCart(q_kdl_, tip, segment + 1);
  return tip.M * offset;
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
  int rc = in.friction ? friction_.setPassThrough(pf, pt) : hd_.setPassThrough(pf, pt);
  if (rc == ChainHdSolver::E_NOERROR) rc = runWeighted(in);
  if (in.friction)  // the weights hold for this row only
    friction_.clearPassThrough();
  else
    hd_.clearPassThrough();
  return rc;
}

int Engine::runWeighted(const RowInputs& in) {
  using Map6X = Eigen::Map<const ChainHdSolver::Matrix6X>;
  using MapV = Eigen::Map<const Eigen::VectorXd>;
  const MapV q(in.q, nj), qd(in.qd, nj);
  bool needs_fk = in.n_link_wrenches > 0;
  for (int b = 0; b < in.n_blocks; ++b) needs_fk |= in.blocks[b].has_offset;
  if (needs_fk) q_kdl_.data = q;
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
    return last_friction_ ? friction_.solve(q, qd, A, b, sg, f, tau, *in.friction) : hd_.solve(q, qd, A, b, sg, f, tau);
  }
  return last_friction_ ? friction_.solve(q, qd, A, b, f, tau, *in.friction) : hd_.solve(q, qd, A, b, f, tau);
}

void Engine::writeCore(double* qdd, double* tau_cmd, double* nu, double* link_acc, int* rank, double* smin) {
  const vereshchagin::HdSolver& s = answered();
  if (last_friction_) {  // outputs at the friction optimum
    std::copy(friction_.qdd().data(), friction_.qdd().data() + nj, qdd);
    std::copy(friction_.commandTorques().data(), friction_.commandTorques().data() + nj, tau_cmd);
    std::copy(friction_.nu().data(), friction_.nu().data() + columns_, nu);
  } else {
    std::copy(s.qdd().data(), s.qdd().data() + nj, qdd);
    std::copy(s.commandTorques().data(), s.commandTorques().data() + nj, tau_cmd);
    std::copy(s.nu().data(), s.nu().data() + columns_, nu);
  }
  if (link_acc) {
    const ChainHdSolver::Matrix6X& acc = last_friction_ ? friction_.linkAccelerations() : s.linkAccelerations();
    std::copy(acc.data(), acc.data() + 6 * (ns + 1), link_acc);
  }
  *rank = s.constraintRank();
  *smin = s.smallestSingularValue();
}

void Engine::writeFriction(double* friction_torque, double* limit_torque, int* status, double* gauss, int* iterations) {
  std::copy(friction_.frictionTorques().data(), friction_.frictionTorques().data() + nj, friction_torque);
  std::copy(friction_.limitTorques().data(), friction_.limitTorques().data() + nj, limit_torque);
  for (unsigned int j = 0; j < nj; ++j) status[j] = friction_.status()[j];
  *gauss = friction_.gaussValue();
  *iterations = friction_.iterations();
}

}  // namespace vsbind
