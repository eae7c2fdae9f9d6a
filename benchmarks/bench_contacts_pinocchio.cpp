// Point contacts on the Gen3 in C++: our exact contact solve (vereshchagin::solve with
// SolveInput::contacts) against Pinocchio 4's constraint solvers on the same problem, the ADMM and
// the PGS at tolerance 1e-10 (header-only use of the `pin` wheel's C++, as bench_pv).
//
// The problem is bench_contacts.cpp's: bench_common's Gen3, a 3-D task holding the tool's origin
// still, point contacts (normal +z) under segments 2 to 5, q near a pose with the forearm over a
// table, q_dot = 0, no torque. Pinocchio's model has one revolute-z joint per segment at its tip
// frame (bench_pv's construction), so segment k is joint k + 1 and our tip frames are its joint
// frames. Each contact is a PointContactConstraintModel between the link (joint k + 1, the point)
// and the world; the task is a PointAnchorConstraintModel on joint 7's origin.
//
// The mapping: at q_dot = 0 and time step 1 our acceleration-level problem is Pinocchio's
// velocity-level one. Delassus G = J M^-1 J^T (ConstraintCholeskyDecomposition after crba), drift
// g = J qdd_free (qdd_free = aba(q, 0, 0)), the impulses lambda are forces, sigma = G lambda + g
// the constraint points' accelerations, and qdd = aba(q, 0, J^T lambda). Pinocchio's point contact
// measures the world's motion against the link's (its rows are -R^T times the point's Jacobian), so
// each contact frame is placed with z along world -z (R = diag(1, -1, -1)): lambda_n >= 0 is the
// table pushing up, the cone is Coulomb's circular one with our mu, and the force on the link in
// base axes is -R lambda.
//
// Compared where the cone's shape cannot matter: frictionless supports (a convex problem: qdd
// unique) and states where every point of ours sticks with its force strictly inside the circular
// cone (our polygon is inscribed in it, so our answer solves Pinocchio's problem too). qdd is
// unique there; the forces are not (4 contacts and a 3-D task on 7 joints: ours is the least-motor-
// effort split), so they are compared on one sticking contact (segment 3, mu = 1) as well.
//
//   bench_contacts_pinocchio [output.md]
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/constraint-cholesky.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/solvers/admm-solver.hpp>
#include <pinocchio/algorithm/solvers/pgs-solver.hpp>
#include <pinocchio/constraints.hpp>
#include <pinocchio/multibody.hpp>

#include <fstream>
#include <iostream>
#include <sstream>

#include "bench_common.hpp"
#include "pinocchio_bridge.hpp"
#include "vereshchagin/data.hpp"

using namespace vereshchagin;

namespace {

constexpr double kTol = 1e-10;
const int kSegments[4] = {2, 3, 4, 5};

Vector3 contactPoint(int k) {
  const double z[4] = {-0.05, -0.15, -0.02, -0.08};
  return Vector3(0.03 * (k % 2 ? 1 : -1), 0.02 * (k < 2 ? 1 : -1), z[k]);
}

Eigen::Matrix3d flip() {
  return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
}

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

// One comparison problem: which contacts, their friction, and whether states must stick.
struct Problem {
  const char* name;
  std::vector<int> contacts;
  double mu;
};

void ourInput(SolveInput& in, const Model& model, const Problem& pb) {
  ConstraintBlock b;
  b.segment = static_cast<int>(model.nrOfSegments()) - 1;
  b.columns = 3;
  for (int c = 0; c < 3; ++c) b.alfa(c, c) = 1.0;
  b.beta.head(3) << 0.0, 0.0, 9.81;  // the tool's origin held (gravity as the base's acceleration)
  in.constraints.push_back(b);
  for (int k : pb.contacts) {
    PointContact p;
    p.segment = kSegments[k];
    p.point = contactPoint(k);
    p.normal = Vector3::UnitZ();
    p.mu = pb.mu;
    in.contacts.push_back(p);
  }
}

using Models = std::vector<pinocchio::ConstraintModel>;
using Datas = std::vector<pinocchio::ConstraintData>;

// Pinocchio's constraints at configuration q (their frames depend on q), built before timing.
void pinConstraints(const pinocchio::Model& model, pinocchio::Data& data, const Eigen::VectorXd& q, const Problem& pb,
                    Models& cms, Datas& cds) {
  pinocchio::forwardKinematics(model, data, q);
  cms.clear();
  for (int k : pb.contacts) {
    const pinocchio::JointIndex j = kSegments[k] + 1;
    const pinocchio::SE3& oMj = data.oMi[j];
    const Eigen::Vector3d p = contactPoint(k);
    pinocchio::PointContactConstraintModel cm(model, j, pinocchio::SE3(oMj.rotation().transpose() * flip(), p), 0,
                                              pinocchio::SE3(flip(), oMj.act(p)));
    cm.setFriction(pb.mu);
    cms.emplace_back(cm);
  }
  const pinocchio::JointIndex tool = model.njoints - 1;
  cms.emplace_back(pinocchio::PointAnchorConstraintModel(model, tool, pinocchio::SE3::Identity(), 0, data.oMi[tool]));
  cds.clear();
  for (const auto& cm : cms) cds.push_back(cm.createData());
}

// Pinocchio's pipeline for one problem; Solver is the ADMM or the PGS.
template <class Solver, class Settings, class Result>
struct PinSolve {
  const pinocchio::Model& model;
  pinocchio::Data data;
  Solver solver;
  Settings settings;
  pinocchio::ConstraintCholeskyDecomposition chol;
  Eigen::MatrixXd J;
  Eigen::VectorXd v0, qdd_free, g, lambda, tau, qdd;
  bool converged = false;
  int iterations = 0;

  // cms0, cds0: constraints of the problem's shape (the decomposition's memory).
  PinSolve(const pinocchio::Model& m, int size, const Settings& s, const Models& cms0, const Datas& cds0)
      : model(m),
        data(m),
        solver(size),
        settings(s),
        chol(m, data, cms0, cds0),
        J(size, m.nv),
        v0(Eigen::VectorXd::Zero(m.nv)),
        g(size),
        lambda(size) {}

  const Eigen::VectorXd& operator()(const Eigen::VectorXd& q, const Models& cms, Datas& cds) {
    pinocchio::crba(model, data, q);
    qdd_free = pinocchio::aba(model, data, q, v0, v0);
    pinocchio::computeJointJacobians(model, data, q);
    for (std::size_t i = 0; i < cms.size(); ++i) cms[i].calc(model, data, cds[i]);
    chol.compute(model, data, cms, cds, 0.0);
    J.setZero();
    pinocchio::getConstraintsJacobian(model, data, cms, cds, J);
    g.noalias() = J * qdd_free;
    auto delassus = chol.getDelassusOperatorCholeskyExpression();
    Result res;
    converged = solver.solve(delassus, g, cms, cds, settings, res);
    iterations = static_cast<int>(res.iterations);
    res.retrieveConstraintImpulses(lambda);
    tau.noalias() = J.transpose() * lambda;
    qdd = pinocchio::aba(model, data, q, v0, tau);
    return qdd;
  }
};

pinocchio::ADMMSolverSettings admmSettings(int size) {
  pinocchio::ADMMSolverSettings s;
  s.max_iterations = 100000;
  s.absolute_feasibility_tol = s.relative_feasibility_tol = kTol;
  s.absolute_complementarity_tol = s.relative_complementarity_tol = kTol;
  s.lanczos_size = static_cast<std::size_t>(size);
  s.anderson_capacity = 4;  // as Pinocchio's own ADMM test
  s.rho_momentum = 0.9;
  return s;
}

pinocchio::PGSSolverSettings pgsSettings() {
  pinocchio::PGSSolverSettings s;
  s.max_iterations = 100000;
  s.absolute_feasibility_tol = s.relative_feasibility_tol = kTol;
  s.absolute_complementarity_tol = s.relative_complementarity_tol = kTol;
  return s;
}

// Our forces pushing strictly inside the circular cone, every point sticking.
bool sticksInside(const Data& data, double mu) {
  const auto f = data.contactForces();
  for (Eigen::Index k = 0; k < f.cols(); ++k) {
    if (data.contactStatus()[k] != ContactStatus::Sticking) return false;
    if (!(f(2, k) > 1e-6 && std::hypot(f(0, k), f(1, k)) < mu * f(2, k) - 1e-6)) return false;
  }
  return true;
}

struct Check {
  int converged = 0, agree = 0, it_max = 0;
  double it_sum = 0, dq_agree = 0, df_agree = 0;
};

template <class Pin>
void compare(Pin& pin, const std::vector<Eigen::VectorXd>& qs, std::vector<Models>& cms, std::vector<Datas>& cds,
             const std::vector<Eigen::VectorXd>& our_qdd, const std::vector<Matrix3X>& our_f, Check& out) {
  for (std::size_t s = 0; s < qs.size(); ++s) {
    const Eigen::VectorXd qdd = pin(qs[s], cms[s], cds[s]);
    out.it_sum += pin.iterations;
    out.it_max = std::max(out.it_max, pin.iterations);
    if (!pin.converged) continue;
    ++out.converged;
    const double dq = (qdd - our_qdd[s]).cwiseAbs().maxCoeff() / std::max(1.0, our_qdd[s].cwiseAbs().maxCoeff());
    if (!(dq <= 1e-6)) continue;
    ++out.agree;
    out.dq_agree = std::max(out.dq_agree, dq);
    for (Eigen::Index k = 0; k < our_f[s].cols(); ++k) {
      const Eigen::Vector3d f = -flip() * pin.lambda.template segment<3>(3 * k);
      out.df_agree = std::max(out.df_agree, (f - our_f[s].col(k)).cwiseAbs().maxCoeff());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const KDL::Chain chain = bench::makeGen3Chain();
  const Model model(chain);
  const pinocchio::Model pmodel = pinocchioModel(chain);
  pinocchio::Data pdata(pmodel);
  const Problem problems[] = {{"4 frictionless supports + 3-D task", {0, 1, 2, 3}, 0.0},
                              {"4 supports, mu 0.6, sticking inside the cone + 3-D task", {0, 1, 2, 3}, 0.6},
                              {"1 support (unique force), mu 1, sticking inside the cone + 3-D task", {1}, 1.0}};
  const double pose[7] = {0.0, 0.9, 0.0, 1.9, 0.0, 0.4, 1.57};
  std::ostringstream md;
  md << "### Point contacts against Pinocchio's ADMM and PGS (C++, `bench_contacts_pinocchio`)\n\n"
     << "CPU " << bench::cpuModel() << ", " << BENCH_CXX_COMPILER << ", " << BENCH_BUILD_TYPE << " (" << BENCH_CXX_FLAGS
     << "). bench_contacts' Gen3 problem (3-D task on the tool, point contacts under segments "
     << "2 to 5, q_dot = 0) for Pinocchio 4: PointContactConstraintModel per contact (circular cone), the task "
     << "as a PointAnchorConstraintModel, time step 1, G = J M^-1 J^T (ConstraintCholeskyDecomposition), "
     << "g = J qdd_free; ADMM (Anderson 4, rho momentum 0.9) and PGS at tolerance 1e-10, up to 100000 "
     << "iterations; the timed Pinocchio call includes crba, both aba, the Jacobians, the decomposition and "
     << "the solver (the constraint models are built per state beforehand). 64 seeded states per problem; "
     << "frictionless: any; with friction: kept when every point of ours sticks strictly inside the cone. "
     << "Differences over the converged solves whose qdd agrees to 1e-6 (relative to max(1, |qdd|)); the "
     << "forces are unique only in the last row.\n\n"
     << "| problem | ours (us) | ADMM (us) | ADMM / ours | ADMM iterations mean (max) | converged | agree | max "
        "qdd diff | max force diff (N) | PGS (us) | PGS / ours | PGS iterations mean (max) | converged | agree | "
        "max qdd diff | max force diff (N) |\n"
     << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  bench::Rng rng(20261128);
  for (const Problem& pb : problems) {
    Data data(model);
    SolveInput in(model);
    ourInput(in, model, pb);
    std::vector<Eigen::VectorXd> qs, our_qdd;
    std::vector<Matrix3X> our_f;
    for (int tries = 0; tries < 200000 && static_cast<int>(qs.size()) < bench::kStates; ++tries) {
      Eigen::VectorXd q(7);
      for (int j = 0; j < 7; ++j) q(j) = pose[j] + rng.uniform(-0.3, 0.3);
      in.setState(JointPositions(q), JointVelocities(Eigen::VectorXd::Zero(7)));
      if (!solve(model, data, in) || (pb.mu > 0.0 && !sticksInside(data, pb.mu))) continue;
      qs.push_back(q);
      our_qdd.push_back(data.qdd());
      our_f.push_back(data.contactForces());
    }
    const int size = 3 * static_cast<int>(pb.contacts.size()) + 3;
    if (qs.empty()) {
      std::fprintf(stderr, "%s: no state found\n", pb.name);
      return 1;
    }
    std::vector<Models> cms(qs.size());
    std::vector<Datas> cds(qs.size());
    for (std::size_t s = 0; s < qs.size(); ++s) pinConstraints(pmodel, pdata, qs[s], pb, cms[s], cds[s]);
    PinSolve<pinocchio::ADMMConstraintSolver, pinocchio::ADMMSolverSettings, pinocchio::ADMMSolverResult> admm(
        pmodel, size, admmSettings(size), cms[0], cds[0]);
    PinSolve<pinocchio::PGSConstraintSolver, pinocchio::PGSSolverSettings, pinocchio::PGSSolverResult> pgs(
        pmodel, size, pgsSettings(), cms[0], cds[0]);
    Check ca, cp;
    compare(admm, qs, cms, cds, our_qdd, our_f, ca);
    compare(pgs, qs, cms, cds, our_qdd, our_f, cp);
    std::vector<std::size_t> idx(qs.size());
    for (std::size_t s = 0; s < idx.size(); ++s) idx[s] = s;
    std::vector<bench::Bench> group;
    bench::addBench(group, "ours", bench::overStates(idx, [&](std::size_t s) {
                      in.setState(JointPositions(qs[s]), JointVelocities(Eigen::VectorXd::Zero(7)));
                      (void)solve(model, data, in);
                      return data.qdd()(0);
                    }));
    bench::addBench(group, "ADMM",
                    bench::overStates(idx, [&](std::size_t s) { return admm(qs[s], cms[s], cds[s])(0); }));
    bench::addBench(group, "PGS", bench::overStates(idx, [&](std::size_t s) { return pgs(qs[s], cms[s], cds[s])(0); }));
    bench::runGroup(group, pb.name);
    const double n = std::max<double>(1.0, static_cast<double>(qs.size()));
    md << "| " << pb.name << " (" << qs.size() << " states) | " << bench::fmt("%.2f", bench::median(group[0].us));
    for (int i = 1; i <= 2; ++i) {
      const Check& c = i == 1 ? ca : cp;
      md << " | " << bench::fmt("%.1f", bench::median(group[i].us)) << " | "
         << bench::fmt("%.1f", bench::pairedRatio(group[i], group[0])) << "x | " << bench::fmt("%.0f", c.it_sum / n)
         << " (" << c.it_max << ") | " << c.converged << " | " << c.agree << " | " << bench::fmt("%.1e", c.dq_agree)
         << " | " << bench::fmt("%.1e", c.df_agree);
    }
    md << " |\n";
  }
  if (argc > 1) {
    std::ofstream(argv[1]) << md.str();
  } else {
    std::cout << md.str();
  }
  std::fprintf(stderr, "sink %g\n", bench::g_sink);
  return 0;
}
