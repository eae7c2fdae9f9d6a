// Micro-benchmark: vereshchagin::ChainHdSolver against Orocos KDL 1.5.1's
// ChainHdSolver_Vereshchagin (the same algorithm), with KDL's recursive Newton-Euler inverse
// dynamics (ChainIdSolver_RNE) and forward dynamics (ChainFdSolver_RNE) as points of scale.
//
// Chains:
//  * "7 (Gen3)": a Kinova Gen3 7-DoF arm (no vision module, no gripper). Joint origins, axes and
//    link inertias transcribed by hand from python/vereshchagin/robots/data/kinova_gen3_7dof.json,
//    which was itself expanded from Kinovarobotics/ros2_kortex
//    kortex_description/arms/gen3/7dof/urdf/gen3_macro.xacro. The fixed end-effector frame is left
//    out because KDL's Vereshchagin solver does not support a fixed last segment.
//  * "n (random)", n = 7, 15, 30, 60: seeded random serial chains, revolute joints about a mixture of
//    x, y and z, masses 0.5-2 kg, physically valid rotated inertias.
//
// For every chain, 64 random states (q, q_dot, feed-forward torques; f_ext = 0; gravity as the
// root acceleration (0, 0, +9.81)) and constraint tasks of m = 0, 1, 6 unit, mutually orthogonal
// constraint wrenches on the last segment. Timed per call:
//  * ours CartToJnt   vereshchagin::ChainHdSolver::CartToJnt (KDL types)
//  * ours solve()     vereshchagin::ChainHdSolver::solve (Eigen types)
//  * KDL              KDL::ChainHdSolver_Vereshchagin::CartToJnt (one solver per m: KDL fixes nc)
//  * KDL ID RNE / FD RNE (m-independent, gravity (0, 0, -9.81) in their convention)
//
// Method: std::chrono::steady_clock; each measurement is first warmed up and calibrated to a batch
// of about kBatchSeconds; the variants of one (chain, m) group are then run in interleaved batches
// (A B C A B C ...) so that machine noise hits them alike. Reported: the median over batches of the
// per-call time, and the median over batches of the per-batch ratio. A sink accumulates one output
// of every call so that no call can be optimised away.
//
// Usage: bench_solver [output.md]    (Markdown to stdout, and to the file if given)

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <kdl/config.h>
#include <Eigen/Core>
#include <Eigen/QR>
#include <kdl/chain.hpp>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>
#include <kdl/segment.hpp>

#include "vereshchagin/chain_hd_solver.hpp"

#include "bench_common.hpp"  // Rng, the Gen3 and random chains, the interleaved-batch timer, report helpers

namespace {

using namespace bench;

const int kTaskSizes[] = {0, 1, 6};  // the first must stay 0 (used as the unconstrained task)

// ---------------------------------------------------------------------------------------------
// Inputs

struct Task {  // m constraints for one state, in both APIs' types
  KDL::Jacobian alfa_kdl;
  KDL::JntArray beta_kdl;
  vereshchagin::ChainHdSolver::Matrix6X alfa;
  Eigen::VectorXd beta;
};

struct State {
  KDL::JntArray q_kdl, qd_kdl, tau_kdl;
  Eigen::VectorXd q, qd, tau;
  std::vector<Task> tasks;  // one per entry of kTaskSizes
};

Task makeTask(int m, Rng& rng) {
  Task t;
  // m orthonormal columns (the first m of a random orthogonal 6x6 matrix): unit and well
  // conditioned (alfa^T alfa = I).
  Eigen::Matrix<double, 6, 6> g;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) g(i, j) = rng.uniform(-1.0, 1.0);
  const Eigen::Matrix<double, 6, 6> qmat = Eigen::HouseholderQR<Eigen::Matrix<double, 6, 6>>(g).householderQ();
  t.alfa = qmat.leftCols(m);
  // beta: hold the tip against gravity along the constraint directions, plus a random set-point.
  Eigen::Matrix<double, 6, 1> up;
  up << 0.0, 0.0, kGravity, 0.0, 0.0, 0.0;
  t.beta = t.alfa.transpose() * up;
  for (int k = 0; k < m; ++k) t.beta(k) += rng.uniform(-1.0, 1.0);
  t.alfa_kdl = KDL::Jacobian(static_cast<unsigned int>(m));
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < m; ++k) t.alfa_kdl(i, k) = t.alfa(i, k);
  t.beta_kdl = toJnt(t.beta);
  return t;
}

std::vector<State> makeStates(int n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<State> states(kStates);
  for (State& s : states) {
    s.q.resize(n);
    s.qd.resize(n);
    s.tau.resize(n);
    for (int i = 0; i < n; ++i) {
      s.q(i) = rng.uniform(-kPi, kPi);
      s.qd(i) = rng.uniform(-1.0, 1.0);
      s.tau(i) = rng.uniform(-2.0, 2.0);
    }
    s.q_kdl = toJnt(s.q);
    s.qd_kdl = toJnt(s.qd);
    s.tau_kdl = toJnt(s.tau);
    for (int m : kTaskSizes) s.tasks.push_back(makeTask(m, rng));
  }
  return states;
}

struct Row {
  std::string label;
  int m = 0;
  double ours_ctj = 0, ours_solve = 0, kdl = 0, ratio_ctj = 0, ratio_solve = 0, max_dqdd = 0, max_qdd = 0,
         min_sigma = 0;
};

struct ScaleRow {
  std::string label;
  double id_rne = 0, fd_rne = 0, ours_m0 = 0, ratio_id = 0, ratio_fd = 0;
};

}  // namespace

int main(int argc, char** argv) {
  const auto wall0 = Clock::now();
  const std::string load_at_start = loadAverage();

  std::vector<ChainCase> cases;
  cases.push_back({"7 (Gen3)", std::make_unique<KDL::Chain>(makeGen3Chain()), 7});
  for (int n : {7, 15, 30, 60})
    cases.push_back(
        {std::to_string(n) + " (random)", std::make_unique<KDL::Chain>(makeRandomChain(n, 0x5eed0000ULL + n)), n});

  const KDL::Twist root_acc(KDL::Vector(0.0, 0.0, kGravity), KDL::Vector::Zero());  // Vereshchagin
  const KDL::Vector gravity(0.0, 0.0, -kGravity);                                   // RNE / FD

  std::vector<Row> rows;
  std::vector<ScaleRow> scale_rows;
  int failures = 0;

  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const ChainCase& cc = cases[ci];
    const KDL::Chain& chain = *cc.chain;
    const int n = static_cast<int>(chain.getNrOfJoints());
    const int ns = static_cast<int>(chain.getNrOfSegments());
    const std::vector<State> states = makeStates(n, 0xba5e0000ULL + 97 * ci);

    vereshchagin::ChainHdSolver ours(chain, root_acc);
    if (ours.modelError() != 0) {
      std::cerr << "model error for chain " << cc.label << ": " << ours.errorMessage() << "\n";
      return 1;
    }
    KDL::ChainIdSolver_RNE kdl_id(chain, gravity);
    KDL::ChainFdSolver_RNE kdl_fd(chain, gravity);

    const KDL::Wrenches f_ext_kdl(ns, KDL::Wrench::Zero());
    const vereshchagin::ChainHdSolver::Matrix6X f_ext = vereshchagin::ChainHdSolver::Matrix6X::Zero(6, ns);
    KDL::JntArray qdd_kdl(n), tau_out_kdl(n), tau_cmd(n), qdd_ours(n);
    const KDL::JntArray qdd_zero(n);

    for (size_t ti = 0; ti < std::size(kTaskSizes); ++ti) {
      const int m = kTaskSizes[ti];
      KDL::ChainHdSolver_Vereshchagin kdl_hd(chain, root_acc, static_cast<unsigned int>(m));

      // Agreement check (also a warm-up): ours vs KDL joint accelerations on every state.
      double max_dqdd = 0.0, max_qdd = 0.0, min_sigma = std::numeric_limits<double>::infinity();
      for (const State& s : states) {
        const Task& t = s.tasks[ti];
        const int r1 =
            ours.CartToJnt(s.q_kdl, s.qd_kdl, qdd_ours, t.alfa_kdl, t.beta_kdl, f_ext_kdl, s.tau_kdl, tau_cmd);
        const int r2 = ours.solve(s.q, s.qd, t.alfa, t.beta, f_ext, s.tau);
        const int r3 =
            kdl_hd.CartToJnt(s.q_kdl, s.qd_kdl, qdd_kdl, t.alfa_kdl, t.beta_kdl, f_ext_kdl, s.tau_kdl, tau_out_kdl);
        if (r1 != 0 || r2 != 0 || r3 != 0) {
          std::cerr << "solver error (chain " << cc.label << ", m " << m << "): ours CartToJnt " << r1
                    << ", ours solve " << r2 << ", KDL " << r3 << " " << ours.errorMessage() << "\n";
          ++failures;
        }
        max_dqdd = std::max(max_dqdd, (qdd_ours.data - qdd_kdl.data).cwiseAbs().maxCoeff());
        max_dqdd = std::max(max_dqdd, (ours.qdd() - qdd_kdl.data).cwiseAbs().maxCoeff());
        max_qdd = std::max(max_qdd, qdd_kdl.data.cwiseAbs().maxCoeff());
        if (m > 0) min_sigma = std::min(min_sigma, ours.smallestSingularValue());
      }

      std::vector<Bench> group;
      addBench(group, "ours CartToJnt", overStates(states, [&](const State& s) {
                 const Task& t = s.tasks[ti];
                 ours.CartToJnt(s.q_kdl, s.qd_kdl, qdd_ours, t.alfa_kdl, t.beta_kdl, f_ext_kdl, s.tau_kdl, tau_cmd);
                 return qdd_ours(n - 1);
               }));
      addBench(group, "ours solve()", overStates(states, [&](const State& s) {
                 const Task& t = s.tasks[ti];
                 ours.solve(s.q, s.qd, t.alfa, t.beta, f_ext, s.tau);
                 return ours.qdd()(n - 1);
               }));
      addBench(group, "KDL Vereshchagin", overStates(states, [&](const State& s) {
                 const Task& t = s.tasks[ti];
                 kdl_hd.CartToJnt(s.q_kdl, s.qd_kdl, qdd_kdl, t.alfa_kdl, t.beta_kdl, f_ext_kdl, s.tau_kdl,
                                  tau_out_kdl);
                 return qdd_kdl(n - 1);
               }));
      const std::string label = "n " + cc.label + ", m " + std::to_string(m);
      std::cerr << "timing " << label << " ..." << std::endl;
      runGroup(group, label);

      Row row;
      row.label = cc.label;
      row.m = m;
      row.ours_ctj = median(group[0].us);
      row.ours_solve = median(group[1].us);
      row.kdl = median(group[2].us);
      row.ratio_ctj = pairedRatio(group[0], group[2]);
      row.ratio_solve = pairedRatio(group[1], group[2]);
      row.max_dqdd = max_dqdd;
      row.max_qdd = max_qdd;
      row.min_sigma = min_sigma;
      rows.push_back(row);
    }

    // KDL's recursive Newton-Euler solvers for scale (independent of m).
    std::vector<Bench> group;
    addBench(group, "KDL ChainIdSolver_RNE", overStates(states, [&](const State& s) {
               kdl_id.CartToJnt(s.q_kdl, s.qd_kdl, qdd_zero, f_ext_kdl, tau_out_kdl);
               return tau_out_kdl(n - 1);
             }));
    addBench(group, "KDL ChainFdSolver_RNE", overStates(states, [&](const State& s) {
               kdl_fd.CartToJnt(s.q_kdl, s.qd_kdl, s.tau_kdl, f_ext_kdl, qdd_kdl);
               return qdd_kdl(n - 1);
             }));
    // Ours without constraints (m = 0) again, interleaved with these for paired ratios.
    addBench(group, "ours CartToJnt m=0", overStates(states, [&](const State& s) {
               const Task& t = s.tasks[0];
               ours.CartToJnt(s.q_kdl, s.qd_kdl, qdd_ours, t.alfa_kdl, t.beta_kdl, f_ext_kdl, s.tau_kdl, tau_cmd);
               return qdd_ours(n - 1);
             }));
    const std::string label = "n " + cc.label + ", RNE";
    std::cerr << "timing " << label << " ..." << std::endl;
    runGroup(group, label);
    ScaleRow srow;
    srow.label = cc.label;
    srow.id_rne = median(group[0].us);
    srow.fd_rne = median(group[1].us);
    srow.ours_m0 = median(group[2].us);
    srow.ratio_id = pairedRatio(group[2], group[0]);
    srow.ratio_fd = pairedRatio(group[2], group[1]);
    scale_rows.push_back(srow);
  }

  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();

  // ----------------------------------------------------------------------------------------------
  std::ostringstream md;
  md << "# C++ benchmark: vereshchagin::ChainHdSolver vs KDL " << KDL_VERSION_STRING << "\n\n";
  md << "- Date: " << utcNow() << "\n";
  md << "- Machine: " << cpuModel() << ", " << sysconf(_SC_NPROCESSORS_ONLN)
     << " online CPUs (nproc); load average (1, 5, 15 min) " << load_at_start << " at start, " << loadAverage()
     << " at end\n";
  md << "- Compiler: " << BENCH_CXX_COMPILER << " (`__VERSION__` = " << __VERSION__ << "), C++ " << __cplusplus << "\n";
  md << "- Build type: " << BENCH_BUILD_TYPE << "; flags (library and benchmark): `" << BENCH_CXX_FLAGS
     << "` (no -march)\n";
  md << "- KDL: system library (headers " << KDL_VERSION_STRING << ", distribution binary with its own flags); Eigen "
     << EIGEN_WORLD_VERSION << "." << EIGEN_MAJOR_VERSION << "." << EIGEN_MINOR_VERSION << "\n";
  md << "- Method: " << kStates << " pre-generated random states per chain (q in [-pi, pi], q_dot in [-1, 1], "
     << "ff torques in [-2, 2], f_ext = 0, root_acc = (0, 0, 9.81)); m orthonormal unit constraint columns on the "
     << "last segment. steady_clock; warm-up, then " << kBatches << " interleaved batches of about "
     << kBatchSeconds * 1e3 << " ms per variant; median per-call time over batches; ratio = median of "
     << "per-batch ratios. Total run time " << fmt("%.1f", wall) << " s.\n";
  md << "- Noise: largest batch inter-quartile range / median over all measurements: "
     << fmt("%.1f", 100.0 * g_worst_spread) << " % (" << g_worst_spread_name << ").\n\n";

  md << "## Constrained hybrid dynamics (microseconds per call)\n\n";
  md << "`ours` = `vereshchagin::ChainHdSolver::CartToJnt` (KDL types); `ours solve()` = the Eigen entry point; "
     << "`KDL` = `KDL::ChainHdSolver_Vereshchagin::CartToJnt` (one solver per m). "
     << "max abs dqdd = largest difference of joint accelerations between ours and KDL over all states (rad/s^2; "
     << "max abs qdd = largest joint acceleration, for scale); min sigma(K) = smallest eigenvalue of the m x m "
        "coupling "
     << "matrix over all states (ours, `smallestSingularValue()`): small values make the task ill-conditioned and "
     << "explain larger differences, since KDL pseudo-inverts K by SVD and we by eigen-decomposition.\n\n";
  md << "| n | m | ours us | ours solve() us | KDL us | ratio ours/KDL | ratio solve()/KDL | max abs dqdd | max abs "
        "qdd | min sigma(K) |\n";
  md << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows) {
    md << "| " << r.label << " | " << r.m << " | " << fmt("%.2f", r.ours_ctj) << " | " << fmt("%.2f", r.ours_solve)
       << " | " << fmt("%.2f", r.kdl) << " | " << fmt("%.2f", r.ratio_ctj) << " | " << fmt("%.2f", r.ratio_solve)
       << " | " << fmt("%.1e", r.max_dqdd) << " | " << fmt("%.1e", r.max_qdd) << " | "
       << (r.m > 0 ? fmt("%.1e", r.min_sigma) : std::string("-")) << " |\n";
  }
  md << "\n## KDL recursive Newton-Euler solvers, for scale (microseconds per call)\n\n";
  md << "Forward dynamics without constraints: ours (`CartToJnt`, m = 0, timed again interleaved with these) "
     << "against KDL's inverse dynamics (RNE, O(n)) and KDL's forward dynamics (`ChainFdSolver_RNE`: joint-space "
     << "inertia matrix, then a dense factorisation).\n\n";
  md << "| n | KDL ChainIdSolver_RNE us | KDL ChainFdSolver_RNE us | ours m=0 us | ratio ours m=0 / ID_RNE | "
     << "ratio ours m=0 / FD_RNE |\n";
  md << "|---|---:|---:|---:|---:|---:|\n";
  for (const ScaleRow& r : scale_rows) {
    md << "| " << r.label << " | " << fmt("%.2f", r.id_rne) << " | " << fmt("%.2f", r.fd_rne) << " | "
       << fmt("%.2f", r.ours_m0) << " | " << fmt("%.2f", r.ratio_id) << " | " << fmt("%.2f", r.ratio_fd) << " |\n";
  }
  if (failures) md << "\n**" << failures << " solver calls returned an error code (see stderr).**\n";
  md << "\n(sink " << fmt("%.6g", g_sink) << ")\n";

  std::cout << md.str();
  if (argc > 1) {
    std::ofstream out(argv[1]);
    if (!out) {
      std::cerr << "cannot write " << argv[1] << "\n";
      return 1;
    }
    out << md.str();
  }
  return failures ? 2 : 0;
}
