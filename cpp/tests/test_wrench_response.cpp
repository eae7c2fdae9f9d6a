// Data::wrenchResponseColumns(): the affine response of a solve to wrenches on segments, against
// (a) the response to joint torques (responseColumns, all joints: the constrained inverse inertia
// G) times the wrench's generalised force J^T w (J: frameJacobian of the segment's tip frame), and
// (b) differences of full solves with and without the wrench in f_ext (the map is affine: only
// round-off separates them). Random chains and trees, constraints on any segments, columns in any
// order.
#include <doctest/doctest.h>

#include "random_chain.hpp"
#include "random_tree.hpp"
#include "vereshchagin/data.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

double relErr(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

// Solves `input` on a random model and checks k random wrench columns both ways; returns the worst
// relative errors (a), (b).
std::pair<double, double> checkModel(RandomGen& g, const Model& model, const std::string& tag) {
  const int n = static_cast<int>(model.nrOfJoints()), ns = static_cast<int>(model.nrOfSegments());
  const testutil::SolveInputs in = testutil::randomInputs(g, n, ns, 0);
  SolveInput input(model);
  input.setState(JointPositions(in.q), JointVelocities(in.qd));
  input.f_ext = in.fext;
  input.ff_torques = in.ff;
  const int blocks = g.integer(0, std::min(2, n));
  for (int b = 0; b < blocks; ++b) {
    const int cols = g.integer(1, std::max(1, std::min(3, n / 2)));
    const Eigen::MatrixXd alfa = g.alfa(cols).data;
    const Eigen::VectorXd beta = g.beta(cols).data;
    REQUIRE(input.addConstraint(g.integer(0, ns - 1), alfa, beta));
  }
  Data data(model), other(model);
  const Status s = solve(model, data, input);
  REQUIRE_MESSAGE(s, tag << ": " << s.message());
  const int k = g.integer(1, 8);
  Eigen::VectorXi segs(k);
  Matrix6X w(6, k);
  for (int c = 0; c < k; ++c) {
    segs(c) = g.integer(0, ns - 1);
    w.col(c) = testutil::toMatrix(g.fext(1)).col(0);
  }
  const Eigen::VectorXd qdd0 = data.qdd();
  Eigen::MatrixXd dqdd = Eigen::MatrixXd::Constant(n, k, NAN);
  REQUIRE(data.wrenchResponseColumns(segs, w, dqdd));
  CHECK(data.qdd() == qdd0);
  // (a) G J^T w.
  Eigen::VectorXi all(n);
  for (int j = 0; j < n; ++j) all(j) = j;
  Eigen::MatrixXd G(n, n), dtau(n, n), J(6, n), expect_a(n, k), expect_b(n, k);
  REQUIRE(data.responseColumns(all, G, dtau));
  for (int c = 0; c < k; ++c) {
    REQUIRE(data.frameJacobian(FrameRef{segs(c), KDL::Frame::Identity()}, J));
    expect_a.col(c) = G * (J.transpose() * w.col(c));
    // (b) the solve with the wrench added.
    SolveInput more = input;
    more.f_ext.col(segs(c)) += w.col(c);
    REQUIRE(solve(model, other, more));
    expect_b.col(c) = other.qdd() - qdd0;
  }
  return {relErr(dqdd, expect_a), relErr(dqdd, expect_b)};
}

}  // namespace

TEST_CASE("wrench response equals G J^T w and differences of solves, chains and trees") {
  RandomGen g(20261126);
  double worst_a = 0.0, worst_b = 0.0;
  for (int trial = 0; trial < 60; ++trial) {
    const bool tree = trial % 2 == 1;
    const int n = g.integer(1, 12);
    testutil::TreeSpec spec;
    spec.n_joints = n;
    const Model model = tree ? Model(testutil::randomTree(g, spec)) : Model(g.chain(n));
    REQUIRE(model.status());
    const auto errors = checkModel(g, model, (tree ? "tree " : "chain ") + std::to_string(trial));
    const double a = errors.first, b = errors.second;  // (a structured binding: see held_chain.hpp)
    CHECK_MESSAGE(a <= 1e-9, "trial " << trial << ": against G J^T w " << a);
    CHECK_MESSAGE(b <= 1e-9, "trial " << trial << ": against solves " << b);
    worst_a = std::max(worst_a, a);
    worst_b = std::max(worst_b, b);
  }
  MESSAGE("worst relative error: G J^T w " << worst_a << ", solves " << worst_b);
}

TEST_CASE("wrench response refuses bad arguments and needs a solve") {
  RandomGen g(7);
  const Model model(g.chain(4));
  Data data(model);
  Eigen::VectorXi segs(1);
  segs << 0;
  Matrix6X w = Matrix6X::Zero(6, 1);
  Eigen::MatrixXd dqdd(4, 1);
  CHECK(data.wrenchResponseColumns(segs, w, dqdd).code() == Error::NoSolution);
  SolveInput input(model);
  REQUIRE(solve(model, data, input));
  segs << 9;
  CHECK(data.wrenchResponseColumns(segs, w, dqdd).code() == Error::OutOfRange);
  Eigen::MatrixXd wrong(3, 1);
  segs << 0;
  CHECK(data.wrenchResponseColumns(segs, w, wrong).code() == Error::SizeMismatch);
}
