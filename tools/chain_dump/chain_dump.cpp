// Development tool (not a test): dumps the outputs of a few hundred random chain solves of every
// kind (m = 0..6 on the last segment, constraints on several segments, f_ext, ff_torques,
// pass-through, response columns, friction) as text with 17 significant digits, so that a
// refactoring of the solver can be checked bit for bit against the build before it:
//
//   g++ -O2 -std=c++17 -I cpp/include -I cpp/tests -I /usr/include/eigen3 \
//       tools/chain_dump/chain_dump.cpp <build>/libvereshchagin.a -lorocos-kdl -o chain_dump
//   ./chain_dump > before.txt   (old build)   ./chain_dump > after.txt   (new build)
//   python3 tools/chain_dump/compare.py before.txt after.txt
#include <cstdio>

#include "random_chain.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"

namespace {

void dump(const char* tag, const Eigen::Ref<const Eigen::MatrixXd>& m) {
  std::printf("%s %ld %ld", tag, (long)m.rows(), (long)m.cols());
  for (Eigen::Index c = 0; c < m.cols(); ++c)
    for (Eigen::Index r = 0; r < m.rows(); ++r) std::printf(" %.17g", m(r, c));
  std::printf("\n");
}

void dumpSolver(vereshchagin::ChainHdSolver& hd, int rc, int nj) {
  std::printf("rc %d rank %d\n", rc, hd.constraintRank());
  if (rc != 0) return;
  dump("qdd", hd.qdd());
  dump("nu", hd.nu());
  dump("tau", hd.commandTorques());
  dump("acc", hd.linkAccelerations());
  Eigen::VectorXi joints(nj);
  for (int j = 0; j < nj; ++j) joints(j) = j;
  Eigen::MatrixXd dqdd(nj, nj), dtau(nj, nj), dnu(std::max(1, hd.constraintCount()), nj);
  hd.responseColumns(joints, dqdd, dtau, dnu);
  dump("dqdd", dqdd);
  dump("dtau", dtau);
  dump("dnu", dnu.topRows(hd.constraintCount()));
  Eigen::VectorXi some(2);
  some << nj - 1, 0;
  Eigen::MatrixXd d2(nj, 2), t2(nj, 2);
  hd.responseColumns(some, d2, t2);
  dump("dqdd2", d2);
  std::printf("sigma %.17g\n", hd.smallestSingularValue());
}

}  // namespace

int main() {
  using vereshchagin::ChainHdSolver;
  for (int seed = 0; seed < 300; ++seed) {
    testutil::RandomGen g(1000 + seed);
    testutil::ChainSpec spec;
    spec.n_joints = g.integer(1, 12);
    if (g.coin(0.3)) spec.fixed_before = {g.integer(0, spec.n_joints)};
    const KDL::Chain chain = g.chain(spec);
    const int nj = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
    ChainHdSolver hd(chain, KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()));
    const Eigen::VectorXd q = g.q(nj).data, qd = g.coin() ? g.qdot(nj).data : Eigen::VectorXd::Zero(nj);
    const Eigen::VectorXd ff = g.coin() ? g.torques(nj).data : Eigen::VectorXd(0);
    const ChainHdSolver::Matrix6X fext = g.coin() ? testutil::toMatrix(g.fext(ns)) : ChainHdSolver::Matrix6X(6, 0);
    const int kind = seed % 4;
    const int m = seed % 7;
    ChainHdSolver::Matrix6X alfa = g.alfa(m).data;
    Eigen::VectorXd beta = g.beta(m).data;
    std::printf("case %d kind %d nj %d m %d\n", seed, kind, nj, m);
    if (kind == 0) {
      dumpSolver(hd, hd.solve(q, qd, alfa, beta, fext, ff), nj);
    } else if (kind == 1) {
      const int mm = 1 + seed % 9;
      alfa = g.alfa(mm).data;
      beta = g.beta(mm).data;
      Eigen::VectorXi segs(mm);
      for (int c = 0; c < mm; ++c) segs(c) = g.integer(0, ns - 1);
      dumpSolver(hd, hd.solve(q, qd, alfa, beta, segs, fext, ff), nj);
    } else if (kind == 2) {
      Eigen::VectorXd pf(m), pt(m);
      for (int c = 0; c < m; ++c) pf(c) = g.uniform(0, 1), pt(c) = g.uniform(0, 1);
      if (m > 0) hd.setPassThrough(pf, pt);
      dumpSolver(hd, hd.solve(q, qd, alfa, beta, fext, ff), nj);
    } else {
      vereshchagin::FrictionSolver fs(chain, KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()));
      vereshchagin::FrictionModel fm;
      fm.static_friction = Eigen::VectorXd::Constant(nj, g.uniform(0.1, 5.0));
      Eigen::VectorXd qd0 = qd;
      for (int j = 0; j < nj; ++j)
        if (g.coin(0.7)) qd0(j) = 0.0;
      const int rc = fs.solve(q, qd0, alfa, beta, fext, ff, fm);
      std::printf("rc %d it %d\n", rc, fs.iterations());
      if (rc == 0) {
        dump("qdd", fs.qdd());
        dump("tau", fs.commandTorques());
        dump("fric", fs.frictionTorques());
        dump("nu", fs.nu());
        dump("acc", fs.linkAccelerations());
        std::printf("gauss %.17g\n", fs.gaussValue());
      }
    }
  }
  return 0;
}
