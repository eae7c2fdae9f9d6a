// C++ micro-benchmark: vereshchagin::TreeHdSolver on Baxter (example-robot-data: head, two 7-joint
// arms, two-finger grippers, 19 joints) against a dense KKT solve assembled from Pinocchio's C++
// pieces, with 6-D constraints on no hand (m = 0), the left hand (m = 6) or both hands (m = 12).
//
//   ours   solver.solve(q, qd, alfa, beta, segments, {}, tau): columns on the two gripper base
//          segments (base axes, moment about the segment's tip origin), gravity as a base
//          acceleration of +9.81 m/s^2 along z.
//   KKT    pinocchio::forwardKinematics(q, v, 0) and computeJointJacobians (placements, velocities,
//          velocity-product accelerations, joint Jacobians), crba (H, upper triangle mirrored),
//          nonLinearEffects (bias b with gravity), per hand the LOCAL_WORLD_ALIGNED Jacobian J_h and
//          drift a_h at the tip frame, A = [alfa_h^T J_h], gamma = beta - alfa^T (a + [0 0 9.81 0 0 0]);
//          then with Eigen: LDL^T of H, qdd_free = H^-1 (tau - b), Y = H^-1 A^T, the Schur complement
//          S = A Y (LL^T), lambda = S^-1 (gamma - A qdd_free), qdd = qdd_free + Y lambda.
//   ABA    pinocchio::aba (m = 0 only).
// Pinocchio's model is built here from the same KDL tree (our URDF loader), joint by joint (no
// Pinocchio library is linked: its URDF parser's urdfdom would clash with Debian's), so both sides
// solve the same robot; qdd of both is compared on every state before timing (relative 1e-9).
//
// Built only when the Pinocchio C++ headers are found (benchmarks/CMakeLists.txt); usage:
//   <build>/benchmarks/bench_tree_kkt <baxter.urdf> [output.md]
#include <pinocchio/multibody.hpp>
// The algorithm headers need the model and data definitions above.
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <Eigen/Cholesky>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "bench_common.hpp"
#include "pinocchio_bridge.hpp"
#include "vereshchagin/tree_hd_solver.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace {

using vereshchagin::TreeHdSolver;
using Matrix6X = TreeHdSolver::Matrix6X;
const char* const kHands[2] = {"left_gripper_base_link", "right_gripper_base_link"};

// The robot twice: our solver and Pinocchio's model of the same KDL tree (pinocchio_bridge.hpp,
// axis-aligned joint types where the axis is +x, +y or +z, as Pinocchio's URDF parser picks them).
struct Robot {
  explicit Robot(const vereshchagin::RobotTree& rt)
      : solver(rt.tree, KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero())),
        pin(solver.model(), KDL::Vector(0, 0, -9.81), /*aligned_axes=*/true) {
    for (const char* h : kHands) hands.push_back(solver.segmentIndex(h));
  }
  Eigen::VectorXd toPin(const Eigen::VectorXd& x) const { return pin.toPin(x); }
  TreeHdSolver solver;
  testutil::PinRobot pin;
  std::vector<int> hands;
};

struct State {
  Eigen::VectorXd q, qd, tau, pq, pv, ptau;  // ours, then in Pinocchio's joint order
  Matrix6X alfa;                             // 6 x 12: 6 columns per hand
  Eigen::VectorXd beta;
};

// The dense KKT pipeline on preallocated buffers.
struct Kkt {
  explicit Kkt(const Robot& r) : robot(r), data(r.pin.model), ldlt(r.pin.model.nv) {
    const int n = r.pin.model.nv;
    J.setZero(6, n);
    A.resize(12, n);
    Y.resize(n, 12);
    S.resize(12, 12);
    llt = Eigen::LLT<Eigen::MatrixXd>(12);
    gamma.resize(12);
    qdd.resize(n);
    zero = Eigen::VectorXd::Zero(n);
  }
  const Eigen::VectorXd& solve(const State& s, int hands) {
    const pinocchio::Model& model = robot.pin.model;
    const int m = 6 * hands;
    pinocchio::forwardKinematics(model, data, s.pq, s.pv, zero);
    pinocchio::computeJointJacobians(model, data);
    pinocchio::crba(model, data, s.pq);
    data.M.triangularView<Eigen::StrictlyLower>() = data.M.transpose();
    pinocchio::nonLinearEffects(model, data, s.pq, s.pv);
    Eigen::Matrix<double, 6, 1> up;
    up << 0, 0, 9.81, 0, 0, 0;
    for (int h = 0; h < hands; ++h) {
      const int seg = robot.hands[h];
      J.setZero();
      pinocchio::getFrameJacobian(model, data, robot.pin.joint_of[seg], robot.pin.tip[seg],
                                  pinocchio::LOCAL_WORLD_ALIGNED, J);
      const Eigen::Matrix<double, 6, 1> a0 =
          pinocchio::getFrameAcceleration(model, data, robot.pin.joint_of[seg], robot.pin.tip[seg],
                                          pinocchio::LOCAL_WORLD_ALIGNED)
              .toVector() +
          up;
      const auto alfa = s.alfa.middleCols<6>(6 * h);
      A.middleRows<6>(6 * h).noalias() = alfa.transpose() * J;
      gamma.segment<6>(6 * h) = s.beta.segment<6>(6 * h);
      gamma.segment<6>(6 * h).noalias() -= alfa.transpose() * a0;
    }
    ldlt.compute(data.M);
    qdd = s.ptau - data.nle;
    ldlt.solveInPlace(qdd);
    if (m == 0) return qdd;
    auto Yv = Y.leftCols(m);
    Yv = A.topRows(m).transpose();
    ldlt.solveInPlace(Yv);
    auto Sv = S.topLeftCorner(m, m);
    Sv.noalias() = A.topRows(m) * Yv;
    llt.compute(Sv);
    auto g = gamma.head(m);
    g.noalias() -= A.topRows(m) * qdd;
    llt.solveInPlace(g);
    qdd.noalias() += Yv * g;
    return qdd;
  }
  const Robot& robot;
  pinocchio::Data data;
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::Matrix<double, 6, Eigen::Dynamic> J;
  Eigen::MatrixXd A, Y, S;
  Eigen::VectorXd gamma, qdd, zero;
};

std::vector<State> makeStates(const Robot& r, std::uint64_t seed) {
  bench::Rng rng(seed);
  const int n = static_cast<int>(r.solver.nrOfJoints());
  std::vector<State> out(bench::kStates);
  for (State& s : out) {
    s.q.resize(n);
    s.qd.resize(n);
    s.tau.resize(n);
    for (int j = 0; j < n; ++j) {
      s.q(j) = rng.uniform(-1.5, 1.5);
      s.qd(j) = rng.uniform(-1, 1);
      s.tau(j) = rng.uniform(-2, 2);
    }
    s.pq = r.toPin(s.q);
    s.pv = r.toPin(s.qd);
    s.ptau = r.toPin(s.tau);
    s.alfa.resize(6, 12);
    for (int h = 0; h < 2; ++h) {  // orthonormal columns per hand
      Eigen::Matrix<double, 6, 6> g;
      for (int k = 0; k < 36; ++k) g.data()[k] = rng.uniform(-1, 1);
      s.alfa.middleCols<6>(6 * h) = Eigen::HouseholderQR<Eigen::Matrix<double, 6, 6>>(g).householderQ();
    }
    s.beta.resize(12);
    for (int c = 0; c < 12; ++c) s.beta(c) = rng.uniform(-1, 1);
  }
  return out;
}

struct Row {
  int m;
  double ours, kkt, aba, ratio, ratio_aba, err;
};

Row runCase(Robot& r, Kkt& kkt, const std::vector<State>& states, int hands) {
  const int m = 6 * hands;
  Eigen::VectorXi segs(m);
  for (int c = 0; c < m; ++c) segs(c) = r.hands[c / 6];
  const Matrix6X no_fext(6, 0);
  pinocchio::Data aba_data(r.pin.model);
  Row row{m, 0, 0, 0, 0, 0, 0};
  for (const State& s : states) {  // correctness first
    const int rc = r.solver.solve(s.q, s.qd, s.alfa.leftCols(m), s.beta.head(m), segs, no_fext, s.tau);
    if (rc != 0) throw std::runtime_error(std::string("solve failed: ") + r.solver.errorMessage());
    const Eigen::VectorXd ref = kkt.solve(s, hands);
    const Eigen::VectorXd ours = r.toPin(r.solver.qdd());
    row.err = std::max(row.err, (ours - ref).norm() / std::max(1.0, ref.norm()));
  }
  std::vector<bench::Bench> group;
  bench::addBench(group, "ours", bench::overStates(states, [&](const State& s) {
                    r.solver.solve(s.q, s.qd, s.alfa.leftCols(m), s.beta.head(m), segs, no_fext, s.tau);
                    return r.solver.qdd()(0);
                  }));
  bench::addBench(group, "kkt", bench::overStates(states, [&](const State& s) { return kkt.solve(s, hands)(0); }));
  if (m == 0)
    bench::addBench(group, "aba", bench::overStates(states, [&](const State& s) {
                      return pinocchio::aba(r.pin.model, aba_data, s.pq, s.pv, s.ptau)(0);
                    }));
  bench::runGroup(group, "Baxter m = " + std::to_string(m));
  row.ours = bench::median(group[0].us);
  row.kkt = bench::median(group[1].us);
  row.ratio = bench::pairedRatio(group[0], group[1]);
  if (m == 0) {
    row.aba = bench::median(group[2].us);
    row.ratio_aba = bench::pairedRatio(group[0], group[2]);
  }
  return row;
}

std::string report(const std::vector<Row>& rows, int n) {
  std::ostringstream out;
  out << "## Trees in C++: TreeHdSolver vs a dense KKT solve from Pinocchio's pieces (Baxter)\n\n"
      << "CPU " << bench::cpuModel() << ", " << BENCH_CXX_COMPILER << ", " << BENCH_BUILD_TYPE << " ("
      << BENCH_CXX_FLAGS << "), load average " << bench::loadAverage() << " at the end (shared machine). Baxter, " << n
      << " joints; " << bench::kStates << " seeded states; " << bench::kBatches
      << " interleaved batches, medians; ratio = median of the per-batch ratios.\n\n"
      << "`KKT` = Pinocchio C++ `forwardKinematics(q, v, 0)`, `computeJointJacobians`, `crba`, "
         "`nonLinearEffects`, the LOCAL_WORLD_ALIGNED Jacobian and drift of each constrained hand, then "
         "Eigen: LDL^T of H and the Schur complement A H^-1 A^T (LL^T). `max rel. diff` = largest relative "
         "difference of qdd over all states, checked before timing.\n\n"
      << "| m | constrained segments | ours us | KKT us | ours / KKT | ABA us | ours / ABA | max rel. diff |\n"
      << "|---:|---|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows) {
    const char* segs = r.m == 0 ? "-" : r.m == 6 ? "left_gripper_base_link" : "both gripper base links";
    out << "| " << r.m << " | " << segs << " | " << bench::fmt("%.2f", r.ours) << " | " << bench::fmt("%.2f", r.kkt)
        << " | " << bench::fmt("%.2f", r.ratio) << " | " << (r.m == 0 ? bench::fmt("%.2f", r.aba) : "-") << " | "
        << (r.m == 0 ? bench::fmt("%.2f", r.ratio_aba) : "-") << " | " << bench::fmt("%.1e", r.err) << " |\n";
  }
  out << "\nTarget: with constraints, ours / KKT <= 0.5:";
  bool met = true;
  for (const Row& r : rows) {
    if (r.m == 0) continue;
    out << " " << bench::fmt("%.2f", r.ratio) << " (m = " << r.m << ")";
    met = met && r.ratio <= 0.5;
  }
  out << (met ? ": met.\n" : ": not met.\n");
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: bench_tree_kkt <baxter.urdf> [output.md]\n";
    return 1;
  }
  const vereshchagin::UrdfTreeResult loaded = vereshchagin::treeFromUrdfFile(argv[1]);
  if (!loaded.ok) {
    std::cerr << "loading " << argv[1] << ": " << loaded.message << "\n";
    return 1;
  }
  Robot robot(loaded.robot);
  for (int h : robot.hands)
    if (h < 0) {
      std::cerr << argv[1] << " has no segments " << kHands[0] << " and " << kHands[1] << "\n";
      return 1;
    }
  Kkt kkt(robot);
  const std::vector<State> states = makeStates(robot, 0xBA7E5);
  std::vector<Row> rows;
  bool ok = true;
  for (int hands = 0; hands <= 2; ++hands) {
    std::cerr << "timing Baxter, m = " << 6 * hands << " ...\n";
    rows.push_back(runCase(robot, kkt, states, hands));
    ok = ok && rows.back().err <= 1e-9;
  }
  const std::string md = report(rows, static_cast<int>(robot.solver.nrOfJoints()));
  std::cout << md;
  if (argc > 2) std::ofstream(argv[2]) << md;
  std::cerr << "(sink " << bench::g_sink << ")\n";
  if (!ok) std::cerr << "qdd differs from the KKT solution by more than 1e-9\n";
  return ok ? 0 : 2;
}
