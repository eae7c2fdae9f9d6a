// Micro-benchmark of the exact static-friction solve (vereshchagin::FrictionSolver) on a 7-joint arm
// with all joints at rest, against
//  * plain     our frictionless solve, vereshchagin::ChainHdSolver::solve, same inputs;
//  * KDL       KDL 1.5.1's frictionless ChainHdSolver_Vereshchagin::CartToJnt, same inputs;
//  * vertices  the report's vertex enumeration (Vukcevic 2018, sec. 5.6): for each of the 2^7 sign
//              vectors mu = +-f, one KDL CartToJnt solve with ff - mu and the Gauss function
//              g(mu) = Z0 + mu^T qdd, keeping the best vertex.
//
// The Gauss function is evaluated as in python/vereshchagin/experiments/gauss.py, without a mass
// matrix: H (qdd - qdd_free) = tau_cmd - mu, so Z0 = 1/2 (qdd - qdd_free)^T (tau_cmd - mu), with
// qdd_free one KDL nc = 0 solve under ff (per state) and tau_cmd = -J^T alfa nu, J the base-frame
// tip Jacobian (KDL::ChainJntToJacSolver, once per state) and nu from KDL's
// getContraintForceMagnitude. (KDL's own constraint_torques output is not that command: see
// docs/kdl-pinocchio.md, "KDL 1.5.1's solver".) The vertex timing includes the
// free solve and the Jacobian.
//
// Chains: the Kinova Gen3 7-DoF chain and the seeded random 7-joint chain of bench_solver.cpp
// (bench_common.hpp). 64 seeded states per chain: q in [-pi, pi], q_dot = 0 (every joint at rest),
// gravity as root_acc = (0, 0, 9.81), f_ext = 0, static friction f_j in [0.5, 3] N m per joint
// (kinetic = static; it plays no part at rest), feed-forward torques = the gravity torque at q
// (KDL's RNE) times a random factor in [0, 1] plus U(-2, 2) N m per joint, so that some joints
// stick and some slip. Tasks on the last segment: m = 0 (none), m = 1 (a random unit direction,
// beta = alfa^T root_acc: the tip does not accelerate along it), m = 6 (alfa = identity,
// beta = root_acc: the tool is held still; one redundant degree of freedom is left).
//
// Before timing, each case checks on every state: every call succeeds; our plain solve agrees with
// KDL; the KDL-based g at the exact optimum mu* equals FrictionSolver::gaussValue(); the command
// -J^T alfa nu from KDL matches ours; the best vertex's g is at most the exact optimum's. It
// reports how often the best vertex's qdd differs from the exact qdd (relative 1e-6).
//
// Method: as bench_solver.cpp (bench_common.hpp): warm-up and calibration to batches of about
// 8 ms (a vertex-enumeration batch is one pass over the 64 states, longer), 61 interleaved batches,
// median per-call time, ratios = median of per-batch ratios, a sink.
//
// Usage: bench_friction [output.md]    (Markdown to stdout, and to the file if given)

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <kdl/config.h>
#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>

#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"

#include "bench_common.hpp"

namespace {

using namespace bench;
using Matrix6X = vereshchagin::ChainHdSolver::Matrix6X;

const int kTaskSizes[] = {0, 1, 6};
constexpr double kFrictionLo = 0.5, kFrictionHi = 3.0;  // N m, static friction per joint
constexpr double kDiffTol = 1e-6;                       // "vertex answer differs": relative qdd

// Issue targets.
constexpr double kTargetPlain = 2.5;     // friction / our plain solve: at most
constexpr double kTargetKdl = 1.0;       // friction / KDL plain solve: below
constexpr double kTargetVertex = 100.0;  // vertex enumeration / friction: at least

struct Task {
  KDL::Jacobian alfa_kdl;
  KDL::JntArray beta_kdl;
  Matrix6X alfa;
  Eigen::VectorXd beta;
};

struct State {
  KDL::JntArray q_kdl, qd_kdl, tau_kdl;
  Eigen::VectorXd q, qd, tau;
  vereshchagin::FrictionModel friction;
  std::vector<Task> tasks;  // one per entry of kTaskSizes
};

Task makeTask(int m, Rng& rng) {
  Task t;
  Eigen::Matrix<double, 6, 1> up;
  up << 0.0, 0.0, kGravity, 0.0, 0.0, 0.0;
  if (m == 6) {
    t.alfa = Matrix6X::Identity(6, 6);
  } else {
    t.alfa = Matrix6X::Zero(6, m);
    for (int k = 0; k < m; ++k) {
      for (int i = 0; i < 6; ++i) t.alfa(i, k) = rng.uniform(-1.0, 1.0);
      t.alfa.col(k).normalize();
    }
  }
  t.beta = t.alfa.transpose() * up;  // the tip does not accelerate along the constraints
  t.alfa_kdl = KDL::Jacobian(static_cast<unsigned int>(m));
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < m; ++k) t.alfa_kdl(i, k) = t.alfa(i, k);
  t.beta_kdl = toJnt(t.beta);
  return t;
}

std::vector<State> makeStates(const KDL::Chain& chain, std::uint64_t seed) {
  const int n = static_cast<int>(chain.getNrOfJoints());
  KDL::ChainIdSolver_RNE rne(chain, KDL::Vector(0.0, 0.0, -kGravity));
  const KDL::Wrenches no_wrench(chain.getNrOfSegments(), KDL::Wrench::Zero());
  const KDL::JntArray zero(n);
  KDL::JntArray gravity_torque(n);
  Rng rng(seed);
  std::vector<State> states(kStates);
  for (State& s : states) {
    s.q.resize(n);
    s.qd = Eigen::VectorXd::Zero(n);
    s.tau.resize(n);
    s.friction.static_friction.resize(n);
    for (int i = 0; i < n; ++i) s.q(i) = rng.uniform(-kPi, kPi);
    s.q_kdl = toJnt(s.q);
    rne.CartToJnt(s.q_kdl, zero, zero, no_wrench, gravity_torque);
    const double compensation = rng.uniform();
    for (int i = 0; i < n; ++i) {
      s.tau(i) = compensation * gravity_torque(i) + rng.uniform(-2.0, 2.0);
      s.friction.static_friction(i) = rng.uniform(kFrictionLo, kFrictionHi);
    }
    s.qd_kdl = toJnt(s.qd);
    s.tau_kdl = toJnt(s.tau);
    for (int m : kTaskSizes) s.tasks.push_back(makeTask(m, rng));
  }
  return states;
}

// The report's vertex enumeration with KDL solves. Workspace allocated once.
class VertexEnumeration {
 public:
  VertexEnumeration(const KDL::Chain& chain, const KDL::Twist& root_acc, int m)
      : n_(static_cast<int>(chain.getNrOfJoints())),
        m_(m),
        free_(chain, root_acc, 0),
        task_(chain, root_acc, m),
        jac_solver_(chain),
        f_ext_(chain.getNrOfSegments(), KDL::Wrench::Zero()),
        alfa0_(0),
        beta0_(0),
        qdd_free_(n_),
        qdd_(n_),
        tau_(n_),
        tau_out_(n_),
        jac_(n_),
        jta_(n_, m),
        nu_(m),
        mu_(n_),
        tau_cmd_(n_),
        best_mu_(n_),
        best_qdd_(n_) {}

  // Returns the best g; best_mu() and best_qdd() hold its vertex and motion.
  double run(const State& s, const Task& t) {
    free_.CartToJnt(s.q_kdl, s.qd_kdl, qdd_free_, alfa0_, beta0_, f_ext_, s.tau_kdl, tau_out_);
    if (m_ > 0) {
      jac_solver_.JntToJac(s.q_kdl, jac_);
      jta_.noalias() = jac_.data.transpose() * t.alfa;
    }
    const Eigen::VectorXd& f = s.friction.static_friction;
    double best = -std::numeric_limits<double>::infinity();
    for (unsigned v = 0; v < (1u << n_); ++v) {
      for (int j = 0; j < n_; ++j) mu_(j) = (v >> j) & 1u ? f(j) : -f(j);
      const double g = gauss(s, t);
      if (g > best) {
        best = g;
        best_mu_ = mu_;
        best_qdd_ = qdd_.data;
      }
    }
    return best;
  }

  // g(mu) for the mu given (the free solve and the Jacobian of the same state must be current).
  double gaussAt(const State& s, const Task& t, const Eigen::VectorXd& mu) {
    mu_ = mu;
    return gauss(s, t);
  }
  // After run() or gaussAt(): free motion and the command -J^T alfa nu of the last solve.
  const Eigen::VectorXd& commandTorques() const { return tau_cmd_; }
  const Eigen::VectorXd& qdd() const { return qdd_.data; }
  const Eigen::VectorXd& bestMu() const { return best_mu_; }
  const Eigen::VectorXd& bestQdd() const { return best_qdd_; }
  int lastError() const { return error_; }

 private:
  double gauss(const State& s, const Task& t) {
    tau_.data = s.tau - mu_;
    const int rc = task_.CartToJnt(s.q_kdl, s.qd_kdl, qdd_, t.alfa_kdl, t.beta_kdl, f_ext_, tau_, tau_out_);
    if (rc != 0) error_ = rc;
    if (m_ > 0) {
      task_.getContraintForceMagnitude(nu_);
      tau_cmd_.noalias() = -jta_ * nu_;
    } else {
      tau_cmd_.setZero();
    }
    const double z0 = 0.5 * (qdd_.data - qdd_free_.data).dot(tau_cmd_ - mu_);
    return z0 + mu_.dot(qdd_.data);
  }

  int n_, m_;
  KDL::ChainHdSolver_Vereshchagin free_, task_;
  KDL::ChainJntToJacSolver jac_solver_;
  KDL::Wrenches f_ext_;
  KDL::Jacobian alfa0_;
  KDL::JntArray beta0_, qdd_free_, qdd_, tau_, tau_out_;
  KDL::Jacobian jac_;
  Eigen::MatrixXd jta_;
  Eigen::VectorXd nu_, mu_, tau_cmd_, best_mu_, best_qdd_;
  int error_ = 0;
};

struct Row {
  std::string label;
  int m = 0;
  double friction = 0, plain = 0, kdl = 0, vertex = 0;
  double r_plain = 0, r_kdl = 0, r_vertex = 0;
  double mean_iter = 0;
  int max_iter = 0;
  double mean_stick = 0, mean_slip = 0;
  int vertex_differs = 0;
  double max_gap = 0, mean_rel_gap = 0;  // g* - g(best vertex)
  double max_plain_dqdd = 0;             // ours plain vs KDL
  double max_g_check = 0;                // |g_KDL(mu*) - gaussValue()| / max(1, |g*|)
  double max_cmd_check = 0;              // |-J^T alfa nu (KDL) - ours tau_cmd|
  int g_violations = 0;                  // best vertex g above the exact optimum
};

double relDiff(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace

int main(int argc, char** argv) {
  const auto wall0 = Clock::now();
  const std::string load_at_start = loadAverage();

  std::vector<ChainCase> cases;
  cases.push_back({"7 (Gen3)", std::make_unique<KDL::Chain>(makeGen3Chain()), 7});
  cases.push_back({"7 (random)", std::make_unique<KDL::Chain>(makeRandomChain(7, 0x5eed0000ULL + 7)), 7});

  const KDL::Twist root_acc(KDL::Vector(0.0, 0.0, kGravity), KDL::Vector::Zero());

  std::vector<Row> rows;
  int failures = 0;

  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const ChainCase& cc = cases[ci];
    const KDL::Chain& chain = *cc.chain;
    const int n = static_cast<int>(chain.getNrOfJoints());
    const int ns = static_cast<int>(chain.getNrOfSegments());
    const std::vector<State> states = makeStates(chain, 0xf71c0000ULL + 131 * ci);

    vereshchagin::FrictionSolver fric(chain, root_acc);
    vereshchagin::ChainHdSolver plain(chain, root_acc);
    if (fric.modelError() != 0 || plain.modelError() != 0) {
      std::cerr << "model error for chain " << cc.label << ": " << plain.errorMessage() << "\n";
      return 1;
    }
    const KDL::Wrenches f_ext_kdl(ns, KDL::Wrench::Zero());
    const Matrix6X f_ext = Matrix6X::Zero(6, ns);
    KDL::JntArray qdd_kdl(n), tau_out_kdl(n);

    for (size_t ti = 0; ti < std::size(kTaskSizes); ++ti) {
      const int m = kTaskSizes[ti];
      KDL::ChainHdSolver_Vereshchagin kdl_hd(chain, root_acc, static_cast<unsigned int>(m));
      VertexEnumeration vertices(chain, root_acc, m);
      const std::string label = "n " + cc.label + ", m " + std::to_string(m);

      // Checks (also a warm-up).
      Row row;
      row.label = cc.label;
      row.m = m;
      long iter_sum = 0, stick = 0, slip = 0;
      double rel_gap_sum = 0.0;
      for (const State& s : states) {
        const Task& t = s.tasks[ti];
        const int r1 = fric.solve(s.q, s.qd, t.alfa, t.beta, f_ext, s.tau, s.friction);
        const int r2 = plain.solve(s.q, s.qd, t.alfa, t.beta, f_ext, s.tau);
        const int r3 =
            kdl_hd.CartToJnt(s.q_kdl, s.qd_kdl, qdd_kdl, t.alfa_kdl, t.beta_kdl, f_ext_kdl, s.tau_kdl, tau_out_kdl);
        if (r1 != 0 || r2 != 0 || r3 != 0) {
          std::cerr << "solver error (" << label << "): friction " << r1 << " (" << fric.errorMessage() << "), plain "
                    << r2 << ", KDL " << r3 << "\n";
          ++failures;
          continue;
        }
        row.max_plain_dqdd = std::max(row.max_plain_dqdd, (plain.qdd() - qdd_kdl.data).cwiseAbs().maxCoeff());
        iter_sum += fric.iterations();
        row.max_iter = std::max(row.max_iter, fric.iterations());
        for (signed char st : fric.status()) {
          stick += st == vereshchagin::FrictionSolver::Stick;
          slip += st == vereshchagin::FrictionSolver::SlipPositive || st == vereshchagin::FrictionSolver::SlipNegative;
        }
        const Eigen::VectorXd qdd_exact = fric.qdd();
        const Eigen::VectorXd mu_exact = -fric.frictionTorques();
        const double g_exact = fric.gaussValue();

        const double g_vertex = vertices.run(s, t);
        const Eigen::VectorXd mu_vertex = vertices.bestMu(), qdd_vertex = vertices.bestQdd();
        if (relDiff(qdd_vertex, qdd_exact) > kDiffTol) ++row.vertex_differs;
        const double gap = g_exact - g_vertex, gscale = std::max(1.0, std::abs(g_exact));
        if (gap < -1e-9 * gscale) ++row.g_violations;
        row.max_gap = std::max(row.max_gap, gap);
        rel_gap_sum += std::max(gap, 0.0) / gscale;

        // The KDL-based Gauss function at the exact optimum equals the solver's optimum value.
        const double g_at_exact = vertices.gaussAt(s, t, mu_exact);
        row.max_g_check = std::max(row.max_g_check, std::abs(g_at_exact - g_exact) / gscale);
        // The command -J^T alfa nu from KDL against ours at the best vertex.
        vertices.gaussAt(s, t, mu_vertex);
        plain.solve(s.q, s.qd, t.alfa, t.beta, f_ext, s.tau - mu_vertex);
        row.max_cmd_check =
            std::max(row.max_cmd_check, (vertices.commandTorques() - plain.commandTorques()).cwiseAbs().maxCoeff());
        if (vertices.lastError() != 0) {
          std::cerr << "KDL error in the vertex enumeration (" << label << "): " << vertices.lastError() << "\n";
          ++failures;
        }
      }
      row.mean_iter = double(iter_sum) / states.size();
      row.mean_stick = double(stick) / states.size();
      row.mean_slip = double(slip) / states.size();
      row.mean_rel_gap = rel_gap_sum / states.size();
      if (row.g_violations) ++failures;

      std::vector<Bench> group;
      addBench(group, "friction", overStates(states, [&](const State& s) {
                 const Task& t = s.tasks[ti];
                 fric.solve(s.q, s.qd, t.alfa, t.beta, f_ext, s.tau, s.friction);
                 return fric.qdd()(n - 1);
               }));
      addBench(group, "plain", overStates(states, [&](const State& s) {
                 const Task& t = s.tasks[ti];
                 plain.solve(s.q, s.qd, t.alfa, t.beta, f_ext, s.tau);
                 return plain.qdd()(n - 1);
               }));
      addBench(group, "KDL", overStates(states, [&](const State& s) {
                 const Task& t = s.tasks[ti];
                 kdl_hd.CartToJnt(s.q_kdl, s.qd_kdl, qdd_kdl, t.alfa_kdl, t.beta_kdl, f_ext_kdl, s.tau_kdl,
                                  tau_out_kdl);
                 return qdd_kdl(n - 1);
               }));
      addBench(group, "vertex enumeration",
               overStates(states, [&](const State& s) { return vertices.run(s, s.tasks[ti]); }));
      std::cerr << "timing " << label << " ..." << std::endl;
      runGroup(group, label);
      row.friction = median(group[0].us);
      row.plain = median(group[1].us);
      row.kdl = median(group[2].us);
      row.vertex = median(group[3].us);
      row.r_plain = pairedRatio(group[0], group[1]);
      row.r_kdl = pairedRatio(group[0], group[2]);
      row.r_vertex = pairedRatio(group[3], group[0]);
      rows.push_back(row);
    }
  }
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();

  // ----------------------------------------------------------------------------------------------
  std::ostringstream md;
  md << "# Static friction (C++): vereshchagin::FrictionSolver, all joints at rest, n = 7\n\n";
  md << "- Date: " << utcNow() << "\n";
  md << "- Machine: " << cpuModel() << ", " << sysconf(_SC_NPROCESSORS_ONLN)
     << " online CPUs (nproc); load average (1, 5, 15 min) " << load_at_start << " at start, " << loadAverage()
     << " at end\n";
  md << "- Compiler: " << BENCH_CXX_COMPILER << "; build type " << BENCH_BUILD_TYPE << "; flags `" << BENCH_CXX_FLAGS
     << "`; KDL headers " << KDL_VERSION_STRING << "\n";
  md << "- Inputs: the Gen3 and the seeded random 7-joint chains of `bench_solver`; " << kStates
     << " seeded states per chain: q in [-pi, pi], q_dot = 0 (every joint at rest), gravity, f_ext = 0, static "
     << "friction f_j in [" << kFrictionLo << ", " << kFrictionHi << "] N m per joint, feed-forward torques = "
     << "(random factor in [0, 1]) x gravity torque + U(-2, 2) N m. Tasks on the last segment: m = 0; m = 1, a "
     << "random unit direction with beta = alfa^T root_acc (no tip acceleration along it); m = 6, alfa = I and "
     << "beta = root_acc (the tool held still, one redundant degree of freedom left).\n";
  md << "- Timed per call: `friction` = `vereshchagin::FrictionSolver::solve`; `plain` = "
     << "`vereshchagin::ChainHdSolver::solve` with the same inputs and no friction; `KDL` = "
     << "`KDL::ChainHdSolver_Vereshchagin::CartToJnt` (plain, one solver per m); `vertices` = the report's "
     << "vertex enumeration: one KDL nc = 0 solve (free motion), the tip Jacobian (m > 0), then for each of the "
     << "2^7 = 128 sign vectors mu = +-f one KDL `CartToJnt` with ff - mu and g(mu) = 1/2 (qdd - qdd_free)^T "
     << "(tau_cmd - mu) + mu^T qdd with tau_cmd = -J^T alfa nu (KDL's nu), keeping the best.\n";
  md << "- Method: steady_clock; warm-up, then " << kBatches << " interleaved batches (about " << kBatchSeconds * 1e3
     << " ms each; one pass over the states for `vertices`); median per-call time; ratio = median of per-batch "
     << "ratios. Total run time " << fmt("%.1f", wall) << " s. Noise: largest batch inter-quartile range / median "
     << fmt("%.1f", 100.0 * g_worst_spread) << " % (" << g_worst_spread_name << ").\n\n";

  md << "| chain | m | friction us | plain us | KDL us | vertices us | friction/plain (target <= "
     << fmt("%.1f", kTargetPlain) << ") | friction/KDL (target < " << fmt("%.0f", kTargetKdl)
     << ") | vertices/friction (target >= " << fmt("%.0f", kTargetVertex) << ") | active-set iterations mean (max) |\n";
  md << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows)
    md << "| " << r.label << " | " << r.m << " | " << fmt("%.2f", r.friction) << " | " << fmt("%.2f", r.plain) << " | "
       << fmt("%.2f", r.kdl) << " | " << fmt("%.1f", r.vertex) << " | " << fmt("%.2f", r.r_plain) << " | "
       << fmt("%.2f", r.r_kdl) << " | " << fmt("%.0f", r.r_vertex) << " | " << fmt("%.2f", r.mean_iter) << " ("
       << r.max_iter << ") |\n";

  auto verdict = [&](const char* what, auto ok_of, auto value_of, const char* f) {
    bool all = true;
    std::string detail;
    for (const Row& r : rows) {
      const bool ok = ok_of(r);
      all &= ok;
      if (!detail.empty()) detail += "; ";
      detail += r.label + " m " + std::to_string(r.m) + ": " + fmt(f, value_of(r)) + (ok ? "" : " (not met)");
    }
    md << "- **Target: " << what << ": " << (all ? "met" : "NOT met") << "** (" << detail << ")\n";
    return all;
  };
  md << "\n";
  const bool t1 = verdict(
      "friction-aware solve at most 2.5x our plain solve", [](const Row& r) { return r.r_plain <= kTargetPlain; },
      [](const Row& r) { return r.r_plain; }, "%.2f");
  const bool t2 = verdict(
      "friction-aware solve faster than one KDL plain solve", [](const Row& r) { return r.r_kdl < kTargetKdl; },
      [](const Row& r) { return r.r_kdl; }, "%.2f");
  const bool t3 = verdict(
      "friction-aware solve at least 100x faster than vertex enumeration",
      [](const Row& r) { return r.r_vertex >= kTargetVertex; }, [](const Row& r) { return r.r_vertex; }, "%.0f");

  md << "\n## Answers: exact optimum against the best vertex\n\n";
  md << "Per case, over the " << kStates << " states: joints sticking / slipping at the exact optimum (mean per "
     << "state); how often the best vertex's qdd differs from the exact qdd (max-norm difference > " << kDiffTol
     << " x max(1, |qdd*|)); the gap g* - g(best vertex) between the exact optimum (`gaussValue()`) and the best "
     << "vertex (largest, and mean relative to max(1, |g*|)). Checks: |g(mu*) - g*| with g evaluated by the KDL "
     << "recipe at the exact mu* (relative), the largest difference between -J^T alfa nu from KDL and our "
     << "`commandTorques()` (N m), and the largest difference between our plain qdd and KDL's (rad/s^2).\n\n";
  md << "| chain | m | stick / slip joints | vertex qdd differs | max g* - g_vertex | mean rel. gap | check g(mu*) | "
     << "check tau_cmd | check plain qdd |\n";
  md << "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows)
    md << "| " << r.label << " | " << r.m << " | " << fmt("%.2f", r.mean_stick) << " / " << fmt("%.2f", r.mean_slip)
       << " | " << r.vertex_differs << " / " << kStates << " | " << fmt("%.3g", r.max_gap) << " | "
       << fmt("%.2g", r.mean_rel_gap) << " | " << fmt("%.1e", r.max_g_check) << " | " << fmt("%.1e", r.max_cmd_check)
       << " | " << fmt("%.1e", r.max_plain_dqdd) << " |\n";
  md << "\nThe vertex answer is right only when the optimum is at a vertex (every resting joint slips, or the task "
     << "fixes its acceleration); whenever a joint sticks with the task leaving it free, the optimum is inside the "
     << "box and the best vertex moves a joint that friction holds (Vukcevic 2018, sec. 5.6).\n";
  const int violations = [&] {
    int v = 0;
    for (const Row& r : rows) v += r.g_violations;
    return v;
  }();
  if (violations)
    md << "\n**" << violations << " states have a vertex with g above the exact optimum: the exact solve is not "
       << "optimal there.**\n";
  if (failures) md << "\n**" << failures << " problems (solver errors or optimality violations; see stderr).**\n";
  md << "\n(targets: " << (t1 && t2 && t3 ? "all met" : "not all met") << "; sink " << fmt("%.6g", g_sink) << ")\n";

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
