// Pinocchio's own Popov-Vereshchagin solver (pinocchio::pv) and its constrained ABA
// (pinocchio::constrainedABA), C++ only in the `pin` wheel's headers, against
// vereshchagin::ChainHdSolver on the Kinova Gen3 of bench_common.hpp with its tip frame held
// (a 6D FrameAnchorConstraintModel to the world there; here alfa = identity in base axes with beta
// holding the tip still). q_dot = 0 in every state, so that Pinocchio's zero constraint
// acceleration (local frame) and ours (base axes, spatial) are the same condition.
//
//   bench_pv [output.md]
//
// Header-only use of Pinocchio (no Pinocchio library linked), as bench_tree_kkt.
#include <pinocchio/algorithm/proximal.hpp>
#include <pinocchio/algorithm/pv.hpp>
#include <pinocchio/constraints.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/spatial.hpp>

#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "bench_common.hpp"
#include "pinocchio_bridge.hpp"
#include "vereshchagin/chain_hd_solver.hpp"

namespace {

using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using Anchor = pinocchio::FrameAnchorConstraintModel;
using AnchorData = pinocchio::FrameAnchorConstraintData;

// The KDL chain as a Pinocchio model: each RotAxis joint of bench_common's Gen3 turns about the z
// axis of its segment's tip frame at q = 0 (frame `origin` in the parent's tip frame), and the
// link inertia is expressed in that frame; so a revolute-z joint placed at `origin` carries the
// body with the identity placement.
pinocchio::Model pinocchioModel(const KDL::Chain& chain) {
  pinocchio::Model model;
  pinocchio::JointIndex parent = 0;
  for (const KDL::Segment& seg : chain.segments) {
    parent = model.addJoint(parent, pinocchio::JointModelRZ(), testutil::toSE3(seg.getFrameToTip()), seg.getName());
    model.appendBodyToJoint(parent, testutil::toInertia(seg.getInertia()), pinocchio::SE3::Identity());
  }
  model.gravity.linear(Eigen::Vector3d(0.0, 0.0, -9.81));
  return model;
}

struct State {
  Eigen::VectorXd q, tau;
};

struct Row {
  std::string name;
  double us = 0, ratio = 0, err = 0;
};

}  // namespace

int main(int argc, char** argv) {
  const KDL::Chain chain = bench::makeGen3Chain();
  const int n = static_cast<int>(chain.getNrOfJoints());
  vereshchagin::ChainHdSolver ours(chain, KDL::Twist(KDL::Vector(0.0, 0.0, 9.81), KDL::Vector::Zero()));
  const Matrix6X alfa = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::VectorXd beta = Eigen::VectorXd::Zero(6);
  beta(2) = 9.81;  // the tip's acceleration includes the base's +9.81 up: held still
  const Matrix6X no_fext(6, 0);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);

  const pinocchio::Model model = pinocchioModel(chain);
  pinocchio::Data pv_data(model), caba_data(model);
  std::vector<Anchor> anchors;
  anchors.push_back(Anchor(model, model.njoints - 1, pinocchio::SE3::Identity()));
  std::vector<AnchorData> anchor_data;
  anchor_data.push_back(anchors[0].createData());
  pinocchio::ProximalSettings settings(1e-12, 1e-10, 20);  // accuracy, mu, max iterations
  pinocchio::initPvSolver(model, pv_data, anchors);
  pinocchio::initPvSolver(model, caba_data, anchors);

  bench::Rng rng(0x5EED5);
  std::vector<State> states(bench::kStates);
  for (State& s : states) {
    s.q.resize(n);
    s.tau.resize(n);
    for (int j = 0; j < n; ++j) s.q(j) = rng.uniform(-1.5, 1.5), s.tau(j) = rng.uniform(-2.0, 2.0);
  }
  Row rows[3] = {{"ours (ChainHdSolver::solve)"}, {"pinocchio::pv"}, {"pinocchio::constrainedABA"}};
  for (const State& s : states) {  // correctness first
    if (ours.solve(s.q, zero, alfa, beta, no_fext, s.tau) != 0)
      throw std::runtime_error(std::string("solve failed: ") + ours.errorMessage());
    const Eigen::VectorXd& qdd = ours.qdd();
    const double scale = std::max(1.0, qdd.norm());
    const Eigen::VectorXd pv = pinocchio::pv(model, pv_data, s.q, zero, s.tau, anchors, anchor_data, settings);
    rows[1].err = std::max(rows[1].err, (pv - qdd).norm() / scale);
    const Eigen::VectorXd caba =
        pinocchio::constrainedABA(model, caba_data, s.q, zero, s.tau, anchors, anchor_data, settings);
    rows[2].err = std::max(rows[2].err, (caba - qdd).norm() / scale);
  }
  std::vector<bench::Bench> group;
  bench::addBench(group, rows[0].name, bench::overStates(states, [&](const State& s) {
                    ours.solve(s.q, zero, alfa, beta, no_fext, s.tau);
                    return ours.qdd()(0);
                  }));
  bench::addBench(group, rows[1].name, bench::overStates(states, [&](const State& s) {
                    return pinocchio::pv(model, pv_data, s.q, zero, s.tau, anchors, anchor_data, settings)(0);
                  }));
  bench::addBench(group, rows[2].name, bench::overStates(states, [&](const State& s) {
                    return pinocchio::constrainedABA(model, caba_data, s.q, zero, s.tau, anchors, anchor_data,
                                                     settings)(0);
                  }));
  std::cerr << "timing Gen3, tip held (m = 6) ...\n";
  bench::runGroup(group, "Gen3 pv");
  for (int k = 0; k < 3; ++k) {
    rows[k].us = bench::median(group[k].us);
    rows[k].ratio = bench::pairedRatio(group[0], group[k]);
  }
  std::ostringstream md;
  md << "## Pinocchio's Popov-Vereshchagin solver in C++ (pv, constrainedABA; Gen3, tip held)\n\n"
     << "CPU " << bench::cpuModel() << ", " << BENCH_CXX_COMPILER << ", " << BENCH_BUILD_TYPE << " (" << BENCH_CXX_FLAGS
     << "), load average " << bench::loadAverage()
     << " at the end (shared machine). Kinova Gen3 (7 joints, bench_common's data) with its tip frame held "
        "still: Pinocchio's `FrameAnchorConstraintModel` to the world, `ProximalSettings(1e-12, 1e-10, 20)` "
        "(accuracy, mu, iterations); ours `alfa` = identity (base axes), `beta` holding the tip still. "
     << bench::kStates << " seeded states (q, tau; q_dot = 0), " << bench::kBatches
     << " interleaved batches, medians; ratio = ours / that solver (median of per-batch ratios). "
        "`max rel. diff` = largest |qdd - ours| / max(1, |ours|) over all states, checked before timing "
        "(constrainedABA regularises with mu, so it agrees only to about mu's effect).\n\n"
     << "| solver | us per call | ours / it | max rel. diff of qdd |\n|---|---:|---:|---:|\n";
  for (const Row& r : rows)
    md << "| " << r.name << " | " << bench::fmt("%.2f", r.us) << " | " << bench::fmt("%.2f", r.ratio) << " | "
       << (&r == &rows[0] ? std::string("-") : bench::fmt("%.1e", r.err)) << " |\n";
  std::cout << md.str();
  if (argc > 1) std::ofstream(argv[1]) << md.str();
  std::cerr << "(sink " << bench::g_sink << ")\n";
  const bool ok = rows[1].err <= 1e-9;
  if (!ok) std::cerr << "pinocchio::pv's qdd differs from ours by more than 1e-9\n";
  return ok ? 0 : 2;
}
