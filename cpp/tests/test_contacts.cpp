// Point contacts in solve() (contact.hpp) against a dense oracle built from the companions (mass
// matrix, inverse dynamics, point Jacobians, tested against KDL and Pinocchio elsewhere):
// Gauss's principle with unilateral constraints solved by enumerating which supports push
// (frictionless), sticking points as bilateral point constraints, force set-points as a held
// normal plus a known force; and, for every result, the replay identity
//     H qdd = tau_ff - C qd - g + J_ext^T f_ext + tau_command + sum_c J_c^T f_c.
// Random chains and trees at rest (every point touching), q random, tasks as classical set-points.
#include <doctest/doctest.h>

#include <cmath>

#include <Eigen/Dense>

#include "random_chain.hpp"
#include "random_tree.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/kinematics.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

// The dense problem: H, h = tau_ff - ID(q, qd, 0) (gravity, f_ext included), the task rows A x = b
// and per contact its point Jacobian (3 x n) and bias acceleration (3).
struct Dense {
  Eigen::MatrixXd H, A;
  Eigen::VectorXd h, b;
  std::vector<Eigen::MatrixXd> J;
  std::vector<Vector3> bias;
};

Dense dense(const Model& model, const SolveInput& in) {
  const int n = static_cast<int>(model.nrOfJoints());
  DynamicsData dyn(model);
  KinematicsData kin(model);
  Dense d;
  d.H.resize(n, n);
  d.h.resize(n);
  REQUIRE(massMatrix(model, dyn, JointPositions(in.q), d.H));
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  REQUIRE(inverseDynamics(model, dyn, JointPositions(in.q), JointVelocities(in.q_dot), JointAccelerations(zero),
                          in.f_ext, in.gravity, d.h));
  d.h = in.ff_torques - d.h;
  REQUIRE(forwardKinematics(model, kin, JointPositions(in.q), JointVelocities(in.q_dot)));
  Eigen::MatrixXd J6(6, n);
  Vector6 bias;
  int m = in.columns();
  d.A.resize(m, n);
  d.b.resize(m);
  int row = 0;
  for (const ConstraintBlock& blk : in.constraints) {  // classical set-points (tests use only those)
    const FrameRef at{blk.segment, KDL::Frame(KDL::Vector(blk.point(0), blk.point(1), blk.point(2)))};
    REQUIRE(frameJacobian(model, kin, at, J6));
    REQUIRE(frameBiasAcceleration(model, kin, at, bias));
    for (int c = 0; c < blk.columns; ++c, ++row) {
      d.A.row(row) = blk.alfa.col(c).transpose() * J6;
      d.b(row) = blk.alfa.col(c).dot(blk.classical_acceleration - bias);
    }
  }
  for (const PointContact& pc : in.contacts) {
    const FrameRef at{pc.segment, KDL::Frame(KDL::Vector(pc.point(0), pc.point(1), pc.point(2)))};
    REQUIRE(frameJacobian(model, kin, at, J6));
    REQUIRE(frameBiasAcceleration(model, kin, at, bias));
    d.J.push_back(J6.topRows(3));
    d.bias.push_back(bias.head<3>());
  }
  return d;
}

// Solves H x - A^T nu - C^T lam = h, A x = b, C x = e for x (and the multipliers).
Eigen::VectorXd kkt(const Dense& d, const Eigen::MatrixXd& C, const Eigen::VectorXd& e, Eigen::VectorXd& lam) {
  const int n = static_cast<int>(d.h.size()), m = static_cast<int>(d.b.size()), k = static_cast<int>(e.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m + k, n + m + k);
  Eigen::VectorXd r(n + m + k);
  K.topLeftCorner(n, n) = d.H;
  K.block(0, n, n, m) = -d.A.transpose();
  K.block(0, n + m, n, k) = -C.transpose();
  K.block(n, 0, m, n) = d.A;
  K.block(n + m, 0, k, n) = C;
  r << d.h, d.b, e;
  const Eigen::VectorXd x = K.colPivHouseholderQr().solve(r);
  lam = x.tail(k);
  return x.head(n);
}

// The replay identity's residual, relative (d: dense(model, in)).
double replay(const Dense& d, const SolveInput& in, const Data& data) {
  Eigen::VectorXd r = d.H * data.qdd() - d.h - data.commandTorques();
  for (std::size_t c = 0; c < in.contacts.size(); ++c) r -= d.J[c].transpose() * data.contactForces().col(c);
  return r.cwiseAbs().maxCoeff() / std::max(1.0, d.h.cwiseAbs().maxCoeff());
}

double replay(const Model& model, const SolveInput& in, const Data& data) {
  return replay(dense(model, in), in, data);
}

// The worst violation of the support conditions at the instant, relative to the problem's scale
// max(1, |h|) (forces) and max(1, |qdd|) (accelerations): per support, the normal force f_n >= 0,
// the point's normal acceleration a_n >= 0, f_n a_n = 0, the tangential force within mu f_n (the
// friction polygon lies inside that circle), a sticking point's acceleration zero and a separating
// point's force zero (d: dense(model, in)).
double supportViolation(const Dense& d, const SolveInput& in, const Data& data) {
  const double fs = std::max(1.0, d.h.cwiseAbs().maxCoeff()), as = std::max(1.0, data.qdd().cwiseAbs().maxCoeff());
  double worst = 0.0;
  for (std::size_t c = 0; c < in.contacts.size(); ++c) {
    const PointContact& pc = in.contacts[c];
    const Vector3 f = data.contactForces().col(static_cast<Eigen::Index>(c));
    const Vector3 a = d.J[c] * data.qdd() + d.bias[c];
    const double fn = pc.normal.dot(f), an = pc.normal.dot(a), ft = (f - fn * pc.normal).norm();
    worst = std::max({worst, -fn / fs, -an / as, std::abs(fn * an) / (fs * as), (ft - pc.mu * fn) / fs});
    const ContactStatus st = data.contactStatus()[c];
    if (st == ContactStatus::Sticking) worst = std::max(worst, a.norm() / as);
    if (st == ContactStatus::Separating) worst = std::max(worst, f.norm() / fs);
  }
  return worst;
}

Model randomModel(RandomGen& g, bool tree, int n) {
  testutil::TreeSpec spec;
  spec.n_joints = n;
  return tree ? Model(testutil::randomTree(g, spec)) : Model(g.chain(n));
}

SolveInput restingInput(RandomGen& g, const Model& model, int contacts, double mu, double force) {
  const int n = static_cast<int>(model.nrOfJoints()), ns = static_cast<int>(model.nrOfSegments());
  SolveInput in(model);
  in.q = g.q(n).data;
  in.q_dot.setZero();
  in.ff_torques = g.torques(n).data;
  for (int c = 0; c < contacts; ++c) {
    PointContact pc;
    pc.segment = g.integer(0, ns - 1);
    const KDL::Vector p = g.vector(-0.2, 0.2);  // (draws in their own statements: random_chain.hpp)
    pc.point = Vector3(p.x(), p.y(), p.z());
    const KDL::Vector v = g.vector(-1.0, 1.0);
    pc.normal = Vector3(v.x(), v.y(), v.z()).normalized();
    pc.mu = mu;
    pc.force = force;
    in.contacts.push_back(pc);
  }
  return in;
}

}  // namespace

TEST_CASE("frictionless supports equal the enumerated Gauss problem, chains and trees") {
  RandomGen g(31);
  double worst_qdd = 0.0, worst_force = 0.0, worst_replay = 0.0;
  int pushing = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const Model model = randomModel(g, trial % 2 == 1, g.integer(2, 9));
    const int k = g.integer(1, std::min(4, static_cast<int>(model.nrOfJoints())));
    SolveInput in = restingInput(g, model, k, 0.0, std::numeric_limits<double>::quiet_NaN());
    Data data(model);
    const Status s = solve(model, data, in);
    REQUIRE_MESSAGE(s, "trial " << trial << ": " << std::string(s.message()));
    CHECK(data.contactOutcome() == ContactOutcome::Unique);
    const Dense d = dense(model, in);
    // Enumerate the supports that push (the rest must separate).
    int found = 0;
    for (int mask = 0; mask < (1 << k); ++mask) {
      const int a = __builtin_popcount(mask);
      Eigen::MatrixXd C(a, model.nrOfJoints());
      Eigen::VectorXd e(a), lam;
      for (int c = 0, r = 0; c < k; ++c)
        if (mask >> c & 1) {
          C.row(r) = in.contacts[c].normal.transpose() * d.J[c];
          e(r++) = -in.contacts[c].normal.dot(d.bias[c]);
        }
      const Eigen::VectorXd x = kkt(d, C, e, lam);
      bool ok = a == 0 || lam.minCoeff() >= -1e-9;
      for (int c = 0; c < k && ok; ++c)
        if (!(mask >> c & 1)) ok = in.contacts[c].normal.dot(d.J[c] * x + d.bias[c]) >= -1e-9;
      if (!ok) continue;
      ++found;
      worst_qdd = std::max(worst_qdd, (data.qdd() - x).cwiseAbs().maxCoeff() / std::max(1.0, x.cwiseAbs().maxCoeff()));
      // The generalised contact force sum_c J_c^T f_c is unique (the forces themselves are not when
      // the points' Jacobians are dependent): compare it, and each force's direction and sign.
      Eigen::VectorXd gen_ours = Eigen::VectorXd::Zero(x.size()), gen_oracle = gen_ours;
      for (int c = 0, r = 0; c < k; ++c) {
        const double fn = (mask >> c & 1) ? lam(r++) : 0.0;
        const Vector3 f = data.contactForces().col(c);
        gen_ours += d.J[c].transpose() * f;
        gen_oracle += d.J[c].transpose() * (fn * in.contacts[c].normal);
        CHECK((f - in.contacts[c].normal.dot(f) * in.contacts[c].normal).norm() <= 1e-12 * std::max(1.0, f.norm()));
        CHECK(in.contacts[c].normal.dot(f) >= 0.0);
        pushing += fn > 1e-9;
      }
      worst_force = std::max(
          worst_force, (gen_ours - gen_oracle).cwiseAbs().maxCoeff() / std::max(1.0, gen_oracle.cwiseAbs().maxCoeff()));
      break;
    }
    CHECK_MESSAGE(found == 1, "trial " << trial << ": the enumeration found no consistent support set");
    worst_replay = std::max(worst_replay, replay(model, in, data));
  }
  CHECK(worst_qdd <= 1e-9);
  CHECK(worst_force <= 1e-9);
  CHECK(worst_replay <= 1e-9);
  CHECK(pushing > 20);
  MESSAGE("worst: qdd " << worst_qdd << ", force " << worst_force << ", replay " << worst_replay << "; " << pushing
                        << " pushing supports");
}

TEST_CASE("sticking points with friction equal bilateral point constraints") {
  RandomGen g(47);
  double worst = 0.0;
  int sticking = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const Model model = randomModel(g, trial % 2 == 0, g.integer(4, 9));
    SolveInput in = restingInput(g, model, 1, 2.0, std::numeric_limits<double>::quiet_NaN());
    in.contacts[0].segment = static_cast<int>(model.nrOfSegments()) - 1;  // a chain's tip: a full-rank point
    Data data(model);
    REQUIRE(solve(model, data, in));
    const Dense d = dense(model, in);
    Eigen::VectorXd lam;
    const Eigen::VectorXd x = kkt(d, d.J[0], -d.bias[0], lam);
    // The bilateral answer must push and lie strictly inside the friction polygon (apothem mu cos(pi/4)).
    const Vector3 n0 = in.contacts[0].normal;
    const double fn = n0.dot(lam), ft = (lam - fn * n0).norm();
    if (fn <= 1e-6 || ft >= 0.99 * 2.0 * std::cos(M_PI / 4) * fn) continue;
    ++sticking;
    CHECK(data.contactStatus()[0] == ContactStatus::Sticking);
    CHECK(data.contactOutcome() == ContactOutcome::Consistent);
    const double eq = (data.qdd() - x).cwiseAbs().maxCoeff() / std::max(1.0, x.cwiseAbs().maxCoeff());
    // The generalised force J^T f is unique; the force itself only when J has rank 3.
    const Eigen::VectorXd gen = d.J[0].transpose() * lam;
    const double ef = (d.J[0].transpose() * data.contactForces().col(0) - gen).cwiseAbs().maxCoeff() /
                      std::max(1.0, gen.cwiseAbs().maxCoeff());
    if (eq > 1e-9 || ef > 1e-9)
      MESSAGE("trial " << trial << " qdd err " << eq << " force " << data.contactForces().col(0).transpose() << " vs "
                       << lam.transpose());
    worst = std::max({worst, eq, ef});
    CHECK(replay(model, in, data) <= 1e-9);
  }
  CHECK(sticking > 25);
  CHECK(worst <= 1e-9);
  MESSAGE("worst relative error " << worst << " over " << sticking << " sticking points");
}

TEST_CASE("a contact solve's outputs are those of the plain solve with its forces as wrenches") {
  // Supports (frictionless, and with friction at rest: sticking where they hold) with a task on
  // the last segment or on another one: the contact stage's results, however it reaches them
  // (the held forces' linear update or a final sweep), must equal a plain solve of the same input
  // with each reported contact force as a frame wrench at its point, including nu, the command
  // torques and the segments' accelerations (linkAccelerations).
  RandomGen g(71);
  double worst = 0.0;
  int compared = 0, degenerate = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const Model model = randomModel(g, trial % 2 == 1, g.integer(4, 9));
    const int n = static_cast<int>(model.nrOfJoints()), ns = static_cast<int>(model.nrOfSegments());
    const int k = g.integer(1, 3);
    SolveInput in = restingInput(g, model, k, trial % 3 == 0 ? 0.0 : 1.5, std::numeric_limits<double>::quiet_NaN());
    ConstraintBlock task;
    task.segment = trial % 4 == 0 ? g.integer(0, ns - 1) : ns - 1;
    task.columns = std::min(2, n - 1);
    for (int c = 0; c < task.columns; ++c) task.alfa(3 + c, c) = 1.0;  // angular rows: the points keep moving
    task.beta.setZero();
    in.constraints.push_back(task);
    Data data(model);
    if (!solve(model, data, in)) continue;
    // Held directions the motion hardly affects need forces far above the problem's scale (up to
    // 1e18 N here); both answers then carry round-off of |f| eps in the accelerations, and the
    // plain solve is no reference: such trials are counted, not compared.
    if (data.contactForces().cwiseAbs().maxCoeff() > 1e6) {
      ++degenerate;
      continue;
    }
    SolveInput plain = in;
    plain.contacts.clear();
    for (int c = 0; c < k; ++c) {
      FrameWrench w;
      w.segment = in.contacts[c].segment;
      w.point = in.contacts[c].point;
      w.wrench.head<3>() = data.contactForces().col(c);
      plain.wrenches.push_back(w);
    }
    Data ref(model);
    REQUIRE(solve(model, ref, plain));
    const auto rel = [](const auto& a, const auto& b) {
      return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
    };
    const double err = std::max({rel(data.qdd(), ref.qdd()), rel(data.commandTorques(), ref.commandTorques()),
                                 rel(Eigen::VectorXd(data.nu()), Eigen::VectorXd(ref.nu())),
                                 rel(data.linkAccelerations(), ref.linkAccelerations())});
    CHECK_MESSAGE(err <= 1e-9, "trial " << trial << ": relative difference " << err);
    worst = std::max(worst, err);
    ++compared;
  }
  CHECK(compared > 80);
  CHECK(degenerate <= 5);
  MESSAGE("worst relative difference " << worst << " over " << compared << " solves (" << degenerate
                                       << " with forces above 1e6 N left out)");
}

TEST_CASE("a frictionless force set-point holds the normal and pushes with its force") {
  RandomGen g(59);
  double worst = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    const Model model = randomModel(g, trial % 2 == 0, g.integer(3, 8));
    SolveInput in = restingInput(g, model, 1, 0.0, g.uniform(0.0, 20.0));
    Data data(model);
    const Status s = solve(model, data, in);
    REQUIRE_MESSAGE(s, std::string(s.message()));
    Dense d = dense(model, in);
    const PointContact& pc = in.contacts[0];
    d.h += d.J[0].transpose() * (pc.force * pc.normal);  // the surface's known push
    Eigen::VectorXd lam;
    const Eigen::VectorXd x =
        kkt(d, pc.normal.transpose() * d.J[0], Eigen::VectorXd::Constant(1, -pc.normal.dot(d.bias[0])), lam);
    worst = std::max(worst, (data.qdd() - x).cwiseAbs().maxCoeff() / std::max(1.0, x.cwiseAbs().maxCoeff()));
    worst = std::max(worst, (data.contactForces().col(0) - pc.force * pc.normal).norm() / std::max(1.0, pc.force));
    CHECK(data.nu().size() == 0);  // the set-point's column is not one of the input's
    CHECK(replay(model, in, data) <= 1e-9);
  }
  CHECK(worst <= 1e-9);
}

TEST_CASE("contacts refuse invalid input with messages") {
  RandomGen g(3);
  const Model model(g.chain(4));
  Data data(model);
  SolveInput in(model);
  PointContact pc;
  pc.segment = 7;
  in.contacts.push_back(pc);
  Status s = solve(model, data, in);
  CHECK(s.code() == Error::InvalidContact);
  CHECK(std::string(s.message()).find("contacts[0].segment") != std::string::npos);
  in.contacts[0].segment = 1;
  in.contacts[0].normal = Vector3(0, 0, 2);
  CHECK(solve(model, data, in).code() == Error::InvalidContact);
  in.contacts[0].normal = Vector3::UnitZ();
  in.contacts[0].mu = -1.0;
  CHECK(solve(model, data, in).code() == Error::InvalidContact);
  in.contacts[0].mu = 0.5;
  in.contacts[0].facets = 2;
  CHECK(solve(model, data, in).code() == Error::InvalidContact);
  in.contacts[0].facets = 4;
  REQUIRE(solve(model, data, in));
  CHECK(data.contactForces().cols() == 1);
  in.contacts.clear();
  REQUIRE(solve(model, data, in));
  CHECK(data.contactForces().cols() == 0);
  CHECK(data.contactOutcome() == ContactOutcome::None);
}

namespace {

// A planar arm of three 1 kg links about y (KDL): 0.4 m, 0.4 m, and the tool 0.1 m beyond the
// wrist (the third link's centre of mass 0.2 m beyond it).
KDL::Chain planarArm() {
  KDL::Chain chain;
  const KDL::RigidBodyInertia link(1.0, KDL::Vector(0.2, 0, 0), KDL::RotationalInertia(0.001, 0.015, 0.015));
  chain.addSegment(KDL::Segment("l1", KDL::Joint("j1", KDL::Joint::RotY), KDL::Frame(KDL::Vector(0.4, 0, 0)), link));
  chain.addSegment(KDL::Segment("l2", KDL::Joint("j2", KDL::Joint::RotY), KDL::Frame(KDL::Vector(0.4, 0, 0)), link));
  chain.addSegment(KDL::Segment("l3", KDL::Joint("j3", KDL::Joint::RotY), KDL::Frame(KDL::Vector(0.1, 0, 0)), link));
  return chain;
}

}  // namespace

TEST_CASE("a support under a direction the task also holds carries the load (least motor effort)") {
  // The arm stands still, its tool held in x, z and pitch (3 columns: no motion left). A support
  // at the elbow (the tip of l1, mu = 0.5) is redundant with the task: any valid support force
  // leaves qdd = 0, and the solve takes the one of least ||tau_command||, then of least ||f||.
  // Oracle: with qdd = 0, tau_command = tau_free - J_e^T f (tau_free: the command without the
  // support). The elbow moves with joint 1 only, so the least command zeroes its first entry along
  // the line b . (f_x, f_z) = tau_free(0) (b: the elbow's x and z rows of joint 1); the least force
  // on that line inside f_z >= 0, |f_x| <= mu f_z (the 4-facet polygon's vertices in the arm's
  // plane) is the line's point nearest the origin, or the nearer of its crossings with the edges.
  const Model model(planarArm());
  Data data(model);
  SolveInput in(model);
  Eigen::VectorXd q(3), qd = Eigen::VectorXd::Zero(3);
  q << 0.6, -0.6, -0.6;
  in.setState(JointPositions(q), JointVelocities(qd));
  Eigen::MatrixXd alfa = Eigen::MatrixXd::Zero(6, 3);
  alfa(0, 0) = alfa(2, 1) = alfa(4, 2) = 1.0;
  REQUIRE(in.addConstraint(2, alfa, Eigen::VectorXd::Zero(3)));
  in.constraints[0].classical = true;
  REQUIRE(solve(model, data, in));
  const Eigen::VectorXd tau_free = data.commandTorques();
  PointContact elbow;
  elbow.segment = 0;
  elbow.normal = Vector3::UnitZ();
  elbow.mu = 0.5;
  in.contacts.push_back(elbow);
  const Status s = solve(model, data, in);
  REQUIRE_MESSAGE(s, std::string(s.message()));
  const Vector3 f = data.contactForces().col(0);
  CHECK(data.qdd().cwiseAbs().maxCoeff() <= 1e-9);
  // The oracle: least squares in (f_x, f_z), projected onto the cone's edges if outside.
  KinematicsData kin(model);
  REQUIRE(forwardKinematics(model, kin, JointPositions(q), JointVelocities(qd)));
  Eigen::MatrixXd J6(6, 3);
  REQUIRE(frameJacobian(model, kin, FrameRef{0, KDL::Frame::Identity()}, J6));
  Eigen::MatrixXd B(3, 2);
  B << J6.row(0).transpose(), J6.row(2).transpose();  // columns: f_x, f_z
  const Eigen::Vector2d b = B.row(0).transpose();
  const double tau1 = tau_free(0);
  REQUIRE(B.bottomRows(2).cwiseAbs().maxCoeff() == 0.0);  // joints 2 and 3 do not move the elbow
  Eigen::Vector2d best = b * tau1 / b.squaredNorm();      // the nearest point of the line
  if (std::abs(best(0)) > 0.5 * best(1)) {
    double best_norm = std::numeric_limits<double>::infinity();
    for (const double side : {-1.0, 1.0}) {  // crossing the edge f_x = side mu f_z
      const Eigen::Vector2d edge(side * 0.5, 1.0);
      const double s = tau1 / b.dot(edge);
      if (s > 0.0 && (s * edge).norm() < best_norm) best = s * edge, best_norm = (s * edge).norm();
    }
  }
  CHECK(f.z() > 1.0);
  CHECK(std::abs(f.x() - best(0)) <= 1e-9 * std::max(1.0, best.norm()));
  CHECK(std::abs(f.z() - best(1)) <= 1e-9 * std::max(1.0, best.norm()));
  CHECK((data.commandTorques() - (tau_free - B * best)).cwiseAbs().maxCoeff() <= 1e-9 * tau_free.norm());
  MESSAGE("support force " << f.transpose() << " N; oracle " << best.transpose() << "; command "
                           << data.commandTorques().transpose() << " N m (free " << tau_free.transpose() << ")");
}

TEST_CASE("a force set-point the task drags along slides, its friction at the opposing vertex") {
  // The planar arm's tool presses down on a table with 5 N (mu = 0.4) while the task accelerates
  // it along x at 0.5 m/s^2 from rest: the point starts to slide, so Coulomb's law with maximum
  // dissipation puts the friction at mu F against the motion, (-2, 0, 5) N in all. (The task's
  // column along x contradicts a sticking trial's tangential column there: the solve must see
  // that the point does not stick.)
  const Model model(planarArm());
  Data data(model);
  SolveInput in(model);
  Eigen::VectorXd q(3), qd = Eigen::VectorXd::Zero(3);
  q << 0.6, -1.2, 0.3;
  in.setState(JointPositions(q), JointVelocities(qd));
  Eigen::MatrixXd alfa = Eigen::MatrixXd::Zero(6, 1);
  alfa(0, 0) = 1.0;
  REQUIRE(in.addConstraint(2, alfa, Eigen::VectorXd::Zero(1)));
  in.constraints[0].classical = true;
  in.constraints[0].classical_acceleration(0) = 0.5;
  PointContact tool;
  tool.segment = 2;
  tool.normal = Vector3::UnitZ();
  tool.mu = 0.4;
  tool.force = 5.0;
  in.contacts.push_back(tool);
  const Status s = solve(model, data, in);
  REQUIRE_MESSAGE(s, std::string(s.message()));
  CHECK(data.contactStatus()[0] == ContactStatus::Sliding);
  CHECK((data.contactForces().col(0) - Vector3(-2.0, 0.0, 5.0)).norm() <= 1e-12);
  CHECK(replay(model, in, data) <= 1e-12);
}

TEST_CASE("contacts with joint friction: the replay identity, friction bounds, and zero friction") {
  RandomGen g(29);
  int checked = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const bool tree = trial % 2 == 1;
    const Model model = randomModel(g, tree, 6);
    const int n = static_cast<int>(model.nrOfJoints());
    SolveInput in = restingInput(g, model, 1 + trial % 3, trial % 3 == 0 ? 0.0 : 0.6, NAN);
    FrictionModel fm;
    fm.static_friction = Eigen::VectorXd::Zero(n);
    Data plain(model), data(model);
    REQUIRE(solve(model, plain, in));
    in.friction = &fm;  // zero friction: the contacts' answer
    REQUIRE(solve(model, data, in));
    if (plain.contactOutcome() == ContactOutcome::Unique) {
      CHECK((data.qdd() - plain.qdd()).cwiseAbs().maxCoeff() <=
            1e-10 * std::max(1.0, plain.qdd().cwiseAbs().maxCoeff()));
    } else {
      // With friction at a touching support another consistent answer may exist (ContactOutcome::
      // Consistent): the two solves' methods may reach different ones, each of them valid.
      const Dense d = dense(model, in);
      CHECK(replay(d, in, plain) <= 1e-9);
      CHECK(replay(d, in, data) <= 1e-9);
      CHECK(supportViolation(d, in, plain) <= 1e-9);
      CHECK(supportViolation(d, in, data) <= 1e-9);
    }
    for (int j = 0; j < n; ++j) fm.static_friction(j) = g.uniform(0.0, 2.0);
    in.q_dot(trial % n) = 0.5;  // one joint moving: its kinetic friction
    const Status s = solve(model, data, in);
    if (!s) {  // a support approaching its surface is refused; none else
      CHECK(std::string(s.message()).find("approaches") != std::string::npos);
      continue;
    }
    // H qdd = h + tau_command + friction + limits + sum_c J_c^T f_c, and every friction torque within
    // its bound, opposing the joint's velocity (moving) or its acceleration (resting, slipping).
    const Dense d = dense(model, in);
    Eigen::VectorXd r = d.H * data.qdd() - d.h - data.commandTorques() - data.frictionTorques() - data.limitTorques();
    for (std::size_t c = 0; c < in.contacts.size(); ++c) r -= d.J[c].transpose() * data.contactForces().col(c);
    CHECK(r.cwiseAbs().maxCoeff() <= 1e-9 * std::max(1.0, d.h.cwiseAbs().maxCoeff()));
    ++checked;
    for (int j = 0; j < n; ++j) {
      const double t = data.frictionTorques()(j), f = fm.static_friction(j), a = data.qdd()(j);
      CHECK(std::abs(t) <= f * (1.0 + 1e-12));
      if (in.q_dot(j) != 0.0)
        CHECK(t == doctest::Approx(-f));
      else if (std::abs(a) > 1e-9 * std::max(1.0, data.qdd().cwiseAbs().maxCoeff()))
        CHECK(t == doctest::Approx(a > 0.0 ? -f : f));
    }
  }
  CHECK(checked >= 6);
}
