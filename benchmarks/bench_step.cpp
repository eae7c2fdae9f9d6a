// The time step's cost (docs/time-step.md, "Simulator"): on the Kinova Gen3 with joint friction,
// one step() of data.hpp and one Simulator::step against the friction-aware solve at the instant of
// the same state and inputs (target: a step at most 1.5x that solve), joints at rest and moving,
// and with a support with friction under the wrist; then steps per second of Simulator::rollout
// (64 steps per call, a gravity-compensating controller). 64 seeded states near a pose; static
// friction |gravity torque| x U(0.3, 1.5) + 0.2 N m per joint (kinetic 0.8 of it) so that some
// joints stick and some slip, dt = 1 ms. Method: bench_common.hpp (interleaved batches, medians,
// paired ratios). Prints a markdown report (stdout, or the file given as argv[1]); `--dump file` writes
// step()'s results for comparing two builds, `--profile step|solve|simulator [reps]` loops one of them
// for perf or callgrind.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "bench_common.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/simulator.hpp"

using namespace vereshchagin;

namespace {

constexpr double kDt = 1e-3;

struct State {
  Eigen::VectorXd q, qd;
  FrictionModel friction;
};

Eigen::VectorXd gravityTorques(const Model& model, const Eigen::VectorXd& q) {
  DynamicsData dyn(model);
  Eigen::VectorXd g(7);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  (void)inverseDynamics(model, dyn, JointPositions(q), JointVelocities(zero), JointAccelerations(zero),
                        Matrix6X::Zero(6, model.nrOfSegments()), KDL::Vector(0, 0, -9.81), g);
  return g;
}

std::vector<State> states(const Model& model, bool moving, bench::Rng& rng) {
  const double pose[7] = {0.0, 0.6, 0.0, 2.1, 0.0, 0.45, 1.57};
  std::vector<State> out;
  for (int s = 0; s < bench::kStates; ++s) {
    State st{Eigen::VectorXd(7), Eigen::VectorXd::Zero(7), FrictionModel()};
    for (int j = 0; j < 7; ++j) st.q(j) = pose[j] + rng.uniform(-0.3, 0.3);
    if (moving)
      for (int j = 0; j < 7; ++j) st.qd(j) = rng.uniform(-0.5, 0.5);
    const Eigen::VectorXd g = gravityTorques(model, st.q);
    st.friction.static_friction.resize(7);
    for (int j = 0; j < 7; ++j) st.friction.static_friction(j) = std::abs(g(j)) * rng.uniform(0.3, 1.5) + 0.2;
    st.friction.kinetic_friction = 0.8 * st.friction.static_friction;
    out.push_back(st);
  }
  return out;
}

void addSupport(SolveInput& in) {
  PointContact p;
  p.segment = 5;
  p.point = Vector3(0.0, 0.0, -0.05);
  p.normal = Vector3::UnitZ();
  p.mu = 0.6;
  in.contacts.push_back(p);
}

enum Kind { kSolve, kStep, kSimulator };

// One bench body: a friction-aware solve at the instant, a step() or a Simulator::step of each state.
struct Runner {
  const Model& model;
  Kind kind;
  Data data{model};
  SolveInput in{model};
  Simulator sim{model, kDt};
  Eigen::VectorXd q_next = Eigen::VectorXd(7), qd_next = Eigen::VectorXd(7);

  double operator()(const State& s) {
    in.friction = &s.friction;
    if (kind == kSimulator) {
      (void)sim.setState(JointPositions(s.q), JointVelocities(s.qd));
      (void)sim.step(in);
      return sim.q()(0);
    }
    in.q = s.q;
    in.q_dot = s.qd;
    in.time_step = kind == kStep ? kDt : 0.0;
    if (kind == kSolve) {
      (void)solve(model, data, in);
      return data.qdd()(0);
    }
    (void)step(model, data, in, q_next, qd_next);
    return q_next(0);
  }
};

// `bench_step --dump file`: the results of step() on the bench's states (at rest, moving, moving
// slowly so that most joints stop within the step, with a support) and along 300-step runs from
// each moving state, every number with 17 digits, to compare two builds (a change of the step's
// method must agree to 1e-12 where the answer is unique).
int dump(const Model& model, const std::vector<State>& rest, const std::vector<State>& moving,
         const std::vector<State>& slow, const char* path) {
  std::ofstream out(path);
  Data data(model);
  Eigen::VectorXd q_next(7), qd_next(7);
  const auto write = [&](const char* tag, int s, int t) {
    out << tag << ' ' << s << ' ' << t << ' ' << data.iterations();
    const Eigen::VectorXd* rows[] = {&qd_next, &q_next, &data.frictionTorques(), &data.commandTorques()};
    for (const Eigen::VectorXd* v : rows)
      for (int j = 0; j < 7; ++j) out << ' ' << bench::fmt("%.17g", (*v)(j));
    out << '\n';
  };
  const char* tags[] = {"rest", "moving", "slow", "support"};
  const std::vector<State>* sets[] = {&rest, &moving, &slow, &rest};
  for (int c = 0; c < 4; ++c) {
    SolveInput in(model);
    if (c == 3) addSupport(in);
    in.time_step = kDt;
    for (std::size_t s = 0; s < sets[c]->size(); ++s) {
      const State& st = (*sets[c])[s];
      in.friction = &st.friction;
      in.q = st.q;
      in.q_dot = st.qd;
      for (int t = 0; t < (c == 1 || c == 2 ? 300 : 1); ++t) {
        const Status status = step(model, data, in, q_next, qd_next);
        if (!status) out << "error " << status.message() << '\n';
        write(tags[c], static_cast<int>(s), t);
        in.q = q_next;
        in.q_dot = qd_next;
      }
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Model model(bench::makeGen3Chain());
  bench::Rng rng(20261127);
  const std::vector<State> rest = states(model, false, rng), moving = states(model, true, rng);
  if (argc > 2 && std::string(argv[1]) == "--profile") {  // step() on the moving states, for perf
    const std::string what = argv[2];
    Runner r{model, what == "solve" ? kSolve : what == "simulator" ? kSimulator : kStep};
    const int reps = argc > 3 ? std::atoi(argv[3]) : 20000;
    for (int rep = 0; rep < reps; ++rep)
      for (const State& st : moving) bench::g_sink += r(st);
    return bench::g_sink == 0.123 ? 1 : 0;
  }
  if (argc > 2 && std::string(argv[1]) == "--dump") {
    std::vector<State> slow = states(model, true, rng);
    for (State& st : slow) st.qd *= 0.1;
    return dump(model, rest, moving, slow, argv[2]);
  }
  const char* kinds[] = {"friction-aware solve (instant)", "step() (data.hpp)", "Simulator::step"};
  const char* cases[] = {"at rest", "moving", "at rest + support (mu 0.6)"};
  std::vector<std::unique_ptr<Runner>> runners;
  std::vector<bench::Bench> group;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) {
      runners.push_back(std::unique_ptr<Runner>(new Runner{model, static_cast<Kind>(k)}));
      if (c == 2) addSupport(runners.back()->in);
      Runner& r = *runners.back();
      bench::addBench(group, std::string(cases[c]) + ", " + kinds[k],
                      bench::overStates(c == 1 ? moving : rest, [&r](const State& s) { return r(s); }));
    }
  // Rollouts: kStates steps per pass from a moving state, a controller compensating 90% of gravity.
  Simulator sim(model, kDt);
  SolveInput in(model);
  in.friction = &moving[0].friction;
  DynamicsData dyn(model);
  RolloutRecord rec;
  rec.resize(7, bench::kStates, true, true);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  const Matrix6X no_wrench = Matrix6X::Zero(6, model.nrOfSegments());
  const Controller controller = [&](const Eigen::VectorXd& q, const Eigen::VectorXd&, double, SolveInput& input) {
    (void)inverseDynamics(model, dyn, JointPositions(q), JointVelocities(zero), JointAccelerations(zero), no_wrench,
                          KDL::Vector(0, 0, -9.81), input.ff_torques);
    input.ff_torques *= 0.9;
  };
  bench::addBench(group, "Simulator::rollout (per step, with a controller)", [&](int reps) {
    for (int r = 0; r < reps; ++r) {
      (void)sim.setState(JointPositions(moving[0].q), JointVelocities(moving[0].qd));
      (void)sim.rollout(bench::kStates, controller, in, rec);
      bench::g_sink += rec.q(0, bench::kStates);
    }
  });
  bench::runGroup(group, "step");
  std::ostringstream md;
  md << "### Time step (C++, `bench_step`)\n\n"
     << "The Kinova Gen3 with joint friction (" << bench::kStates
     << " states near a pose, some joints sticking and some slipping), dt = 1 ms: a friction-aware solve at the "
        "instant against a step over dt of the same state and inputs. Target (issue 27): a step at most 1.5x the "
        "solve.\n\n";
  md << "| case | us per call | vs the solve | steps per second |\n|---|---:|---:|---:|\n";
  for (std::size_t i = 0; i < group.size(); ++i) {
    const double us = bench::median(group[i].us);
    const bool solve_row = i < 9 && i % 3 == 0;
    md << "| " << group[i].name << " | " << bench::fmt("%.2f", us) << " | "
       << (i < 9 && !solve_row ? bench::fmt("%.2f", bench::pairedRatio(group[i], group[i - i % 3])) + "x" : "") << " | "
       << (solve_row ? "" : bench::fmt("%.0f", 1e6 / us)) << " |\n";
  }
  if (argc > 1) {
    std::ofstream(argv[1]) << md.str();
  } else {
    std::cout << md.str();
  }
  std::fprintf(stderr, "sink %g\n", bench::g_sink);
  return 0;
}
