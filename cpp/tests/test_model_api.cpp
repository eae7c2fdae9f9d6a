// The (model, data, input) API (model.hpp, data.hpp, input.hpp): against the solver faces it
// underlies (ChainHdSolver, TreeHdSolver, FrictionSolver), KDL's forward kinematics and Jacobian
// solvers as the oracle of frame loads and Jacobians, threads sharing one Model, typed inputs
// and errors.
#include <doctest/doctest.h>

#include <thread>
#include <type_traits>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainfksolvervel_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treejnttojacsolver.hpp>

#include "random_chain.hpp"
#include "random_tree.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/friction_solver.hpp"
#include "vereshchagin/tree_hd_solver.hpp"
#include "vereshchagin/urdf_loader.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

const KDL::Twist kUp(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero());

// |a - b| <= tol * max(1, |b|), entrywise in the max norm.
bool close(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b, double tol = 1e-12) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  if (a.size() == 0) return true;
  return (a - b).cwiseAbs().maxCoeff() <= tol * std::max(1.0, b.cwiseAbs().maxCoeff());
}

bool same(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && (a.array() == b.array()).all();
}

Vector3 vec(const KDL::Vector& v) {
  return Vector3(v.x(), v.y(), v.z());
}

// Input with the random state of `in` and its columns as blocks of up to 6 on `segments`.
void fill(SolveInput& input, const testutil::SolveInputs& in) {
  input.setState(JointPositions(in.q), JointVelocities(in.qd));
  input.f_ext = in.fext;
  input.ff_torques = in.ff;
  input.constraints.clear();
  for (Eigen::Index c = 0; c < in.alfa.cols(); ++c) {
    const int seg = in.segments(c);
    if (input.constraints.empty() || input.constraints.back().segment != seg || input.constraints.back().columns == 6)
      input.constraints.push_back(ConstraintBlock{seg});
    ConstraintBlock& b = input.constraints.back();
    b.alfa.col(b.columns) = in.alfa.col(c);
    b.beta(b.columns) = in.beta(c);
    ++b.columns;
  }
}

}  // namespace

TEST_CASE("Model names and frames") {
  RandomGen g(1);
  const KDL::Chain chain = g.chain(5);
  const Model model(chain);
  CHECK(model.status().ok());
  CHECK(model.nrOfJoints() == chain.getNrOfJoints());
  CHECK(model.isChain());
  FrameRef f;
  CHECK(model.findFrame(chain.getSegment(2).getName(), f));
  CHECK(f.segment == 2);
  CHECK(model.findFrame("base", f));
  CHECK(f.segment == -1);
  CHECK_FALSE(model.findFrame("no such frame", f));

  const KDL::Tree tree = testutil::randomTree(g, testutil::TreeSpec());
  const Model tmodel(tree);
  const TreeHdSolver ts(tree, kUp);
  CHECK(tmodel.segmentNames() == ts.segmentNames());
  CHECK(tmodel.jointNames() == ts.jointNames());
  CHECK(tmodel.parents() == ts.parent());

  const char* urdf = R"(<robot name="r">
    <link name="base"/>
    <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <link name="tool"><inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <joint name="j0" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
    <joint name="fix" type="fixed"><parent link="a"/><child link="tool"/><origin xyz="0.1 0.2 0.3"/></joint>
  </robot>)";
  const UrdfResult loaded = chainFromUrdfString(urdf);
  REQUIRE(loaded.ok);
  const Model rmodel(loaded.robot);
  CHECK(rmodel.status().ok());
  CHECK(rmodel.baseName() == "base");
  CHECK(rmodel.jointIndex("j0") == 0);
  REQUIRE(rmodel.findFrame("tool", f));
  CHECK(f.segment == 0);
  for (const LinkPlacement& l : rmodel.links())
    if (l.link == "tool") CHECK(KDL::Equal(f.in_tip, l.in_segment_tip));
}

TEST_CASE("solve equals ChainHdSolver on random chains") {
  RandomGen g(2);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = g.integer(1, 12);
    const KDL::Chain chain = g.chain(n);
    const unsigned ns = chain.getNrOfSegments();
    const int m = g.integer(0, 6);
    testutil::SolveInputs in = testutil::randomInputs(g, n, ns, m);
    in.segments = Eigen::VectorXi::Constant(m, static_cast<int>(ns) - 1);
    ChainHdSolver hd(chain, kUp);
    const Model model(chain);
    Data data(model);
    SolveInput input(model);
    fill(input, in);
    Eigen::VectorXd pf = Eigen::VectorXd::Zero(m);
    if (m > 0 && g.coin()) {
      for (int c = 0; c < m; ++c) pf(c) = g.uniform(0.0, 1.0);
      REQUIRE(hd.setPassThrough(pf, Eigen::VectorXd()) == 0);
      for (int c = 0; c < m; ++c) input.constraints[0].f_ext_pass_through(c) = pf(c);
    }
    REQUIRE(hd.solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff) == 0);
    REQUIRE(solve(model, data, input).ok());
    CHECK(same(data.qdd(), hd.qdd()));  // the same path: bit for bit
    CHECK(same(data.commandTorques(), hd.commandTorques()));
    CHECK(same(data.nu(), hd.nu()));
    CHECK(same(data.linkAccelerations(), hd.linkAccelerations()));
    CHECK(data.constraintRank() == hd.constraintRank());
  }
}

TEST_CASE("solve equals TreeHdSolver with constraints on any segments") {
  RandomGen g(3);
  for (int trial = 0; trial < 30; ++trial) {
    testutil::TreeSpec spec;
    spec.n_joints = g.integer(2, 12);
    const KDL::Tree tree = testutil::randomTree(g, spec);
    TreeHdSolver hd(tree, kUp);
    const Model model(tree);
    const unsigned ns = model.nrOfSegments();
    const int m = g.integer(0, 8);
    testutil::SolveInputs in = testutil::randomInputs(g, model.nrOfJoints(), ns, m);
    in.segments.resize(m);
    for (int c = 0; c < m; ++c) in.segments(c) = g.integer(0, static_cast<int>(ns) - 1);
    Data data(model);
    SolveInput input(model);
    fill(input, in);
    // The caller's column order of nu is the blocks' order: compare with that order.
    Eigen::Matrix<double, 6, Eigen::Dynamic> alfa(6, m);
    Eigen::VectorXd beta(m);
    Eigen::VectorXi segs(m);
    int col = 0;
    for (const ConstraintBlock& b : input.constraints)
      for (int c = 0; c < b.columns; ++c, ++col) {
        alfa.col(col) = b.alfa.col(c);
        beta(col) = b.beta(c);
        segs(col) = b.segment;
      }
    const int rc = hd.solve(in.q, in.qd, alfa, beta, segs, in.fext, in.ff);
    const Status s = solve(model, data, input);
    REQUIRE(s.value() == rc);
    if (rc != 0) continue;  // more than 6 columns on one segment: both refuse
    CHECK(same(data.qdd(), hd.qdd()));
    CHECK(same(data.nu(), hd.nu()));
    CHECK(same(data.commandTorques(), hd.commandTorques()));
  }
}

TEST_CASE("friction through solve equals FrictionSolver") {
  RandomGen g(4);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = g.integer(1, 10);
    const KDL::Chain chain = g.chain(n);
    const int m = g.integer(0, 6);
    testutil::SolveInputs in = testutil::randomInputs(g, n, chain.getNrOfSegments(), m);
    in.segments = Eigen::VectorXi::Constant(m, static_cast<int>(chain.getNrOfSegments()) - 1);
    for (int j = 0; j < n; ++j)
      if (g.coin()) in.qd(j) = 0.0;
    FrictionModel friction;
    friction.static_friction = g.jntArray(n, 0.0, 3.0).data;
    FrictionSolver fs(chain, kUp);
    const Model model(chain);
    Data data(model);
    data.reserveFriction();
    SolveInput input(model);
    fill(input, in);
    input.friction = &friction;
    const int rc = fs.solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff, friction);
    const Status s = solve(model, data, input);
    REQUIRE(s.value() == rc);
    if (rc != 0) continue;
    CHECK(same(data.qdd(), fs.qdd()));
    CHECK(same(data.commandTorques(), fs.commandTorques()));
    CHECK(same(data.frictionTorques(), fs.frictionTorques()));
    CHECK(same(data.limitTorques(), fs.limitTorques()));
    CHECK(same(data.nu(), fs.nu()));
    CHECK(same(data.linkAccelerations(), fs.linkAccelerations()));
    CHECK(data.gaussValue() == fs.gaussValue());
    for (int j = 0; j < n; ++j) CHECK(static_cast<int>(data.jointStatus()[j]) == fs.status()[j]);
    // Held response: the sticking joints do not move (their rows vanish), and a torque on a
    // sticking joint is absorbed by its friction (its column vanishes), when G[S, S] is regular.
    Eigen::VectorXi all = Eigen::VectorXi::LinSpaced(n, 0, n - 1);
    Eigen::MatrixXd dq(n, n), dt(n, n), dq_free(n, n), dt_free(n, n);
    REQUIRE(data.responseColumnsHoldingSticking(all, dq, dt).ok());
    REQUIRE(data.responseColumns(all, dq_free, dt_free).ok());
    const double scale = std::max(1.0, dq_free.cwiseAbs().maxCoeff());
    bool any_stick = false;
    for (int j = 0; j < n; ++j) {
      if (data.jointStatus()[j] != JointStatus::Stick) continue;
      any_stick = true;
      CHECK(dq.row(j).cwiseAbs().maxCoeff() <= 1e-9 * scale);
    }
    if (!any_stick) CHECK(same(dq, dq_free));
    Eigen::MatrixXd wrong(n, n + 1);
    CHECK(data.responseColumnsHoldingSticking(all, wrong, dt).code() ==
          (any_stick ? Error::SizeMismatch : data.responseColumns(all, wrong, dt).code()));
    // The same Data without friction again: zero friction outputs, all Moving.
    input.friction = nullptr;
    REQUIRE(solve(model, data, input).ok());
    CHECK(data.frictionTorques().isZero(0.0));
    CHECK(data.jointStatus()[0] == JointStatus::Moving);
  }
}

TEST_CASE("points of blocks and frame wrenches equal tip loads shifted by KDL's FK") {
  RandomGen g(5);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = g.integer(2, 10);
    const KDL::Chain chain = g.chain(n);
    const unsigned ns = chain.getNrOfSegments();
    const Model model(chain);
    const int m = g.integer(1, 6);
    testutil::SolveInputs in = testutil::randomInputs(g, n, ns, m);
    const int seg = g.integer(0, static_cast<int>(ns) - 1), wseg = g.integer(0, static_cast<int>(ns) - 1);
    const Vector3 point = vec(g.vector(-0.5, 0.5)), wpoint = vec(g.vector(-0.5, 0.5));
    Vector6 wrench;
    for (int k = 0; k < 6; ++k) wrench(k) = g.uniform(-3.0, 3.0);
    KDL::ChainFkSolverPos_recursive fk(chain);
    KDL::JntArray q(n);
    q.data = in.q;
    KDL::Frame tip, wtip;
    REQUIRE(fk.JntToCart(q, tip, static_cast<int>(seg) + 1) >= 0);
    REQUIRE(fk.JntToCart(q, wtip, static_cast<int>(wseg) + 1) >= 0);

    SolveInput input(model);
    input.setState(JointPositions(in.q), JointVelocities(in.qd));
    input.f_ext = in.fext;
    input.ff_torques = in.ff;
    REQUIRE(input.addConstraint(seg, in.alfa, in.beta, point).ok());
    FrameRef wframe{wseg, KDL::Frame(KDL::Vector(wpoint(0), wpoint(1), wpoint(2)))};
    REQUIRE(input.addWrench(wframe, wrench).ok());
    Data data(model);
    REQUIRE(solve(model, data, input).ok());

    // The oracle: the same loads moved to the tips by hand, with KDL's rotations.
    const Vector3 r = vec(tip.M * KDL::Vector(point(0), point(1), point(2)));
    Eigen::Matrix<double, 6, Eigen::Dynamic> alfa = in.alfa;
    for (int c = 0; c < m; ++c) alfa.col(c).tail<3>() += r.cross(Vector3(alfa.col(c).head<3>()));
    const Vector3 rw = vec(wtip.M * KDL::Vector(wpoint(0), wpoint(1), wpoint(2)));
    Eigen::Matrix<double, 6, Eigen::Dynamic> fext = in.fext;
    fext.col(wseg).head<3>() += wrench.head<3>();
    fext.col(wseg).tail<3>() += wrench.tail<3>() + rw.cross(Vector3(wrench.head<3>()));
    ChainHdSolver hd(chain, kUp);
    REQUIRE(hd.solve(in.q, in.qd, alfa, in.beta, Eigen::VectorXi::Constant(m, seg), fext, in.ff) == 0);
    CHECK(close(data.qdd(), hd.qdd(), 1e-12));
    CHECK(close(data.nu(), hd.nu(), 1e-12));
    CHECK(close(data.commandTorques(), hd.commandTorques(), 1e-12));
  }
}

// The oracle of a classical set-point: beta = alfa^T [a - w x v - g; alpha] with the frame's twist
// [v; w] from KDL's velocity FK (the tip's twist moved to the point), then an ordinary solve.
TEST_CASE("classical set-points equal beta from KDL's twists, with and without friction") {
  RandomGen g(6);
  const KDL::Vector gravity(0.3, -0.2, -9.81);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = g.integer(2, 9);
    const KDL::Chain chain = g.chain(n);
    const unsigned ns = chain.getNrOfSegments();
    const Model model(chain);
    const int m = g.integer(1, 6);
    testutil::SolveInputs in = testutil::randomInputs(g, n, ns, m);
    const int seg = g.integer(0, static_cast<int>(ns) - 1);
    const Vector3 point = trial % 3 == 0 ? Vector3::Zero() : vec(g.vector(-0.5, 0.5));
    Vector6 a;
    for (int k = 0; k < 6; ++k) a(k) = g.uniform(-4.0, 4.0);
    KDL::ChainFkSolverVel_recursive fk(chain);
    KDL::JntArrayVel state(n);
    state.q.data = in.q;
    state.qdot.data = in.qd;
    KDL::FrameVel tip;
    REQUIRE(fk.JntToCart(state, tip, seg + 1) >= 0);
    const KDL::Twist t = tip.GetTwist().RefPoint(tip.M.R * KDL::Vector(point(0), point(1), point(2)));
    Vector6 spatial;
    spatial.head<3>() = a.head<3>() - vec(t.rot).cross(vec(t.vel)) - vec(gravity);
    spatial.tail<3>() = a.tail<3>();
    const Eigen::VectorXd beta = in.alfa.transpose() * spatial;
    FrictionModel friction;
    friction.static_friction = g.jntArray(n, 0.0, 2.0).data;
    for (const bool with_friction : {false, true}) {
      SolveInput classical(model), plain(model);
      for (SolveInput* input : {&classical, &plain}) {
        input->setState(JointPositions(in.q), JointVelocities(in.qd));
        input->f_ext = in.fext;
        input->ff_torques = in.ff;
        input->gravity = gravity;
        input->friction = with_friction ? &friction : nullptr;
      }
      REQUIRE(plain.addConstraint(seg, in.alfa, beta, point).ok());
      REQUIRE(classical.addConstraint(seg, in.alfa, Eigen::VectorXd::Constant(m, 1e300), point).ok());
      classical.constraints[0].classical = true;
      classical.constraints[0].classical_acceleration = a;
      Data d_classical(model), d_plain(model);
      const Status s_plain = solve(model, d_plain, plain);
      REQUIRE(solve(model, d_classical, classical).value() == s_plain.value());
      if (!s_plain) continue;
      CHECK(close(d_classical.qdd(), d_plain.qdd(), 1e-12));
      CHECK(close(d_classical.nu(), d_plain.nu(), 1e-12));
      CHECK(close(d_classical.commandTorques(), d_plain.commandTorques(), 1e-12));
    }
  }
  // A moving base or a non-finite set-point is refused.
  const KDL::Chain chain = g.chain(3);
  const Model model(chain);
  SolveInput input(model);
  REQUIRE(input.addConstraint(2, Eigen::MatrixXd::Identity(6, 1), Eigen::VectorXd::Zero(1)).ok());
  input.constraints[0].classical = true;
  Data data(model);
  REQUIRE(solve(model, data, input).ok());
  input.base_acceleration.vel(0) = 1.0;
  Status s = solve(model, data, input);
  CHECK(s.code() == Error::OutOfRange);
  CHECK(std::string(s.message()).find("base_acceleration must be zero") != std::string::npos);
  input.base_acceleration = KDL::Twist::Zero();
  input.constraints[0].classical_acceleration(2) = std::nan("");
  s = solve(model, data, input);
  CHECK(s.code() == Error::NonfiniteInput);
  CHECK(std::string(s.message()).find("classical_acceleration") != std::string::npos);
}

TEST_CASE("kinematics equal KDL's FK and Jacobians (chains and trees)") {
  RandomGen g(6);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = g.integer(1, 10);
    const KDL::Chain chain = g.chain(n);
    const Model model(chain);
    Data data(model);
    SolveInput input(model);
    input.q = g.q(n).data;
    input.q_dot = g.qdot(n).data;
    REQUIRE(solve(model, data, input).ok());
    const int last = static_cast<int>(model.nrOfSegments()) - 1;
    const FrameRef frame{last, g.frame()};
    KDL::JntArray q(n), qd(n);
    q.data = input.q;
    qd.data = input.q_dot;
    KDL::Frame tip;
    KDL::ChainFkSolverPos_recursive(chain).JntToCart(q, tip);
    const KDL::Frame pose = data.framePose(frame), expected = tip * frame.in_tip;
    CHECK(KDL::Equal(pose, expected, 1e-12));
    // KDL's Jacobian: base axes, reference point the tip origin -> moved to the frame's origin.
    KDL::Jacobian J(n);
    KDL::ChainJntToJacSolver(chain).JntToJac(q, J);
    J.changeRefPoint(tip.M * frame.in_tip.p);
    Eigen::MatrixXd mine(6, n);
    REQUIRE(data.frameJacobian(frame, mine).ok());
    CHECK(close(mine, J.data));
    const KDL::Twist t = data.frameTwist(frame);
    const Vector6 expected_twist = J.data * input.q_dot;
    CHECK(close(testutil::toVector(t), expected_twist));
  }
  for (int trial = 0; trial < 10; ++trial) {
    const KDL::Tree tree = testutil::randomTree(g, testutil::TreeSpec());
    const Model model(tree);
    const unsigned nj = model.nrOfJoints();
    Data data(model);
    SolveInput input(model);
    input.q = g.q(nj).data;
    REQUIRE(solve(model, data, input).ok());
    const int seg = g.integer(0, static_cast<int>(model.nrOfSegments()) - 1);
    const std::string& name = model.segmentNames()[seg];
    KDL::JntArray q(nj);
    q.data = input.q;
    KDL::Frame tip;
    KDL::TreeFkSolverPos_recursive(tree).JntToCart(q, tip, name);
    CHECK(KDL::Equal(data.framePose(FrameRef{seg}), tip, 1e-12));
    KDL::Jacobian J(nj);
    REQUIRE(KDL::TreeJntToJacSolver(tree).JntToJac(q, J, name) >= 0);
    Eigen::MatrixXd mine(6, nj);
    REQUIRE(data.frameJacobian(FrameRef{seg}, mine).ok());
    CHECK(close(mine, J.data));
  }
}

TEST_CASE("one Model shared by Data objects on 4 threads") {
  RandomGen g(7);
  const KDL::Tree tree = testutil::randomTree(g, testutil::TreeSpec{20});
  const Model model(tree);
  const unsigned nj = model.nrOfJoints();
  std::vector<testutil::SolveInputs> inputs;
  for (int k = 0; k < 50; ++k) {
    inputs.push_back(testutil::randomInputs(g, nj, model.nrOfSegments(), 1));
    inputs.back().segments = Eigen::VectorXi::Constant(1, static_cast<int>(model.nrOfSegments()) - 1);
  }
  auto run = [&](Eigen::MatrixXd& out) {
    Data data(model);
    SolveInput input(model);
    out.resize(nj, inputs.size());
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      fill(input, inputs[k]);
      if (solve(model, data, input).ok()) out.col(k) = data.qdd();
    }
  };
  Eigen::MatrixXd reference;
  run(reference);
  std::vector<Eigen::MatrixXd> results(4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) threads.emplace_back(run, std::ref(results[t]));
  for (std::thread& t : threads) t.join();
  for (const Eigen::MatrixXd& r : results) CHECK(same(r, reference));
}

// setState(JointVelocities, JointPositions) must not compile.
template <typename A, typename B, typename = void>
struct CanSetState : std::false_type {};
template <typename A, typename B>
struct CanSetState<A, B,
                   std::void_t<decltype(std::declval<SolveInput&>().setState(std::declval<A>(), std::declval<B>()))>>
    : std::true_type {};
static_assert(CanSetState<JointPositions, JointVelocities>::value, "the right order compiles");
static_assert(!CanSetState<JointVelocities, JointPositions>::value, "swapped q and q_dot must not compile");
static_assert(!CanSetState<Eigen::VectorXd, Eigen::VectorXd>::value, "untyped vectors must not compile");

TEST_CASE("errors: codes, sizes, values, another model's Data") {
  static_assert(static_cast<int>(Error::SizeMismatch) == KDL::SolverI::E_SIZE_MISMATCH);
  static_assert(static_cast<int>(Error::OutOfRange) == KDL::SolverI::E_OUT_OF_RANGE);
  static_assert(static_cast<int>(Error::NotUpToDate) == KDL::SolverI::E_NOT_UP_TO_DATE);
  static_assert(static_cast<int>(Error::NonfiniteInput) == HdSolver::E_NONFINITE_INPUT);
  static_assert(static_cast<int>(Error::InvalidModel) == HdSolver::E_INVALID_MODEL);
  static_assert(static_cast<int>(Error::DegenerateInertia) == HdSolver::E_DEGENERATE_INERTIA);
  static_assert(static_cast<int>(Error::TooManyConstraints) == HdSolver::E_TOO_MANY_CONSTRAINTS);
  static_assert(static_cast<int>(Error::NoSolution) == HdSolver::E_NO_SOLUTION);
  static_assert(static_cast<int>(Error::InvalidOptions) == HdSolver::E_INVALID_OPTIONS);
  static_assert(static_cast<int>(Error::NonfiniteResult) == HdSolver::E_NONFINITE_RESULT);
  static_assert(static_cast<int>(Error::ConcurrentCall) == HdSolver::E_CONCURRENT_CALL);
  static_assert(static_cast<int>(Error::StateOutOfRange) == HdSolver::E_STATE_OUT_OF_RANGE);
  static_assert(static_cast<int>(Error::InvalidFriction) == FrictionSolver::E_INVALID_FRICTION);
  static_assert(static_cast<int>(Error::NotConverged) == FrictionSolver::E_NOT_CONVERGED);

  RandomGen g(8);
  const KDL::Chain chain = g.chain(4);
  const Model model(chain), other(chain);
  Data data(model);
  SolveInput input(model);
  CHECK(solve(model, data, input).ok());

  input.q.resize(3);
  Status s = solve(model, data, input);
  CHECK(s.code() == Error::SizeMismatch);
  CHECK(std::string(s.message()) == "q has 3 entries, expected 4 (joints)");
  input.q = Eigen::VectorXd::Zero(4);
  input.q_dot(1) = std::numeric_limits<double>::quiet_NaN();
  s = solve(model, data, input);
  CHECK(s.code() == Error::NonfiniteInput);
  CHECK(std::string(s.message()) == "q_dot contains NaN or Inf");
  input.q_dot.setZero();
  input.gravity = KDL::Vector(0, 0, std::numeric_limits<double>::infinity());
  CHECK(solve(model, data, input).code() == Error::NonfiniteInput);
  input.gravity = KDL::Vector(0, 0, -9.81);

  CHECK(input.addConstraint(7, Eigen::MatrixXd::Zero(6, 1), Eigen::VectorXd::Zero(1)).code() == Error::OutOfRange);
  CHECK(input.addConstraint(0, Eigen::MatrixXd::Zero(6, 7), Eigen::VectorXd::Zero(7)).code() == Error::SizeMismatch);
  CHECK(input.addConstraint(0, Eigen::MatrixXd::Zero(6, 2), Eigen::VectorXd::Zero(1)).code() == Error::SizeMismatch);
  Eigen::MatrixXd alfa = Eigen::MatrixXd::Zero(6, 1);
  alfa(0, 0) = std::numeric_limits<double>::quiet_NaN();
  REQUIRE(input.addConstraint(3, alfa, Eigen::VectorXd::Zero(1)).ok());
  s = solve(model, data, input);
  CHECK(s.code() == Error::NonfiniteInput);
  CHECK(std::string(s.message()) == "alfa contains NaN or Inf");
  input.constraints[0].alfa(0, 0) = 1.0;
  input.constraints[0].f_ext_pass_through(0) = 2.0;
  CHECK(solve(model, data, input).code() == Error::OutOfRange);
  input.clear();

  s = solve(other, data, input);
  CHECK(s.code() == Error::NotUpToDate);
  Data bad(model, [] {
    SolverOptions o;
    o.rcond = -1.0;
    return o;
  }());
  CHECK(bad.status().code() == Error::InvalidOptions);

  FrictionModel friction;
  friction.static_friction = Eigen::VectorXd::Zero(2);
  input.friction = &friction;
  s = solve(model, data, input);
  CHECK(s.code() == Error::InvalidFriction);
  CHECK(std::string(s.message()) == "friction.static_friction has 2 entries, expected 4 (joints)");

  KDL::Chain massless;
  massless.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ)));
  const Model invalid(massless);
  const ChainHdSolver invalid_solver(massless, kUp);
  CHECK(invalid.status().value() == invalid_solver.modelError());  // a joint that moves nothing
  CHECK(std::string(invalid.status().message()) == invalid_solver.errorMessage());
  Data invalid_data(invalid);
  SolveInput invalid_input(invalid);
  CHECK(solve(invalid, invalid_data, invalid_input).code() == Error::DegenerateInertia);

  // Facade accessors: the same Model, and its Data usable through solve().
  ChainHdSolver hd(chain, kUp);
  SolveInput in2(hd.model());
  CHECK(solve(hd.model(), hd.data(), in2).ok());
  CHECK(hd.model().nrOfJoints() == 4);
}

TEST_CASE("modelFriction and an empty FrictionModel (no friction)") {
  const char* urdf = R"(<robot name="r">
    <link name="base"/>
    <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <link name="b"><inertial><origin xyz="0.2 0 0"/><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <joint name="j0" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
      <limit lower="-1" upper="2" effort="10" velocity="1"/><dynamics friction="0.7"/></joint>
    <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
      <limit lower="-0.5" upper="0.5" effort="10" velocity="1"/><dynamics friction="0.2"/></joint>
  </robot>)";
  const UrdfResult loaded = chainFromUrdfString(urdf);
  REQUIRE(loaded.ok);
  const Model model(loaded.robot);
  const FrictionModel fm = modelFriction(model);
  CHECK(fm.static_friction.isApprox(Eigen::Vector2d(0.7, 0.2)));
  CHECK(fm.lower.isApprox(Eigen::Vector2d(-1.0, -0.5)));
  CHECK(fm.upper.isApprox(Eigen::Vector2d(2.0, 0.5)));
  CHECK(!fm.empty());
  // A model from KDL objects carries no friction: an empty model, and a solve with it is the
  // frictionless solve, bit for bit, at the instant and over a time step.
  RandomGen g(9);
  const Model kmodel(g.chain(4));
  const FrictionModel none = modelFriction(kmodel);
  CHECK(none.empty());
  Data plain(kmodel), with_empty(kmodel);
  SolveInput in(kmodel);
  in.q = g.q(4).data;
  in.q_dot = g.qdot(4).data;
  REQUIRE(solve(kmodel, plain, in));
  in.friction = &none;
  for (const double dt : {0.0, 1e-3}) {
    in.time_step = dt;
    REQUIRE(solve(kmodel, with_empty, in));
    CHECK((with_empty.qdd().array() == plain.qdd().array()).all());
    CHECK((with_empty.frictionTorques().array() == 0.0).all());
  }
  // The friction solver's own face takes it too.
  FrictionSolver fs(g.chain(3), KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()));
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
  CHECK(fs.solve(q, q, Eigen::MatrixXd(6, 0), Eigen::VectorXd(0), Eigen::MatrixXd(6, 0), q, FrictionModel()) == 0);
}
