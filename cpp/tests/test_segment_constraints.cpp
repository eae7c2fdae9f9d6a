// Constraints on any segments (the several-segment path of ChainHdSolver::solve) against an
// oracle built from KDL's own pieces, none of which shares code with our sweeps:
//  * H from ChainDynParam (+ rotor inertias), J_k from ChainJntToJacSolver (segment k's tip,
//    base axes), the unconstrained motion qdd_free and link accelerations from KDL's
//    ChainHdSolver_Vereshchagin with no constraint (verified equal to KDL's RNE forward dynamics);
//  * the bias of each constraint b = alfa_c^T (Xdd_k - J_k qdd_free), since Xdd_k is affine in qdd;
//  * Gauss' principle as a dense KKT system: qdd = qdd_free + H^-1 A^T lambda with
//    (A H^-1 A^T) lambda = beta - alfa^T b - A qdd_free, A = [alfa_c^T J_{k(c)}];
//    then nu = -lambda and tau_cmd = A^T lambda = -sum J^T alfa nu.
// Also: KDL's forward dynamics driven by ff + our command torques reproduces our qdd; the general
// path equals the end-segment path when only the last segment is constrained; column order only
// permutes nu; response columns equal exact differences of two solves; a rank-deficient set of
// constraints gives finite outputs and the reported rank.
#include <algorithm>
#include <numeric>

#include <doctest/doctest.h>
#include <Eigen/LU>
#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"

using testutil::relErr;
using testutil::str;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;

namespace {

// Unconstrained motion and link accelerations (base axes, tip origins) from KDL.
struct Free {
  Eigen::VectorXd qdd;
  Matrix6X acc;  // column i + 1: segment i
};

Free kdlFree(const KDL::Chain& chain, const KDL::Twist& root_acc, const KDL::JntArray& q, const KDL::JntArray& qd,
             const KDL::Wrenches& fext, const KDL::JntArray& tau) {
  const unsigned int n = chain.getNrOfJoints();
  KDL::ChainHdSolver_Vereshchagin kdl(chain, root_acc, 0);
  KDL::JntArray qdd(n), tc(n);
  KDL::Jacobian none(0);
  KDL::JntArray no_beta(0);
  kdl.CartToJnt(q, qd, qdd, none, no_beta, fext, tau, tc);
  std::vector<KDL::Twist> acc(chain.getNrOfSegments() + 1);
  kdl.getTransformedLinkAcceleration(acc);
  return Free{qdd.data, testutil::toMatrix(acc)};
}

Eigen::MatrixXd segmentJacobian(const KDL::Chain& chain, const KDL::JntArray& q, int segment) {
  KDL::ChainJntToJacSolver jac(chain);
  KDL::Jacobian J(chain.getNrOfJoints());
  jac.JntToJac(q, J, segment + 1);
  return J.data;
}

}  // namespace

TEST_CASE("600 random tasks on any segments against KDL's pieces: KKT, FD, column order, response columns") {
  int compared = 0, skipped = 0;
  double worst_qdd = 0.0, worst_nu = 0.0, worst_tau = 0.0, worst_fd = 0.0, worst_cols = 0.0;
  for (int s = 0; s < 600; ++s) {
    const unsigned long long seed = 7919ULL * static_cast<unsigned long long>(s) + 5ULL;
    testutil::RandomGen g(seed);
    const int n = g.integer(2, 12);
    const KDL::Chain chain = g.chain(n);
    const int ns = static_cast<int>(chain.getNrOfSegments());
    const bool gravity = g.coin(0.7);
    const KDL::Twist root_acc = gravity ? KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()) : KDL::Twist::Zero();
    const KDL::JntArray q = g.q(n), qd = g.qdot(n), ff = g.torques(n);
    const KDL::Wrenches fext = g.fext(ns);
    const Matrix6X fe = testutil::toMatrix(fext);
    // 1..3 distinct segments, m_k columns each, at most n columns in total (full rank generically).
    const int nseg = std::min(ns, g.integer(1, 3));
    std::vector<int> pool(ns);
    std::iota(pool.begin(), pool.end(), 0);
    std::vector<int> chosen;
    for (int k = 0; k < nseg; ++k) {
      const int pick = g.integer(k, ns - 1);
      std::swap(pool[k], pool[pick]);
      chosen.push_back(pool[k]);
    }
    // Generically full rank: segment k (k + 1 joints up to it, no fixed joints here) gets at most
    // k + 1 columns minus those already on more proximal segments.
    std::sort(chosen.begin(), chosen.end());
    std::vector<int> seg_of_col;
    for (int k = 0; k < nseg; ++k) {
      const int cap = std::min(6, chosen[k] + 1 - static_cast<int>(seg_of_col.size()));
      if (cap < 1) continue;
      const int mk = g.integer(1, cap);
      for (int c = 0; c < mk; ++c) seg_of_col.push_back(chosen[k]);
    }
    // Interleave the columns of different segments (the solver must not assume grouping).
    for (std::size_t c = seg_of_col.size(); c > 1; --c)
      std::swap(seg_of_col[c - 1], seg_of_col[g.integer(0, static_cast<int>(c) - 1)]);
    const int M = static_cast<int>(seg_of_col.size());
    const Matrix6X alfa = g.alfa(M).data;
    const Eigen::VectorXd beta = g.beta(M).data;
    Eigen::VectorXi segs(M);
    for (int c = 0; c < M; ++c) segs(c) = seg_of_col[c];
    const std::string tag = "sample " + str(s) + " (n=" + str(n) + ", M=" + str(M) + ", segments " + str(nseg) + ")";

    vereshchagin::ChainHdSolver ours(chain, root_acc);
    int rc = ours.solve(q.data, qd.data, alfa, beta, segs, fe, ff.data);
    if (!CHECK_MESSAGE(rc == 0, tag << ": solve returned " << str(rc) << " " << ours.errorMessage())) continue;
    const Eigen::VectorXd qdd = ours.qdd(), nu = ours.nu(), tau = ours.commandTorques();
    CHECK_MESSAGE((qdd.allFinite() && nu.allFinite() && tau.allFinite() && nu.size() == M), tag << ": outputs");

    // Dense KKT oracle.
    const testutil::DenseModel d = testutil::denseModel(chain, q);
    const Free fr = kdlFree(chain, root_acc, q, qd, fext, ff);
    Eigen::MatrixXd A(M, n);
    Eigen::VectorXd rhs(M);
    for (int c = 0; c < M; ++c) {
      const Eigen::MatrixXd J = segmentJacobian(chain, q, segs(c));
      A.row(c) = alfa.col(c).transpose() * J;
      const Eigen::VectorXd bias = fr.acc.col(segs(c) + 1) - J * fr.qdd;
      rhs(c) = beta(c) - alfa.col(c).dot(bias) - A.row(c).dot(fr.qdd);
    }
    const Eigen::PartialPivLU<Eigen::MatrixXd> Hlu(d.H);
    const Eigen::MatrixXd HinvAt = Hlu.solve(A.transpose());
    const Eigen::MatrixXd K = A * HinvAt;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (K + K.transpose()), Eigen::EigenvaluesOnly);
    CHECK_MESSAGE((ours.constraintRank() == M || !testutil::wellConditioned(es.eigenvalues(), 1e-9)),
                  tag << ": rank " << str(ours.constraintRank()) << " of a well-posed task");
    if (!testutil::wellConditioned(es.eigenvalues())) {
      ++skipped;
      continue;
    }
    const Eigen::VectorXd lambda = K.ldlt().solve(rhs);
    const Eigen::VectorXd qdd_ref = fr.qdd + HinvAt * lambda;
    const double e_qdd = relErr(qdd, qdd_ref), e_nu = relErr(nu, -lambda), e_tau = relErr(tau, A.transpose() * lambda);
    CHECK_MESSAGE(e_qdd <= 1e-9, tag << ": qdd vs KKT rel err " << str(e_qdd));
    CHECK_MESSAGE(e_nu <= 1e-9, tag << ": nu vs KKT rel err " << str(e_nu));
    CHECK_MESSAGE(e_tau <= 1e-9, tag << ": tau_cmd vs KKT rel err " << str(e_tau));
    worst_qdd = std::max(worst_qdd, e_qdd);
    worst_nu = std::max(worst_nu, e_nu);
    worst_tau = std::max(worst_tau, e_tau);
    ++compared;

    // KDL forward dynamics with ff + our command torques gives our qdd.
    KDL::JntArray ff_cmd(n);
    ff_cmd.data = ff.data + tau;
    const double e_fd = relErr(kdlFree(chain, root_acc, q, qd, fext, ff_cmd).qdd, qdd);
    CHECK_MESSAGE(e_fd <= 1e-9, tag << ": KDL FD with command torques rel err " << str(e_fd));
    worst_fd = std::max(worst_fd, e_fd);

    // Response columns equal exact differences (the solution is affine in ff).
    Eigen::VectorXi joints(n);
    for (int j = 0; j < n; ++j) joints(j) = j;
    Eigen::MatrixXd dq(n, n), dt(n, n), dn(M, n);
    rc = ours.responseColumns(joints, dq, dt, dn);
    CHECK_MESSAGE(rc == 0, tag << ": responseColumns " << str(rc));
    Eigen::VectorXd tau_of(n);
    CHECK_MESSAGE((ours.commandTorquesOf(nu, tau_of) == 0 && tau_of == tau),
                  tag << ": commandTorquesOf(nu()) != commandTorques()");
    vereshchagin::ChainHdSolver other(chain, root_acc);
    for (int j = 0; j < n; j += 3) {
      Eigen::VectorXd ff2 = ff.data;
      ff2(j) += 1.0;
      other.solve(q.data, qd.data, alfa, beta, segs, fe, ff2);
      // The difference of two solves carries their round-off: measure at the solutions' scale.
      auto err = [](const Eigen::VectorXd& col, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
        const double scale = std::max({1.0, a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff()});
        return (col - (a - b)).cwiseAbs().maxCoeff() / scale;
      };
      const double e = std::max({err(dq.col(j), other.qdd(), qdd), err(dt.col(j), other.commandTorques(), tau),
                                 err(dn.col(j), other.nu(), nu)});
      CHECK_MESSAGE(e <= 1e-9, tag << ": response column " << str(j) << " rel err " << str(e));
      worst_cols = std::max(worst_cols, e);
    }

    // Reversed column order: same motion, nu permuted.
    Matrix6X alfa_rev(6, M);
    Eigen::VectorXd beta_rev(M);
    Eigen::VectorXi segs_rev(M);
    for (int c = 0; c < M; ++c) {
      alfa_rev.col(c) = alfa.col(M - 1 - c);
      beta_rev(c) = beta(M - 1 - c);
      segs_rev(c) = segs(M - 1 - c);
    }
    other.solve(q.data, qd.data, alfa_rev, beta_rev, segs_rev, fe, ff.data);
    CHECK_MESSAGE((relErr(other.qdd(), qdd) <= 1e-10 && relErr(other.nu().reverse(), nu) <= 1e-10),
                  tag << ": column order changes the solution");
  }
  MESSAGE("compared " << str(compared) << " (skipped ill-conditioned " << str(skipped) << "); worst rel err qdd "
                      << str(worst_qdd) << ", nu " << str(worst_nu) << ", tau_cmd " << str(worst_tau) << ", KDL FD "
                      << str(worst_fd) << ", response columns " << str(worst_cols));
}

TEST_CASE("the general path equals the end-segment path with a zero column on another segment") {
  double worst_path = 0.0;
  // The general path equals the end-segment path: last-segment constraints plus a zero column on
  // another segment (which forces the general path and is truncated away).
  for (int s = 0; s < 200; ++s) {
    testutil::RandomGen g(31ULL * s + 3ULL);
    const int n = g.integer(2, 10);
    const KDL::Chain chain = g.chain(n);
    const int ns = static_cast<int>(chain.getNrOfSegments());
    const KDL::Twist root_acc(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());
    const KDL::JntArray q = g.q(n), qd = g.qdot(n), ff = g.torques(n);
    const Matrix6X fe = testutil::toMatrix(g.fext(ns));
    const int m = g.integer(1, 6);
    const Matrix6X alfa = g.alfa(m).data;
    const Eigen::VectorXd beta = g.beta(m).data;
    vereshchagin::ChainHdSolver end(chain, root_acc), gen(chain, root_acc);
    if (end.solve(q.data, qd.data, alfa, beta, fe, ff.data) != 0) continue;
    Matrix6X alfa2(6, m + 1);
    alfa2 << alfa, Matrix6X::Zero(6, 1);
    Eigen::VectorXd beta2(m + 1);
    beta2 << beta, 0.0;
    Eigen::VectorXi segs = Eigen::VectorXi::Constant(m + 1, ns - 1);
    segs(m) = g.integer(0, ns - 2);
    const std::string tag = "path sample " + str(s);
    const int rc = gen.solve(q.data, qd.data, alfa2, beta2, segs, fe, ff.data);
    if (!CHECK_MESSAGE(rc == 0, tag << ": general solve " << str(rc))) continue;
    const double e = std::max({relErr(gen.qdd(), end.qdd()), relErr(gen.commandTorques(), end.commandTorques()),
                               relErr(gen.nu().head(m), end.nu()), std::abs(gen.nu()(m))});
    CHECK_MESSAGE(gen.constraintRank() == end.constraintRank(),
                  tag << ": rank " << str(gen.constraintRank()) << " vs " << str(end.constraintRank()));
    if (end.constraintRank() == m) {
      CHECK_MESSAGE(e <= 1e-10, tag << ": general vs end-segment path rel err " << str(e));
      worst_path = std::max(worst_path, e);
    }
    CHECK_MESSAGE((relErr(gen.linkAccelerations(), end.linkAccelerations()) <= 1e-9 || end.constraintRank() < m),
                  tag << ": link accelerations differ");
  }
  MESSAGE("worst rel err general vs end path " << str(worst_path));
}

TEST_CASE("conflicting constraints give finite outputs and the rank, and bad segment lists are refused") {
  // Conflicting constraints: the same wrench twice on one segment with different set-points, and
  // more columns than joints: finite outputs, reported rank.
  {
    testutil::RandomGen g(99);
    const KDL::Chain chain = g.chain(5);
    const KDL::Twist root_acc(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());
    const KDL::JntArray q = g.q(5), qd = g.qdot(5);
    Matrix6X alfa(6, 9);
    Eigen::VectorXd beta(9);
    Eigen::VectorXi segs(9);
    const Matrix6X base = g.alfa(3).data;
    for (int c = 0; c < 9; ++c) {
      alfa.col(c) = base.col(c % 3);
      beta(c) = 0.5 * c;
      segs(c) = c < 6 ? 2 : 4;
    }
    for (int policy = 0; policy < 2; ++policy) {
      vereshchagin::SolverOptions opt;
      if (policy == 1) opt.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
      vereshchagin::ChainHdSolver solver(chain, root_acc, opt);
      const int rc = solver.solve(q.data, qd.data, alfa, beta, segs, Matrix6X(6, 0), Eigen::VectorXd(0));
      CHECK_MESSAGE(rc == 0, "conflicting constraints: rc " << str(rc));
      CHECK_MESSAGE((solver.qdd().allFinite() && solver.nu().allFinite() && solver.commandTorques().allFinite()),
                    "conflicting constraints: non-finite output");
      if (policy == 0)
        CHECK_MESSAGE(solver.constraintRank() == 5,
                      "conflicting constraints: rank " << str(solver.constraintRank()) << ", expected 5 (5 joints)");
    }
    // Errors: segment out of range, more than 6 columns on one segment, size mismatch.
    vereshchagin::ChainHdSolver solver(chain, root_acc);
    Eigen::VectorXi bad = segs;
    bad(0) = 7;
    CHECK_MESSAGE(solver.solve(q.data, qd.data, alfa, beta, bad, Matrix6X(6, 0), Eigen::VectorXd(0)) ==
                      vereshchagin::ChainHdSolver::E_OUT_OF_RANGE,
                  "segment index out of range not reported");
    Eigen::VectorXi seven = Eigen::VectorXi::Constant(9, 1);
    CHECK_MESSAGE(solver.solve(q.data, qd.data, alfa, beta, seven, Matrix6X(6, 0), Eigen::VectorXd(0)) ==
                      vereshchagin::ChainHdSolver::E_TOO_MANY_CONSTRAINTS,
                  "7 columns on one segment not reported");
    CHECK_MESSAGE(solver.solve(q.data, qd.data, alfa, beta, segs.head(8), Matrix6X(6, 0), Eigen::VectorXd(0)) ==
                      vereshchagin::ChainHdSolver::E_SIZE_MISMATCH,
                  "segments/alfa size mismatch not reported");
  }
}
