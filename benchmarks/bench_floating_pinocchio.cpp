// Floating bases against Pinocchio's C++ (header-only, from the `pin` wheel): Talos (reduced),
// solo12 and ANYmal loaded with a free-flyer base (vereshchagin::treeFromUrdfFile, base
// FreeFlyer; Pinocchio's model built from ours with a JointModelFreeFlyer root, pinocchio_bridge.hpp).
//  * free motion: vereshchagin::solve against pinocchio::aba (random q, q_dot, joint torques);
//  * foot contacts as segment constraints (docs/floating-base.md: bilateral contacts): 6-D feet on
//    Talos (2 soles), 3-D point feet on solo12 and ANYmal (4 feet), against
//    pinocchio::constraintDynamics (RigidConstraintModel CONTACT_6D / CONTACT_3D, LOCAL) and
//    pinocchio::pv / constrainedABA (FrameAnchorConstraintModel / PointAnchorConstraintModel).
//    q_dot = 0 there, so that the contact points' spatial and classical accelerations coincide
//    (ours constrains the spatial one, Pinocchio's 3-D contacts the classical one).
// Every answer is compared (relative 1e-9) before timing.
//
//   bench_floating_pinocchio <talos_reduced.urdf> <solo12.urdf> <anymal.urdf> [output.md]
//   bench_floating_pinocchio --profile <free|feet> <robot 0-2> <seconds> <the three URDFs>
// The second form only loops over our solve of one case (for `perf record`), no Pinocchio call.
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/constrained-dynamics.hpp>
#include <pinocchio/algorithm/proximal.hpp>
#include <pinocchio/algorithm/pv.hpp>
#include <pinocchio/constraints.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/spatial.hpp>

#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "bench_common.hpp"
#include "pinocchio_bridge.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace {

using RigidModel = pinocchio::RigidConstraintModel;
using RigidData = pinocchio::RigidConstraintData;
const KDL::Vector kGravity(0.0, 0.0, -bench::kGravity);

struct Robot {
  std::string label;
  std::vector<std::string> feet;  // link names
  bool six_d = false;             // 6-D feet (else 3-D points)
  bool joint_space = false;       // InertiaCheck::JointSpace (ANYmal's base link is no rigid body)
};

struct State {
  Eigen::VectorXd q, qd, tau, pq, pqd, ptau;  // ours, then Pinocchio's order
};

struct Row {
  std::string robot, case_name, solver;
  double us = 0, ratio = 0, err = 0;
  bool ours = false;
};

double relDiff(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

std::vector<State> makeStates(const vereshchagin::Model& model, const testutil::PinRobot& pin, bool moving,
                              std::uint64_t seed) {
  bench::Rng rng(seed);
  const int nq = static_cast<int>(model.nq()), nv = static_cast<int>(model.nv());
  std::vector<State> states(bench::kStates);
  for (State& s : states) {
    s.q.resize(nq);
    s.qd.resize(nv);
    s.tau.resize(nv);
    for (int i = 0; i < nq; ++i) s.q(i) = rng.uniform(-0.8, 0.8);
    s.q.segment<4>(3).normalize();
    for (int i = 0; i < nv; ++i) s.qd(i) = moving ? rng.uniform(-1.0, 1.0) : 0.0, s.tau(i) = rng.uniform(-5.0, 5.0);
    s.tau.head(6).setZero();  // no motor on the base
    s.pq = pin.toPinQ(s.q);
    s.pqd = pin.toPin(s.qd);
    s.ptau = pin.toPin(s.tau);
  }
  return states;
}

// The robot loaded by both libraries, with our solver's data.
struct Loaded {
  Loaded(const std::string& path, bool joint_space)
      : model(load(path, joint_space)), pin(model, kGravity, true), data(model), pdata(pin.model) {}
  static vereshchagin::Model load(const std::string& path, bool joint_space) {
    const auto check = joint_space ? vereshchagin::InertiaCheck::JointSpace : vereshchagin::InertiaCheck::Physical;
    vereshchagin::UrdfOptions uopt;
    uopt.base = vereshchagin::BaseKind::FreeFlyer;
    uopt.inertia_check = check;
    const vereshchagin::UrdfTreeResult loaded = vereshchagin::treeFromUrdfFile(path, "", uopt);
    if (!loaded.ok) throw std::runtime_error("loading " + path + ": " + loaded.message);
    vereshchagin::ModelOptions mopt;
    mopt.inertia_check = check;
    vereshchagin::Model model(loaded.robot, mopt);
    if (!model.status()) throw std::runtime_error(path + ": " + model.status().message());
    return model;
  }
  vereshchagin::Model model;
  testutil::PinRobot pin;
  vereshchagin::Data data;
  pinocchio::Data pdata;
};

// Free motion against aba: appends two rows; returns the largest relative difference.
double benchFree(Loaded& r, const std::string& label, std::vector<Row>& rows, std::uint64_t seed) {
  const std::vector<State> states = makeStates(r.model, r.pin, true, seed);
  vereshchagin::SolveInput in(r.model, 0, 0);
  in.gravity = kGravity;
  double err = 0.0;
  for (const State& s : states) {
    in.q = s.q, in.q_dot = s.qd, in.ff_torques = s.tau;
    const vereshchagin::Status st = vereshchagin::solve(r.model, r.data, in);
    if (!st) throw std::runtime_error(label + " free: " + st.message());
    const Eigen::VectorXd pin_qdd = pinocchio::aba(r.pin.model, r.pdata, s.pq, s.pqd, s.ptau);
    err = std::max(err, relDiff(r.pin.fromPin(pin_qdd), r.data.qdd()));
  }
  std::vector<bench::Bench> group;
  bench::addBench(group, "ours", bench::overStates(states, [&](const State& s) {
                    in.q = s.q, in.q_dot = s.qd, in.ff_torques = s.tau;
                    (void)vereshchagin::solve(r.model, r.data, in);
                    return r.data.qdd()(0);
                  }));
  bench::addBench(group, "aba", bench::overStates(states, [&](const State& s) {
                    return pinocchio::aba(r.pin.model, r.pdata, s.pq, s.pqd, s.ptau)(0);
                  }));
  std::cerr << "timing " << label << " free motion ...\n";
  bench::runGroup(group, label + " free");
  const std::string dof = label + " (" + std::to_string(r.model.nv()) + " DOF)";
  rows.push_back({dof, "free motion", "ours (solve)", bench::median(group[0].us), 1, 0, true});
  rows.push_back({"", "", "pinocchio::aba", bench::median(group[1].us), bench::pairedRatio(group[0], group[1]), err});
  return err;
}

// Pinocchio's side of the feet held: constraintDynamics with RigidConstraintModels, pv and
// constrainedABA with anchors of type Anchor (FrameAnchor for 6-D feet, PointAnchor for 3-D).
template <class Anchor>
struct PinFeet {
  using AnchorData = decltype(std::declval<Anchor>().createData());
  std::vector<RigidModel> rigid;
  std::vector<RigidData> rigid_data;
  std::vector<Anchor> anchors;
  std::vector<AnchorData> pv_anchor_data, caba_anchor_data;
  pinocchio::Data cd, pv, caba;
  pinocchio::ProximalSettings cd_settings{1e-12, 0.0, 1}, pv_settings{1e-12, 1e-10, 20};

  explicit PinFeet(const pinocchio::Model& m) : cd(m), pv(m), caba(m) {}
  void add(const pinocchio::Model& m, pinocchio::JointIndex j, const pinocchio::SE3& place, bool six_d) {
    rigid.emplace_back(six_d ? pinocchio::CONTACT_6D : pinocchio::CONTACT_3D, m, j, place, pinocchio::LOCAL);
    if constexpr (std::is_same<Anchor, pinocchio::FrameAnchorConstraintModel>::value)
      anchors.emplace_back(m, j, place);
    else
      anchors.emplace_back(m, j, place, 0, pinocchio::SE3::Identity());
  }
  void init(const pinocchio::Model& m) {
    for (const RigidModel& c : rigid) rigid_data.push_back(c.createData());
    for (const Anchor& c : anchors)
      pv_anchor_data.push_back(c.createData()), caba_anchor_data.push_back(c.createData());
    pinocchio::initConstraintDynamics(m, cd, rigid, rigid_data);
    pinocchio::initPvSolver(m, pv, anchors);
    pinocchio::initPvSolver(m, caba, anchors);
  }
  // k = 0: constraintDynamics, 1: pv, 2: constrainedABA.
  const Eigen::VectorXd& run(int k, const pinocchio::Model& m, const State& s) {
    if (k == 0) return pinocchio::constraintDynamics(m, cd, s.pq, s.pqd, s.ptau, rigid, rigid_data, cd_settings);
    if (k == 1) return pinocchio::pv(m, pv, s.pq, s.pqd, s.ptau, anchors, pv_anchor_data, pv_settings);
    return pinocchio::constrainedABA(m, caba, s.pq, s.pqd, s.ptau, anchors, caba_anchor_data, pv_settings);
  }
};

// Feet held against constraintDynamics, pv and constrainedABA: appends four rows; returns the
// largest relative difference from constraintDynamics and pv (constrainedABA regularises).
template <class Anchor>
double benchFeet(Loaded& r, const Robot& robot, std::vector<Row>& rows, std::uint64_t seed) {
  const std::vector<State> states = makeStates(r.model, r.pin, false, seed);
  vereshchagin::SolveInput held(r.model, 4, 0);
  held.gravity = kGravity;
  const int k = robot.six_d ? 6 : 3;
  Eigen::VectorXd beta = Eigen::VectorXd::Zero(k);
  beta(2) = bench::kGravity;  // the foot at rest: its acceleration is the world's, -gravity
  PinFeet<Anchor> feet(r.pin.model);
  for (const std::string& foot : robot.feet) {
    vereshchagin::FrameRef f;
    if (!r.model.findFrame(foot, f) || f.segment < 0) throw std::runtime_error(robot.label + ": no foot " + foot);
    if (!held.addConstraint(f, Eigen::MatrixXd::Identity(6, k), beta)) throw std::runtime_error("addConstraint");
    feet.add(r.pin.model, r.pin.joint_of[f.segment], r.pin.tip[f.segment] * testutil::toSE3(f.in_tip), robot.six_d);
  }
  feet.init(r.pin.model);
  double errs[3] = {0, 0, 0};
  for (const State& s : states) {
    held.q = s.q, held.q_dot = s.qd, held.ff_torques = s.tau;
    const vereshchagin::Status st = vereshchagin::solve(r.model, r.data, held);
    if (!st) throw std::runtime_error(robot.label + " feet: " + st.message());
    for (int c = 0; c < 3; ++c)
      errs[c] = std::max(errs[c], relDiff(r.pin.fromPin(feet.run(c, r.pin.model, s)), r.data.qdd()));
  }
  std::vector<bench::Bench> group;
  bench::addBench(group, "ours", bench::overStates(states, [&](const State& s) {
                    held.q = s.q, held.q_dot = s.qd, held.ff_torques = s.tau;
                    (void)vereshchagin::solve(r.model, r.data, held);
                    return r.data.qdd()(0);
                  }));
  const char* names[3] = {"pinocchio::constraintDynamics", "pinocchio::pv", "pinocchio::constrainedABA"};
  for (int c = 0; c < 3; ++c)
    bench::addBench(group, names[c],
                    bench::overStates(states, [&, c](const State& s) { return feet.run(c, r.pin.model, s)(0); }));
  std::cerr << "timing " << robot.label << " feet held ...\n";
  bench::runGroup(group, robot.label + " feet");
  const std::string label = std::to_string(robot.feet.size()) + " feet, " + std::to_string(k) +
                            "-D (m = " + std::to_string(robot.feet.size() * k) + ")";
  rows.push_back({"", label, "ours (solve)", bench::median(group[0].us), 1, 0, true});
  for (int c = 0; c < 3; ++c)
    rows.push_back(
        {"", "", names[c], bench::median(group[c + 1].us), bench::pairedRatio(group[0], group[c + 1]), errs[c]});
  return std::max(errs[0], errs[1]);
}

// One robot: free motion, then its feet held. False if an answer differs by more than 1e-9.
bool benchRobot(const Robot& robot, const std::string& path, std::vector<Row>& rows, std::uint64_t seed) {
  Loaded r(path, robot.joint_space);
  const double free_err = benchFree(r, robot.label, rows, seed);
  const double feet_err = robot.six_d ? benchFeet<pinocchio::FrameAnchorConstraintModel>(r, robot, rows, seed + 1)
                                      : benchFeet<pinocchio::PointAnchorConstraintModel>(r, robot, rows, seed + 1);
  return free_err <= 1e-9 && feet_err <= 1e-9;
}

// --profile: our solve of one robot's case in a loop for `seconds` (no timing, no comparison).
int profile(const Robot& robot, const std::string& path, bool feet, double seconds) {
  Loaded r(path, robot.joint_space);
  const std::vector<State> states = makeStates(r.model, r.pin, !feet, 0xF10A7);
  vereshchagin::SolveInput in(r.model, 4, 0);
  in.gravity = kGravity;
  const int k = robot.six_d ? 6 : 3;
  Eigen::VectorXd beta = Eigen::VectorXd::Zero(k);
  beta(2) = bench::kGravity;
  for (const std::string& foot : robot.feet) {
    vereshchagin::FrameRef f;
    if (!feet) break;
    if (!r.model.findFrame(foot, f) || !in.addConstraint(f, Eigen::MatrixXd::Identity(6, k), beta)) return 1;
  }
  const auto t0 = bench::Clock::now();
  long calls = 0;
  while (std::chrono::duration<double>(bench::Clock::now() - t0).count() < seconds) {
    for (const State& s : states) {
      in.q = s.q, in.q_dot = s.qd, in.ff_torques = s.tau;
      if (!vereshchagin::solve(r.model, r.data, in)) return 2;
      bench::g_sink += r.data.qdd()(0);
    }
    calls += static_cast<long>(states.size());
  }
  std::cerr << robot.label << (feet ? " feet" : " free") << ": " << calls << " solves, "
            << 1e6 * seconds / static_cast<double>(calls) << " us each (sink " << bench::g_sink << ")\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Robot robots[3] = {{"Talos (reduced)", {"left_sole_link", "right_sole_link"}, true},
                           {"solo12", {"FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"}, false},
                           {"ANYmal", {"LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"}, false, true}};
  if (argc == 8 && std::string(argv[1]) == "--profile") {
    const int robot = std::stoi(argv[3]);
    if (robot < 0 || robot > 2) return 1;
    return profile(robots[robot], argv[5 + robot], std::string(argv[2]) == "feet", std::stod(argv[4]));
  }
  if (argc < 4) {
    std::cerr << "usage: bench_floating_pinocchio <talos_reduced.urdf> <solo12.urdf> <anymal.urdf> [output.md]\n"
                 "       bench_floating_pinocchio --profile <free|feet> <robot 0-2> <seconds> <the three URDFs>\n";
    return 1;
  }
  std::vector<Row> rows;
  bool ok = true;
  for (int r = 0; r < 3; ++r) ok = benchRobot(robots[r], argv[r + 1], rows, 0xF10A7 + 10 * r) && ok;
  std::ostringstream md;
  md << "### C++ (bench_floating_pinocchio)\n\n"
     << "CPU " << bench::cpuModel() << ", " << BENCH_CXX_COMPILER << ", " << BENCH_BUILD_TYPE << " (" << BENCH_CXX_FLAGS
     << "), load average " << bench::loadAverage()
     << " at the end (shared machine). URDFs of example-robot-data loaded with a free-flyer base "
        "(`treeFromUrdfFile`, `BaseKind::FreeFlyer`; ANYmal with `InertiaCheck::JointSpace`, its base link's inertia "
        "is no rigid body's); Pinocchio's model is built from ours with a "
        "`JointModelFreeFlyer` root (axis-aligned joints, as its URDF parser picks them). Free motion: "
     << bench::kStates
     << " seeded states (q with a unit quaternion, q_dot, joint torques; zero on the base), ours "
        "`vereshchagin::solve` against `pinocchio::aba`. Feet held: the same with q_dot = 0; ours one segment "
        "constraint per foot (alfa = identity columns, world axes, beta = -gravity), Pinocchio's "
        "`constraintDynamics` (`RigidConstraintModel` CONTACT_6D / CONTACT_3D, LOCAL, `ProximalSettings(1e-12, 0, "
        "1)`) and `pv` / `constrainedABA` (`FrameAnchorConstraintModel` / `PointAnchorConstraintModel`, "
        "`ProximalSettings(1e-12, 1e-10, 20)`). "
     << bench::kBatches
     << " interleaved batches, medians; ratio = ours / that solver (median of per-batch ratios; target at most "
        "0.7). `max rel. diff` = largest |qdd - ours|_inf / max(1, |ours|_inf) over all states, checked before "
        "timing (constrainedABA regularises with mu, so it agrees only to about mu's effect).\n\n"
     << "| robot | case | solver | us per call | ours / it | max rel. diff of qdd |\n"
     << "|---|---|---|---:|---:|---:|\n";
  for (const Row& r : rows)
    md << "| " << r.robot << " | " << r.case_name << " | " << r.solver << " | " << bench::fmt("%.2f", r.us) << " | "
       << (r.ours ? std::string("-") : bench::fmt("%.2f", r.ratio)) << " | "
       << (r.ours ? std::string("-") : bench::fmt("%.1e", r.err)) << " |\n";
  std::cout << md.str();
  if (argc > 4) std::ofstream(argv[4]) << md.str();
  std::cerr << "(sink " << bench::g_sink << ")\n";
  if (!ok) std::cerr << "some answers differ from Pinocchio's by more than 1e-9\n";
  return ok ? 0 : 2;
}
