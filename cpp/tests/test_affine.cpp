// Affine response to feed-forward torques: responseColumns() after a solve must equal
//  (a) central finite differences of full solves in ff_torques (the map is affine, so the only error
//      is round-off; step 1 N m), for q_dotdot and the command torques, and
//  (b) the dense formulas. With H the joint-space inertia (KDL's ChainDynParam on the chain with
//      rotor inertias removed, plus the rotor inertias on the diagonal), J the base-frame end Jacobian
//      (ChainJntToJacSolver), A = alfa^T J and K = A H^-1 A^T:
//        H qdd = tau + tau_cmd - C,   tau_cmd = -A^T nu,   A qdd = b
//      => nu = K^-1 (A H^-1 (tau - C) - b), so
//        d nu / d tau      = K^-1 A H^-1,
//        d tau_cmd / d tau = -A^T K^-1 A H^-1,
//        d qdd / d tau     = H^-1 (I - A^T K^-1 A H^-1) = H^-1 - H^-1 A^T K^-1 A H^-1 = G.
//      (The sign of d nu / d tau is checked by finite differences too.)
// Part (b) uses well-conditioned tasks with nc <= n; part (a) also rank-deficient ones (nc > n) and
// the damped least-squares policy, where the map stays affine.
#include <doctest/doctest.h>
#include <Eigen/Cholesky>

#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"

using testutil::relErr;
using testutil::relErrCols;
using testutil::str;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;

TEST_CASE("response columns vs finite differences and dense formulas on 400 random chains") {
  int fd_samples = 0, dense_samples = 0, skipped = 0, columns = 0;
  double worst_fd = 0.0, worst_dense = 0.0, worst_sym = 0.0;

  for (int s = 0; s < 400; ++s) {
    const unsigned long long seed = 15485863ULL * static_cast<unsigned long long>(s) + 5ULL;
    testutil::RandomGen g(seed);
    testutil::ChainSpec spec;
    spec.n_joints = g.integer(1, 12);
    if (g.coin(0.25)) {
      const int nf = g.integer(1, 3);
      for (int f = 0; f < nf; ++f) spec.fixed_before.push_back(g.integer(0, spec.n_joints));
    }
    const int n = spec.n_joints;
    const bool rank_deficient_ok = g.coin(0.2);
    const int nc = rank_deficient_ok ? g.integer(0, 6) : g.integer(0, std::min(6, n));
    const bool damped = g.coin(0.15);
    const KDL::Chain chain = g.chain(spec);
    const unsigned int ns = chain.getNrOfSegments();
    const KDL::Twist root_acc =
        g.coin() ? KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()) : KDL::Twist::Zero();
    const KDL::JntArray q = g.q(n), qd = g.qdot(n), ff = g.torques(n);
    const Matrix6X fext = testutil::toMatrix(g.fext(ns));
    const Matrix6X alfa = g.alfa(nc).data;
    const Eigen::VectorXd beta = g.beta(nc).data;
    const int k = g.integer(1, n + 2);
    Eigen::VectorXi joints(k);
    for (int c = 0; c < k; ++c) joints(c) = g.integer(0, n - 1);  // repeats allowed
    const std::string tag = "sample " + str(s) + " (seed " + str(seed) + ", n=" + str(n) +
                            ", fixed=" + str(spec.fixed_before.size()) + ", nc=" + str(nc) + ", damped=" + str(damped) +
                            ")";

    vereshchagin::SolverOptions opt;
    if (damped) {
      opt.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
      opt.damping = 1e-3;
    }
    vereshchagin::ChainHdSolver solver(chain, root_acc, opt), other(chain, root_acc, opt);
    int rc = solver.solve(q.data, qd.data, alfa, beta, fext, ff.data);
    if (!CHECK_MESSAGE(rc == 0, tag << ": solve returned " << str(rc) << " " << solver.errorMessage())) continue;
    const Eigen::VectorXd qdd0 = solver.qdd(), tau0 = solver.commandTorques(), nu0 = solver.nu();
    const Matrix6X acc0 = solver.linkAccelerations();

    Eigen::MatrixXd dqdd = Eigen::MatrixXd::Constant(n, k, NAN), dtau = Eigen::MatrixXd::Constant(n, k, NAN);
    rc = solver.responseColumns(joints, dqdd, dtau);
    if (!CHECK_MESSAGE(rc == 0, tag << ": responseColumns returned " << str(rc) << " " << solver.errorMessage()))
      continue;
    CHECK_MESSAGE((dqdd.allFinite() && dtau.allFinite()), tag << ": non-finite response");
    CHECK_MESSAGE((solver.qdd() == qdd0 && solver.commandTorques() == tau0 && solver.nu() == nu0 &&
                   solver.linkAccelerations() == acc0),
                  tag << ": responseColumns changed the solve results");
    columns += k;

    // Every joint in chain order takes the symmetric path (half the outward pass, the rest
    // mirrored); the same columns requested in reverse order take the general one.
    Eigen::VectorXi all(n), rev(n);
    for (int j = 0; j < n; ++j) all(j) = j, rev(j) = n - 1 - j;
    Eigen::MatrixXd g_all(n, n), t_all(n, n), g_rev(n, n), t_rev(n, n);
    Eigen::MatrixXd nu_all = Eigen::MatrixXd::Constant(6, n, NAN), nu_rev(6, n), nu_skip(6, n);
    rc = solver.responseColumns(all, g_all, t_all, nu_all) + solver.responseColumns(rev, g_rev, t_rev, nu_rev);
    if (!CHECK_MESSAGE(rc == 0, tag << ": all-joint responseColumns failed: " << solver.errorMessage())) continue;
    // The two orders of evaluation differ by round-off, 1e-12 of the columns' scale; where the
    // multiplier responses d nu are large, d tau_cmd = -J^T alfa d nu and d qdd come out of a
    // cancellation of terms that large, and the round-off grows in proportion (measured 8e-12
    // with |d nu| = 6e4 on a chain with as many constraints as joints, where d qdd is 0 exactly).
    const double dnu_max = nc > 0 ? nu_all.topRows(nc).cwiseAbs().maxCoeff() : 0.0;
    const double order_tol = 1e-12 * std::max(1.0, dnu_max / 100.0);
    Eigen::MatrixXd g_back(n, n), t_back(n, n), nu_back(nc, n);
    for (int j = 0; j < n; ++j) {
      g_back.col(j) = g_rev.col(n - 1 - j);
      t_back.col(j) = t_rev.col(n - 1 - j);
      nu_back.col(j) = nu_rev.col(n - 1 - j).head(nc);
    }
    const double e_sym = std::max(relErrCols(g_all, g_back), relErrCols(t_all, t_back));
    worst_sym = std::max(worst_sym, e_sym);
    CHECK_MESSAGE((e_sym <= order_tol && g_all == g_all.transpose()),
                  tag << ": symmetric all-joint response vs reverse order, rel err " << str(e_sym) << " (tolerance "
                      << str(order_tol) << ")");
    CHECK_MESSAGE(relErrCols(nu_all.topRows(nc), nu_back) <= order_tol, tag << ": all-joint d nu vs reverse order");
    // dtau_cmd may be skipped (empty) beside dnu: the other outputs are unchanged, bit for bit.
    Eigen::MatrixXd g_skip(n, n), none(0, 0);
    rc = solver.responseColumns(all, g_skip, none, nu_skip);
    CHECK_MESSAGE((rc == 0 && g_skip == g_all && nu_skip.topRows(nc) == nu_all.topRows(nc)),
                  tag << ": responseColumns without dtau_cmd differs");
    // commandTorquesOf: commandTorques() for nu(), linear in nu (the columns of dtau_cmd).
    Eigen::VectorXd tau_of(n);
    rc = solver.commandTorquesOf(nu0, tau_of);
    CHECK_MESSAGE((rc == 0 && tau_of == tau0), tag << ": commandTorquesOf(nu()) != commandTorques()");
    for (int j = 0; j < n && nc > 0; ++j) {
      const Eigen::VectorXd nu_j = nu0 + nu_all.col(j).head(nc);
      solver.commandTorquesOf(nu_j, tau_of);
      const double scale = std::max({1.0, tau0.cwiseAbs().maxCoeff(), t_all.col(j).cwiseAbs().maxCoeff()});
      CHECK_MESSAGE((tau_of - tau0 - t_all.col(j)).cwiseAbs().maxCoeff() <= order_tol * scale,
                    tag << ": commandTorquesOf(nu + dnu) - tau_cmd != dtau_cmd, joint " << str(j));
    }
    CHECK_MESSAGE(solver.commandTorquesOf(Eigen::VectorXd::Zero(nc + 1), tau_of) == KDL::SolverI::E_SIZE_MISMATCH,
                  tag << ": commandTorquesOf accepted a wrong-size nu");

    // (a) central differences of full solves, step h.
    const double h = 1.0;
    Eigen::MatrixXd fd_qdd(n, k), fd_tau(n, k), fd_nu(nc, k);
    bool ok = true;
    for (int c = 0; c < k; ++c) {
      Eigen::VectorXd tp = ff.data, tm = ff.data;
      tp(joints(c)) += h;
      tm(joints(c)) -= h;
      ok = ok && other.solve(q.data, qd.data, alfa, beta, fext, tp) == 0;
      const Eigen::VectorXd qp = other.qdd(), cp = other.commandTorques(), np = other.nu();
      ok = ok && other.solve(q.data, qd.data, alfa, beta, fext, tm) == 0;
      fd_qdd.col(c) = (qp - other.qdd()) / (2 * h);
      fd_tau.col(c) = (cp - other.commandTorques()) / (2 * h);
      fd_nu.col(c) = (np - other.nu()) / (2 * h);
    }
    if (!CHECK_MESSAGE(ok, tag << ": finite-difference solves failed")) continue;
    ++fd_samples;
    const double e_fq = relErrCols(dqdd, fd_qdd), e_ft = relErrCols(dtau, fd_tau);
    worst_fd = std::max({worst_fd, e_fq, e_ft});
    CHECK_MESSAGE(e_fq <= 1e-7, tag << ": d qdd / d tau vs finite differences, rel err " << str(e_fq) << "\n  ours "
                                    << testutil::mat(dqdd) << "\n  fd   " << testutil::mat(fd_qdd));
    CHECK_MESSAGE(e_ft <= 1e-7, tag << ": d tau_cmd / d tau vs finite differences, rel err " << str(e_ft) << "\n  ours "
                                    << testutil::mat(dtau) << "\n  fd   " << testutil::mat(fd_tau));

    // (b) dense formulas (truncated policy, well-conditioned, nc <= n).
    if (damped || nc > n) continue;
    const testutil::DenseModel d = testutil::denseModel(chain, q);
    if (!testutil::wellConditioned(testutil::couplingEigenvalues(d, alfa))) {
      ++skipped;
      continue;
    }
    ++dense_samples;
    const Eigen::MatrixXd Hinv = d.H.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
    const Eigen::MatrixXd A = alfa.transpose() * d.J;  // nc x n
    Eigen::MatrixXd G = Hinv, T = Eigen::MatrixXd::Zero(n, n), N = Eigen::MatrixXd::Zero(nc, n);
    if (nc > 0) {
      const Eigen::MatrixXd K = A * Hinv * A.transpose();
      N = K.ldlt().solve(A * Hinv);  // d nu / d tau
      T = -A.transpose() * N;        // d tau_cmd / d tau
      G = Hinv + Hinv * T;           // H^-1 - H^-1 A^T K^-1 A H^-1
    }
    Eigen::MatrixXd Gc(n, k), Tc(n, k), Nc(nc, k);
    for (int c = 0; c < k; ++c) {
      Gc.col(c) = G.col(joints(c));
      Tc.col(c) = T.col(joints(c));
      Nc.col(c) = N.col(joints(c));
    }
    const double e_g = relErrCols(dqdd, Gc), e_t = relErrCols(dtau, Tc), e_n = relErrCols(fd_nu, Nc);
    worst_dense = std::max({worst_dense, e_g, e_t});
    CHECK_MESSAGE(e_g <= 1e-9, tag << ": d qdd / d tau vs dense G, rel err " << str(e_g) << "\n  ours  "
                                   << testutil::mat(dqdd) << "\n  dense " << testutil::mat(Gc));
    CHECK_MESSAGE(e_t <= 1e-9, tag << ": d tau_cmd / d tau vs dense -A^T K^-1 A H^-1, rel err " << str(e_t)
                                   << "\n  ours  " << testutil::mat(dtau) << "\n  dense " << testutil::mat(Tc));
    CHECK_MESSAGE(e_n <= 1e-7,
                  tag << ": finite differences of nu vs dense K^-1 A H^-1 (sign check), rel err " << str(e_n));
  }

  CHECK_MESSAGE(
      (fd_samples >= 350 && dense_samples >= 250 && skipped * 10 <= dense_samples),
      "too few samples: fd " << str(fd_samples) << ", dense " << str(dense_samples) << ", skipped " << str(skipped));
  MESSAGE(str(fd_samples) << " samples vs finite differences, " << str(dense_samples) << " vs dense formulas ("
                          << str(skipped) << " ill-conditioned skipped), " << str(columns)
                          << " columns; worst rel err fd " << str(worst_fd) << ", dense " << str(worst_dense)
                          << ", symmetric path " << str(worst_sym));
}

TEST_CASE("empty requests: no joints, commandTorquesOf before a solve and with no constraint") {
  testutil::RandomGen g(3);
  const KDL::Chain chain = g.chain(4);
  vereshchagin::ChainHdSolver solver(chain, KDL::Twist::Zero());
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(4);
  CHECK_MESSAGE(solver.solve(q, q, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X(6, 0), Eigen::VectorXd(0)) == 0,
                "empty-request setup solve");
  Eigen::MatrixXd a(4, 0), b(4, 0);
  CHECK_MESSAGE(solver.responseColumns(Eigen::VectorXi(0), a, b) == 0, "responseColumns with no joints");
  Eigen::VectorXd tau(4);
  vereshchagin::ChainHdSolver fresh(chain, KDL::Twist::Zero());
  CHECK_MESSAGE(fresh.commandTorquesOf(Eigen::VectorXd(0), tau) == vereshchagin::ChainHdSolver::E_NO_SOLUTION,
                "commandTorquesOf before a solve");
  CHECK_MESSAGE((solver.commandTorquesOf(Eigen::VectorXd(0), tau) == 0 && tau.isZero()), "commandTorquesOf with m = 0");
}
