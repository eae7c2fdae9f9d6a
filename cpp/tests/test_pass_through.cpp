// Driver pass-through (ChainHdSolver::setPassThrough, FrictionSolver::setPassThrough) against the
// dense formula, built from KDL's own pieces only:
//  * H from ChainDynParam (+ rotor inertias), J_k from ChainJntToJacSolver (segment k's tip, base
//    axes), A = [alfa_c^T J_{k(c)}], K = A H^-1 A^T;
//  * the constrained directions' accelerations of the unconstrained arm per driver:
//    a_nature = alfa_c^T Xdd_k from KDL's ChainHdSolver_Vereshchagin with no constraint, no f_ext
//    and no torques (gravity as root_acc, velocity products); a_fext = A H^-1 sum_i J_i^T f_i;
//    a_ff = A H^-1 tau (checked to add up to KDL's unconstrained motion with every driver);
//  * K nu = a_nature + (1 - p_f) .* a_fext + (1 - p_t) .* a_ff - beta, and
//    qdd = qdd_free - H^-1 A^T nu, qdd_free KDL's unconstrained motion with every driver.
// Random chains (prismatic, fixed and rotor-loaded joints), constraints on the last segment (the
// end-segment path) and on several segments (the general path), weights 0, 1 and in between.
// Also: all-zero weights give results bit for bit equal to no weights; the solved link
// accelerations obey alfa^T Xdd = beta + p_f a_fext + p_t a_ff; with static friction the solver's
// friction torques, compensated like any constraint-cancelled torque, satisfy the same formula
// and the stick/slip complementarity; bad weights are refused.
#include <algorithm>

#include <doctest/doctest.h>
#include <Eigen/LU>
#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"

using testutil::relErr;
using testutil::str;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;

namespace {

struct Problem {
  KDL::Chain chain;
  KDL::Twist root_acc;
  KDL::JntArray q, qd, ff;
  KDL::Wrenches fext;
  Matrix6X alfa;
  Eigen::VectorXd beta, p_f, p_t;
  Eigen::VectorXi segs;  // segment of each column
};

// Joint and base-axes link accelerations of the unconstrained arm (KDL, nc = 0).
void kdlFree(const Problem& p, const KDL::JntArray& qd, const KDL::Wrenches& fext, const KDL::JntArray& tau,
             const KDL::Twist& root_acc, Eigen::VectorXd& qdd, Matrix6X& acc) {
  const unsigned int n = p.chain.getNrOfJoints();
  KDL::ChainHdSolver_Vereshchagin kdl(p.chain, root_acc, 0);
  KDL::JntArray out(n), tc(n);
  KDL::Jacobian none(0);
  KDL::JntArray no_beta(0);
  kdl.CartToJnt(p.q, qd, out, none, no_beta, fext, tau, tc);
  std::vector<KDL::Twist> x(p.chain.getNrOfSegments() + 1);
  kdl.getTransformedLinkAcceleration(x);
  qdd = out.data;
  acc = testutil::toMatrix(x);
}

Eigen::MatrixXd segmentJacobian(const KDL::Chain& chain, const KDL::JntArray& q, int segment) {
  KDL::ChainJntToJacSolver jac(chain);
  KDL::Jacobian J(chain.getNrOfJoints());
  jac.JntToJac(q, J, segment + 1);
  return J.data;
}

// The dense formula's nu and qdd, with extra joint torques `compensated` (friction) that the
// constraints always cancel (weight 0), acting besides ff.
struct Dense {
  Eigen::VectorXd nu, qdd, a_fext, a_ff;
  double sum_err = 0.0;  // a_nature + a_fext + a_ff against KDL's unconstrained motion
};

Dense denseFormula(const Problem& p, const Eigen::VectorXd& compensated) {
  const unsigned int n = p.chain.getNrOfJoints(), ns = p.chain.getNrOfSegments();
  const int M = static_cast<int>(p.alfa.cols());
  const testutil::DenseModel d = testutil::denseModel(p.chain, p.q);
  const Eigen::PartialPivLU<Eigen::MatrixXd> Hlu(d.H);
  Eigen::MatrixXd A(M, n);
  for (int c = 0; c < M; ++c) A.row(c) = p.alfa.col(c).transpose() * segmentJacobian(p.chain, p.q, p.segs(c));
  Eigen::VectorXd gen_f = Eigen::VectorXd::Zero(n);  // sum_i J_i^T f_i
  for (unsigned int i = 0; i < ns; ++i) {
    Eigen::Matrix<double, 6, 1> w;
    w << p.fext[i].force.x(), p.fext[i].force.y(), p.fext[i].force.z(), p.fext[i].torque.x(), p.fext[i].torque.y(),
        p.fext[i].torque.z();
    gen_f += segmentJacobian(p.chain, p.q, static_cast<int>(i)).transpose() * w;
  }
  Dense out;
  out.a_fext = A * Hlu.solve(gen_f);
  out.a_ff = A * Hlu.solve(p.ff.data);
  const Eigen::VectorXd a_comp = A * Hlu.solve(compensated);
  Eigen::VectorXd qdd_nat, qdd_all;
  Matrix6X acc_nat, acc_all;
  const KDL::Wrenches no_f(ns, KDL::Wrench::Zero());
  KDL::JntArray zero(n), all_tau(n);
  all_tau.data = p.ff.data + compensated;
  kdlFree(p, p.qd, no_f, zero, p.root_acc, qdd_nat, acc_nat);
  kdlFree(p, p.qd, p.fext, all_tau, p.root_acc, qdd_all, acc_all);
  Eigen::VectorXd a_nat(M), a_all(M);
  for (int c = 0; c < M; ++c) {
    a_nat(c) = p.alfa.col(c).dot(acc_nat.col(p.segs(c) + 1));
    a_all(c) = p.alfa.col(c).dot(acc_all.col(p.segs(c) + 1));
  }
  out.sum_err = relErr(a_nat + out.a_fext + out.a_ff + a_comp, a_all);
  const Eigen::MatrixXd HinvAt = Hlu.solve(A.transpose());
  const Eigen::MatrixXd K = A * HinvAt;
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(M);
  const Eigen::VectorXd rhs =
      a_nat + (ones - p.p_f).cwiseProduct(out.a_fext) + (ones - p.p_t).cwiseProduct(out.a_ff) + a_comp - p.beta;
  out.nu = K.ldlt().solve(rhs);
  out.qdd = qdd_all - HinvAt * out.nu;
  return out;
}

// Weights: half the columns 0 or 1 exactly, the rest uniform in [0, 1].
Eigen::VectorXd weights(testutil::RandomGen& g, int M) {
  Eigen::VectorXd w(M);
  for (int c = 0; c < M; ++c) w(c) = g.coin(0.5) ? (g.coin(0.5) ? 1.0 : 0.0) : g.uniform(0.0, 1.0);
  return w;
}

Problem randomProblem(testutil::RandomGen& g, bool general) {
  Problem p;
  const int n = g.integer(2, 9);
  p.chain = g.chain(n);
  const int ns = static_cast<int>(p.chain.getNrOfSegments());
  p.root_acc = g.coin(0.7) ? KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()) : KDL::Twist::Zero();
  p.q = g.q(n);
  p.qd = g.qdot(n);
  p.ff = g.torques(n);
  p.fext = g.fext(ns);
  // Generically full rank: at most n columns, at most 6 per segment, on segments with enough
  // joints proximal to them.
  std::vector<int> seg_of_col;
  if (general) {
    for (int k = 0; k < ns && static_cast<int>(seg_of_col.size()) < n; ++k) {
      if (!g.coin(0.4)) continue;
      const int cap =
          std::min({6, k + 1 - static_cast<int>(seg_of_col.size()), n - static_cast<int>(seg_of_col.size())});
      for (int c = 0, mk = cap > 0 ? g.integer(1, cap) : 0; c < mk; ++c) seg_of_col.push_back(k);
    }
  }
  if (seg_of_col.empty()) seg_of_col.assign(g.integer(1, std::min(6, n)), ns - 1);
  const int M = static_cast<int>(seg_of_col.size());
  p.alfa = g.alfa(M).data;
  p.beta = g.beta(M).data;
  p.segs = Eigen::Map<const Eigen::VectorXi>(seg_of_col.data(), M);
  p.p_f = weights(g, M);
  p.p_t = weights(g, M);
  return p;
}

int solveWith(vereshchagin::ChainHdSolver& s, const Problem& p, bool general) {
  const Matrix6X fe = testutil::toMatrix(p.fext);
  return general ? s.solve(p.q.data, p.qd.data, p.alfa, p.beta, p.segs, fe, p.ff.data)
                 : s.solve(p.q.data, p.qd.data, p.alfa, p.beta, fe, p.ff.data);
}

struct Worst {
  double qdd = 0, nu = 0, tau_fd = 0, acc = 0, sum = 0;
  int compared = 0, skipped = 0;
};

void oracleCase(testutil::RandomGen& g, bool general, int sample, Worst& w) {
  const Problem p = randomProblem(g, general);
  const int n = static_cast<int>(p.chain.getNrOfJoints()), M = static_cast<int>(p.alfa.cols());
  const std::string tag =
      std::string(general ? "general" : "end") + " sample " + str(sample) + " (n=" + str(n) + ", M=" + str(M) + ")";
  // Well-conditioned tasks only (as the other oracle tests): cond(K) <= 1e5.
  const testutil::DenseModel d = testutil::denseModel(p.chain, p.q);
  Eigen::MatrixXd A(M, n);
  for (int c = 0; c < M; ++c) A.row(c) = p.alfa.col(c).transpose() * segmentJacobian(p.chain, p.q, p.segs(c));
  const Eigen::MatrixXd K = A * d.H.lu().solve(A.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (K + K.transpose()), Eigen::EigenvaluesOnly);
  if (!testutil::wellConditioned(es.eigenvalues())) {
    ++w.skipped;
    return;
  }
  vereshchagin::ChainHdSolver ours(p.chain, p.root_acc);
  int rc = ours.setPassThrough(p.p_f, p.p_t);
  if (!CHECK_MESSAGE(rc == 0, tag << ": setPassThrough " << str(rc) << " " << ours.errorMessage())) return;
  rc = solveWith(ours, p, general);
  if (!CHECK_MESSAGE(rc == 0, tag << ": solve " << str(rc) << " " << ours.errorMessage())) return;
  const Dense ref = denseFormula(p, Eigen::VectorXd::Zero(n));
  const double e_qdd = relErr(ours.qdd(), ref.qdd), e_nu = relErr(ours.nu(), ref.nu);
  CHECK_MESSAGE(ref.sum_err <= 1e-10, tag << ": oracle drivers do not add up, rel err " << str(ref.sum_err));
  CHECK_MESSAGE(e_qdd <= 1e-9, tag << ": qdd vs dense formula rel err " << str(e_qdd));
  CHECK_MESSAGE(e_nu <= 1e-9, tag << ": nu vs dense formula rel err " << str(e_nu));
  // The command torques realise qdd (KDL forward dynamics with ff + tau_cmd).
  Eigen::VectorXd qdd_fd;
  Matrix6X acc;
  KDL::JntArray ff_cmd(n);
  ff_cmd.data = p.ff.data + ours.commandTorques();
  kdlFree(p, p.qd, p.fext, ff_cmd, p.root_acc, qdd_fd, acc);
  const double e_fd = relErr(qdd_fd, ours.qdd());
  CHECK_MESSAGE(e_fd <= 1e-9, tag << ": KDL FD with command torques rel err " << str(e_fd));
  // What passes through: alfa_c^T Xdd = beta_c + p_f a_fext + p_t a_ff.
  Eigen::VectorXd achieved(M);
  for (int c = 0; c < M; ++c) achieved(c) = p.alfa.col(c).dot(ours.linkAccelerations().col(p.segs(c) + 1));
  const Eigen::VectorXd expect = p.beta + p.p_f.cwiseProduct(ref.a_fext) + p.p_t.cwiseProduct(ref.a_ff);
  const double e_acc = relErr(achieved, expect);
  CHECK_MESSAGE(e_acc <= 1e-9, tag << ": alfa^T Xdd vs beta + passed drivers rel err " << str(e_acc));
  w.qdd = std::max(w.qdd, e_qdd), w.nu = std::max(w.nu, e_nu), w.tau_fd = std::max(w.tau_fd, e_fd);
  w.acc = std::max(w.acc, e_acc), w.sum = std::max(w.sum, ref.sum_err);
  ++w.compared;

  // All-zero weights: bit for bit the solve without weights.
  vereshchagin::ChainHdSolver plain(p.chain, p.root_acc), zeroed(p.chain, p.root_acc);
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(M);
  CHECK_MESSAGE((zeroed.setPassThrough(z, z) == 0 && zeroed.passThroughColumns() == M),
                tag << ": zero weights accepted");
  CHECK_MESSAGE((solveWith(plain, p, general) == 0 && solveWith(zeroed, p, general) == 0),
                tag << ": zero-weight solves");
  CHECK_MESSAGE((plain.qdd() == zeroed.qdd() && Eigen::VectorXd(plain.nu()) == Eigen::VectorXd(zeroed.nu()) &&
                 plain.commandTorques() == zeroed.commandTorques()),
                tag << ": zero weights not bit-identical to no weights");
}

// Static friction with pass-through: the friction torques returned are compensated torques in the
// dense formula, and stick / slip complementarity holds.
void frictionCase(testutil::RandomGen& g, int sample, double& worst) {
  Problem p = randomProblem(g, g.coin(0.5));
  const int n = static_cast<int>(p.chain.getNrOfJoints()), M = static_cast<int>(p.alfa.cols());
  const std::string tag = "friction sample " + str(sample) + " (n=" + str(n) + ", M=" + str(M) + ")";
  for (int j = 0; j < n; ++j)
    if (g.coin(0.6)) p.qd(j) = 0.0;  // resting joints
  vereshchagin::FrictionModel fm;
  fm.static_friction = Eigen::VectorXd(n);
  for (int j = 0; j < n; ++j) fm.static_friction(j) = g.uniform(0.0, 3.0);
  const testutil::DenseModel d = testutil::denseModel(p.chain, p.q);
  Eigen::MatrixXd A(M, n);
  for (int c = 0; c < M; ++c) A.row(c) = p.alfa.col(c).transpose() * segmentJacobian(p.chain, p.q, p.segs(c));
  const Eigen::MatrixXd K = A * d.H.lu().solve(A.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (K + K.transpose()), Eigen::EigenvaluesOnly);
  if (!testutil::wellConditioned(es.eigenvalues())) return;
  vereshchagin::FrictionSolver fs(p.chain, p.root_acc);
  CHECK_MESSAGE(fs.setPassThrough(p.p_f, p.p_t) == 0, tag << ": setPassThrough");
  const Matrix6X fe = testutil::toMatrix(p.fext);
  const int rc = fs.solve(p.q.data, p.qd.data, p.alfa, p.beta, p.segs, fe, p.ff.data, fm);
  if (!CHECK_MESSAGE(rc == 0, tag << ": solve " << str(rc) << " " << fs.errorMessage())) return;
  const Dense ref = denseFormula(p, fs.frictionTorques() + fs.limitTorques());
  const double e = std::max(relErr(fs.qdd(), ref.qdd), relErr(fs.nu(), ref.nu));
  CHECK_MESSAGE(e <= 1e-8, tag << ": qdd / nu vs dense formula with the friction torques, rel err " << str(e));
  worst = std::max(worst, e);
  const double scale = std::max(1.0, fs.qdd().cwiseAbs().maxCoeff());
  for (int j = 0; j < n; ++j) {
    if (p.qd(j) != 0.0) continue;
    const double f = fs.frictionTorques()(j), a = fs.qdd()(j), fj = fm.static_friction(j);
    const bool stick = std::abs(a) <= 1e-8 * scale && std::abs(f) <= fj * (1 + 1e-12);
    const bool slip = std::abs(std::abs(f) - fj) <= 1e-10 * std::max(1.0, fj) && f * a <= 0.0;
    CHECK_MESSAGE((stick || slip), tag << ": joint " << str(j) << " neither sticks nor slips (friction " << str(f)
                                       << ", qdd " << str(a) << ", f " << str(fj) << ")");
  }
}

}  // namespace

TEST_CASE("300 random tasks on the last segment or any segments against the dense pass-through formula") {
  Worst w;
  for (int s = 0; s < 300; ++s) {
    testutil::RandomGen g(1000003ULL * static_cast<unsigned long long>(s) + 17ULL);
    oracleCase(g, s % 2 == 1, s, w);
  }
  CHECK_MESSAGE(w.compared >= 200, "too few well-conditioned samples: " << str(w.compared));
  MESSAGE(str(w.compared) << " compared, " << str(w.skipped) << " ill-conditioned skipped; worst rel err qdd "
                          << str(w.qdd) << ", nu " << str(w.nu) << ", FD " << str(w.tau_fd) << ", alfa^T Xdd "
                          << str(w.acc) << ", driver sum " << str(w.sum));
}

TEST_CASE("150 random tasks with static friction and pass-through: dense formula and complementarity") {
  double worst_friction = 0.0;
  for (int s = 0; s < 150; ++s) {
    testutil::RandomGen g(7777ULL * static_cast<unsigned long long>(s) + 3ULL);
    frictionCase(g, s, worst_friction);
  }
  MESSAGE("worst rel err with friction " << str(worst_friction));
}

TEST_CASE("bad pass-through weights are refused and leave none set") {
  testutil::RandomGen g(11);
  const KDL::Chain chain = g.chain(4);
  vereshchagin::ChainHdSolver s(chain, KDL::Twist::Zero());
  using Solver = vereshchagin::ChainHdSolver;
  const Eigen::VectorXd good = Eigen::VectorXd::Constant(2, 0.5);
  Eigen::VectorXd bad = good;
  bad(1) = 1.5;
  CHECK_MESSAGE(s.setPassThrough(bad, good) == Solver::E_OUT_OF_RANGE, "weight 1.5 refused");
  bad(1) = NAN;
  CHECK_MESSAGE(s.setPassThrough(good, bad) == Solver::E_OUT_OF_RANGE, "NaN weight refused");
  CHECK_MESSAGE(s.setPassThrough(good, Eigen::VectorXd::Zero(3)) == Solver::E_SIZE_MISMATCH,
                "weights of different sizes refused");
  CHECK_MESSAGE(s.passThroughColumns() == -1, "refused weights leave none set");
  CHECK_MESSAGE((s.setPassThrough(good, Eigen::VectorXd()) == 0 && s.passThroughColumns() == 2), "p_f alone accepted");
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(4);
  const Matrix6X alfa = g.alfa(3).data;
  const int rc = s.solve(q, q, alfa, Eigen::VectorXd::Zero(3), Matrix6X(6, 0), q);
  CHECK_MESSAGE(
      (rc == Solver::E_SIZE_MISMATCH && std::string(s.errorMessage()).find("pass-through") != std::string::npos),
      "weights for 2 columns, alfa with 3: E_SIZE_MISMATCH naming the pass-through (" << std::string(s.errorMessage())
                                                                                      << ")");
  s.clearPassThrough();
  CHECK_MESSAGE(s.solve(q, q, alfa, Eigen::VectorXd::Zero(3), Matrix6X(6, 0), q) == 0, "cleared weights: solve works");
}
