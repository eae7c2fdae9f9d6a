// The friction stage's iteration counts over long randomized runs, for its real-time bound
// (FrictionModel::max_iterations; docs/friction.md, "Real-time bound"; issue 27). Every solve runs
// with the exhaustive bound (max_iterations = 0), so the counts are what the method needs, and is
// compared with the default bound 6 k + 16 (k the joints whose friction is unknown).
//
//  * instant: solve(model, data, input) with every joint at rest under loads near breakaway (the
//    hard case: friction f_j = U(0.7, 1.3) |tau_j|, tau = the gravity torque plus U(-1, 1) N m of
//    feed-forward, so about half the joints slip) on the Kinova Gen3, on seeded random 7-12 joint
//    chains (bench_common.hpp) and on random trees (two random chains of 4-6 joints on one base
//    link, 8-12 joints);
//  * step: step(model, data, input, ...) at dt = 1 ms, runs from rest of the Gen3 and of random
//    chains whose friction is U(0.8, 1.3) times the gravity torque at the start (some joints held,
//    the others sliding slowly or falling; every joint with friction is an unknown of the step's
//    box QP), and long runs (10^5 steps) of arms held by friction U(1.02, 1.5) times it.
// Reported: the iteration histogram's maximum, 99.99 % quantile and mean, how often the default
// bound would have been hit (expected: never), and the time of one solve of the worst case found
// (median of repeated solves) next to that of a median case.
//
// Usage: bench_realtime [instant solves] [step runs] [steps per run] [output.md]
//        (defaults 1000000 200 5000; Markdown to stdout, and to the file if given). Exit code 1 if
//        a solve failed or needed more than the default bound.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <kdl/tree.hpp>

#include "bench_common.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/model.hpp"

namespace {

using bench::Rng;
using vereshchagin::Data;
using vereshchagin::FrictionModel;
using vereshchagin::Model;
using vereshchagin::SolveInput;

long defaultBound(long k) {
  return 6 * k + 16;
}

// Iteration histogram and the worst case seen (its inputs, to time it afterwards).
struct Tally {
  std::map<int, long> hist;
  std::map<int, int> max_by_k;  // the largest count per k
  long solves = 0, over_default = 0, failures = 0;
  double sum = 0.0;
  int worst = 0, median_k = 0;
  void add(int it, int k, bool ok) {
    ++hist[it];
    ++solves;
    sum += it;
    if (!ok) ++failures;
    if (it > defaultBound(k)) ++over_default;
    max_by_k[k] = std::max(max_by_k[k], it);
  }
  int quantile(double p) const {
    const long target = static_cast<long>(std::ceil(p * static_cast<double>(solves)));
    long seen = 0;
    for (const auto& [it, count] : hist)
      if ((seen += count) >= target) return it;
    return worst;
  }
};

// The models: the Gen3, random chains of 7-12 joints, random two-branch trees of 8-12 joints.
Model randomTree(Rng& rng, std::uint64_t seed) {
  const int a = 4 + rng.index(3), b = 4 + rng.index(3);
  const KDL::Chain left = bench::makeRandomChain(a, seed), right = bench::makeRandomChain(b, seed + 1);
  KDL::Tree tree("root");
  tree.addSegment(KDL::Segment("base", KDL::Joint("fixed", KDL::Joint::Fixed), KDL::Frame(KDL::Vector(0, 0, 0.1)),
                               KDL::RigidBodyInertia(2.0, KDL::Vector(0, 0, 0.05),
                                                     KDL::RotationalInertia(0.01, 0.01, 0.01, 0, 0, 0))),
                  "root");
  KDL::Chain l2, r2;  // distinct segment names per branch
  for (unsigned int i = 0; i < left.getNrOfSegments(); ++i) {
    const KDL::Segment& s = left.getSegment(i);
    l2.addSegment(KDL::Segment("l" + std::to_string(i), s.getJoint(), s.getFrameToTip(), s.getInertia()));
  }
  for (unsigned int i = 0; i < right.getNrOfSegments(); ++i) {
    const KDL::Segment& s = right.getSegment(i);
    r2.addSegment(KDL::Segment("r" + std::to_string(i), s.getJoint(), s.getFrameToTip(), s.getInertia()));
  }
  tree.addChain(l2, "base");
  tree.addChain(r2, "base");
  return Model(tree);
}

// One random resting state near breakaway into `in` / `fm` (instant case).
void restingNearBreakaway(const Model& model, Rng& rng, SolveInput& in, FrictionModel& fm,
                          vereshchagin::DynamicsData& dyn, Eigen::VectorXd& grav) {
  const long n = model.nrOfJoints();
  for (long j = 0; j < n; ++j) in.q(j) = rng.uniform(-bench::kPi, bench::kPi);
  in.q_dot.setZero();
  (void)vereshchagin::gravityTorques(model, dyn, vereshchagin::JointPositions(in.q), in.gravity, grav);
  for (long j = 0; j < n; ++j) {
    in.ff_torques(j) = rng.uniform(-1.0, 1.0);
    fm.static_friction(j) = rng.uniform(0.7, 1.3) * std::abs(grav(j) - in.ff_torques(j)) + 1e-3;
  }
  fm.kinetic_friction = fm.static_friction;
}

double secondsPerSolve(const Model& model, Data& data, const SolveInput& in, int reps) {
  std::vector<double> t;
  for (int r = 0; r < 15; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < reps; ++i) bench::g_sink += static_cast<double>(solve(model, data, in).value());
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / reps);
  }
  return bench::median(t);
}

struct Worst {
  int it = -1;
  std::optional<SolveInput> in;  // (no default constructor)
  FrictionModel fm;
  const Model* model = nullptr;
};

// The instant: `count` solves spread over the models.
void instant(const std::vector<Model>& models, const std::string& label, long count, Tally& tally, Worst& worst) {
  Rng rng(2700 + count % 97 + models.size());
  std::vector<std::unique_ptr<Data>> datas;
  std::vector<std::unique_ptr<SolveInput>> inputs;
  std::vector<FrictionModel> fms(models.size());
  for (const Model& m : models) {
    datas.push_back(std::make_unique<Data>(m));
    inputs.push_back(std::make_unique<SolveInput>(m));
  }
  for (std::size_t i = 0; i < models.size(); ++i) {
    fms[i].static_friction = Eigen::VectorXd::Zero(models[i].nrOfJoints());
    fms[i].max_iterations = 0;
    inputs[i]->friction = &fms[i];
  }
  vereshchagin::DynamicsData dyn0(models[0]);
  for (long s = 0; s < count; ++s) {
    const std::size_t i = static_cast<std::size_t>(s) % models.size();
    const Model& model = models[i];
    vereshchagin::DynamicsData dyn(model);
    Eigen::VectorXd grav(model.nrOfJoints());
    restingNearBreakaway(model, rng, *inputs[i], fms[i], dyn, grav);
    const vereshchagin::Status st = solve(model, *datas[i], *inputs[i]);
    const int it = datas[i]->iterations();
    tally.add(it, static_cast<int>(model.nrOfJoints()), st.code() == vereshchagin::Error::None);
    if (it > worst.it) {
      worst.it = it;
      worst.in = *inputs[i];
      worst.fm = fms[i];
      worst.model = &model;
    }
  }
  (void)label;
}

// Long step runs from rest: `runs` runs of `steps` steps over the models.
void stepRuns(const std::vector<Model>& models, long runs, long steps, double lo, double hi, Tally& tally,
              Worst& worst) {
  Rng rng(4242 + runs);
  for (long r = 0; r < runs; ++r) {
    const Model& model = models[static_cast<std::size_t>(r) % models.size()];
    const long n = model.nrOfJoints();
    Data data(model);
    SolveInput in(model);
    FrictionModel fm;
    vereshchagin::DynamicsData dyn(model);
    Eigen::VectorXd grav(n), q_next(n), qd_next(n);
    for (long j = 0; j < n; ++j) in.q(j) = rng.uniform(-bench::kPi, bench::kPi);
    in.q_dot.setZero();
    (void)vereshchagin::gravityTorques(model, dyn, vereshchagin::JointPositions(in.q), in.gravity, grav);
    fm.static_friction.resize(n);
    for (long j = 0; j < n; ++j) fm.static_friction(j) = rng.uniform(lo, hi) * std::abs(grav(j)) + 1e-3;
    fm.kinetic_friction = 0.8 * fm.static_friction;
    fm.max_iterations = 0;
    in.friction = &fm;
    in.time_step = 1e-3;
    for (long s = 0; s < steps; ++s) {
      const vereshchagin::Status st = step(model, data, in, q_next, qd_next);
      const int it = data.iterations();
      tally.add(it, static_cast<int>(n), st.code() == vereshchagin::Error::None);
      if (it > worst.it) {
        worst.it = it;
        worst.in = in;
        worst.fm = fm;
        worst.model = &model;
      }
      if (!st) break;
      in.q = q_next;
      in.q_dot = qd_next;
    }
  }
}

std::string row(const std::string& what, const Tally& t, const Worst& w) {
  std::ostringstream o;
  double t_worst = NAN, t_default = NAN, t_bound = NAN;
  if (w.model) {
    Data data(*w.model);
    SolveInput in = *w.in;
    FrictionModel fm = w.fm;
    in.friction = &fm;
    t_worst = secondsPerSolve(*w.model, data, in, 2000);
    fm.max_iterations = -1;
    t_default = secondsPerSolve(*w.model, data, in, 2000);
    // The time at the default bound B, extrapolated: one iteration (the bound forced to 1, the
    // fallback included) plus B - 1 times the worst case's cost per further iteration.
    fm.max_iterations = 1;
    const double t_one = secondsPerSolve(*w.model, data, in, 2000);
    const long b = defaultBound(w.model->nrOfJoints());
    if (w.it >= 3)  // (fewer: no cost per iteration to extrapolate from)
      t_bound = t_one + static_cast<double>(b - 1) * std::max(0.0, t_worst - t_one) / (w.it - 1);
  }
  o << "| " << what << " | " << t.solves << " | " << t.worst << " | " << t.quantile(0.9999) << " | "
    << bench::fmt("%.2f", t.sum / std::max(1L, t.solves)) << " | " << t.over_default << " | " << t.failures << " | "
    << bench::fmt("%.2f", t_worst * 1e6) << " | " << bench::fmt("%.2f", t_default * 1e6) << " | "
    << (std::isnan(t_bound) ? std::string("-") : bench::fmt("%.1f", t_bound * 1e6)) << " | ";
  for (const auto& [k, m] : t.max_by_k) o << (k == t.max_by_k.begin()->first ? "" : ", ") << k << ": " << m;
  o << " |\n";
  return o.str();
}

}  // namespace

int main(int argc, char** argv) {
  const long solves = argc > 1 ? std::atol(argv[1]) : 1000000;
  const long runs = argc > 2 ? std::atol(argv[2]) : 200;
  const long steps = argc > 3 ? std::atol(argv[3]) : 5000;
  std::vector<Model> gen3, chains, trees;
  gen3.emplace_back(bench::makeGen3Chain());
  Rng pick(27);
  for (int i = 0; i < 24; ++i) chains.emplace_back(bench::makeRandomChain(7 + i % 6, 100 + i));
  for (int i = 0; i < 12; ++i) trees.push_back(randomTree(pick, 500 + 2 * i));
  std::ostringstream md;
  md << "## Real-time bound\n\n"
     << "`benchmarks/bench_realtime.cpp` (" << bench::utcNow() << ", " << bench::cpuModel() << ", load "
     << bench::loadAverage() << "; " << BENCH_BUILD_TYPE << ", " << BENCH_CXX_FLAGS << "): active-set "
     << "iterations of the friction stage's box QP per solve, every solve with the exhaustive bound "
     << "(`max_iterations = 0`), against the default real-time bound 6 k + 16 (k the joints whose friction "
     << "is unknown: 7-12 here, so a bound of 58-88). Instant: every joint at rest, friction U(0.7, 1.3) "
     << "times the load on each joint. Step: runs of " << steps << " steps of 1 ms from rest, friction U(0.8, "
     << "1.3) times the start's gravity torques; held: 10^5 steps, U(1.02, 1.5). Times: one solve (or step's solve) of "
        "the worst case found, "
     << "median of 15 batches of 2000, with the exhaustive and with the default bound (identical work when "
     << "the bound is not hit), and extrapolated to a solve that spends the whole default bound B: "
     << "the worst case's time with the bound forced to 1 plus B - 1 times its cost per further "
     << "iteration.\n\n"
     << "| case | solves | max | 99.99 % | mean | over the default bound | failed | worst case, us | "
        "same, default bound, us | at the default bound (extrapolated), us | max by k |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n";
  struct Job {
    const char* what;
    std::vector<Model>* models;
    long count, steps;
    double lo, hi;
  };
  const Job jobs[] = {{"instant, Gen3 (k = 7)", &gen3, solves / 2, 0, 0, 0},
                      {"instant, random chains (k = 7-12)", &chains, solves / 4, 0, 0, 0},
                      {"instant, random trees (k = 8-12)", &trees, solves / 4, 0, 0, 0}};
  long bad = 0;  // failed solves and solves over the default bound: exit code 1
  for (const Job& job : jobs) {
    Tally t;
    Worst w;
    instant(*job.models, job.what, job.count, t, w);
    t.worst = w.it;
    bad += t.failures + t.over_default;
    md << row(job.what, t, w);
    std::cerr << job.what << " done\n";
  }
  const Job step_jobs[] = {{"step, Gen3 (k = 7)", &gen3, runs / 2, steps, 0.8, 1.3},
                           {"step, random chains (k = 7-12)", &chains, runs / 2, steps, 0.8, 1.3},
                           {"step, Gen3 held, 10 runs of 10^5 steps", &gen3, 10, 100000, 1.02, 1.5},
                           {"step, random chains held, 12 runs of 10^5 steps", &chains, 12, 100000, 1.02, 1.5}};
  for (const Job& job : step_jobs) {
    Tally t;
    Worst w;
    stepRuns(*job.models, job.count, job.steps, job.lo, job.hi, t, w);
    t.worst = w.it;
    bad += t.failures + t.over_default;
    md << row(job.what, t, w);
    std::cerr << job.what << " done\n";
  }
  std::cerr << "(sink " << bench::g_sink << ")\n";
  std::cout << md.str();
  if (argc > 4) std::ofstream(argv[4]) << md.str();
  return bad == 0 ? 0 : 1;
}
