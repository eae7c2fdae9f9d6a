// The batch API (batch.hpp): rows of strided inputs solved over threads equal solve() of each
// row bit for bit, shared arguments (stride 0) read by every row, friction per row, the lowest
// failing row reported with solve()'s message, and the value checks of solve() that the Python
// package reports (pass-through weights, column capacity, friction values).
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "random_chain.hpp"
#include "vereshchagin/batch.hpp"
#include "vereshchagin/data.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

// B rows of random q, qd, tau on an n-joint chain, one constraint column on the last segment.
struct Rows {
  Rows(int n, int ns, int B, RandomGen& g) : q(B * n), qd(B * n), tau(B * n), alpha(6), beta(B) {
    for (double& x : q) x = g.uniform(-1.0, 1.0);
    for (double& x : qd) x = g.uniform(-1.0, 1.0);
    for (double& x : tau) x = g.uniform(-2.0, 2.0);
    for (double& x : beta) x = g.uniform(-1.0, 1.0);
    alpha = {0.0, 0.0, 1.0, 0.0, 0.0, 0.0};
    input.rows = B;
    input.q = {q.data(), n};
    input.q_dot = {qd.data(), n};
    input.ff_torques = {tau.data(), n};
    input.blocks.push_back(BlockRows{ns - 1, 1, Vector3::Zero(), {alpha.data(), 0}, {beta.data(), 1}, {}});
  }
  std::vector<double> q, qd, tau, alpha, beta;
  BatchInput input;
};

struct Outputs {
  Outputs(int n, int ns, int B) : qdd(B * n), tau(B * n), nu(B), acc(B * 6 * (ns + 1)), smin(B), rank(B) {}
  BatchOutput out() { return {qdd.data(), tau.data(), nu.data(), acc.data(), smin.data(), rank.data()}; }
  std::vector<double> qdd, tau, nu, acc, smin;
  std::vector<int> rank;
};

}  // namespace

TEST_CASE("solveBatch equals solve() row by row, whatever the threads") {
  RandomGen g(7);
  const Model model(g.chain(6));
  const int n = 6, ns = static_cast<int>(model.nrOfSegments()), B = 9;
  Rows rows(n, ns, B, g);
  Outputs single(n, ns, B);
  BatchWorkspace w(model, SolverOptions(), KDL::Vector(0, 0, -9.81));
  for (int b = 0; b < B; ++b) {
    rows.input.fillRow(b, w.input);
    REQUIRE(solve(model, w.data, w.input).ok());
    REQUIRE(single.out().write(b, w.data, 1, false));
  }
  for (int threads : {1, 2, 4}) {
    std::vector<BatchWorkspace> pool;
    pool.reserve(threads);
    std::vector<BatchWorkspace*> ws;
    for (int t = 0; t < threads; ++t)
      ws.push_back(&pool.emplace_back(model, SolverOptions(), KDL::Vector(0, 0, -9.81)));
    Outputs batch(n, ns, B);
    const BatchFailure f = solveBatch(model, rows.input, batch.out(), ws);
    CHECK_MESSAGE(f.ok(), f.message);
    CHECK(batch.qdd == single.qdd);
    CHECK(batch.tau == single.tau);
    CHECK(batch.nu == single.nu);
    CHECK(batch.acc == single.acc);
    CHECK(ws[0]->data.qdd() == Eigen::Map<const Eigen::VectorXd>(&single.qdd[(B - 1) * n], n));  // the last row
  }
}

TEST_CASE("solveBatch reports the lowest failing row with solve()'s message") {
  RandomGen g(8);
  const Model model(g.chain(5));
  const int n = 5, ns = static_cast<int>(model.nrOfSegments()), B = 6;
  Rows rows(n, ns, B, g);
  rows.qd[4 * n + 1] = std::nan("");
  rows.qd[2 * n] = std::nan("");
  std::vector<BatchWorkspace> pool;
  pool.reserve(3);
  std::vector<BatchWorkspace*> ws;
  for (int t = 0; t < 3; ++t) ws.push_back(&pool.emplace_back(model, SolverOptions(), KDL::Vector(0, 0, -9.81)));
  Outputs out(n, ns, B);
  const BatchFailure f = solveBatch(model, rows.input, out.out(), ws);
  CHECK(f.row == 2);
  CHECK_MESSAGE(f.message.rfind("batch row 2: ", 0) == 0, f.message);
  CHECK_MESSAGE(f.message.find("q_dot") != std::string::npos, f.message);
}

TEST_CASE("friction per row: rows without friction get NaN and -1 in the friction outputs") {
  RandomGen g(9);
  const Model model(g.chain(4));
  const int n = 4, ns = static_cast<int>(model.nrOfSegments()), B = 2;
  Rows rows(n, ns, B, g);
  FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::Constant(n, 0.5);
  rows.input.friction = {&fm, nullptr};
  Outputs out(n, ns, B);
  std::vector<double> fr(B * n), lim(B * n), gauss(B);
  std::vector<int> status(B * n), iters(B);
  BatchOutput o = out.out();
  o.friction_torque = fr.data();
  o.limit_torque = lim.data();
  o.gauss_value = gauss.data();
  o.status = status.data();
  o.iterations = iters.data();
  BatchWorkspace w(model, SolverOptions(), KDL::Vector(0, 0, -9.81));
  const BatchFailure f = solveBatch(model, rows.input, o, {&w});
  REQUIRE_MESSAGE(f.ok(), f.message);
  CHECK(std::isfinite(gauss[0]));
  CHECK(iters[0] >= 0);
  CHECK(std::isnan(gauss[1]));
  CHECK(iters[1] == -1);
  CHECK(status[n] == -1);
  CHECK(std::isnan(fr[n]));
}

TEST_CASE("solve() checks weights, capacity and friction values with the Python package's wording") {
  RandomGen g(10);
  const Model model(g.chain(3));
  Data data(model);
  SolveInput in(model);
  Eigen::MatrixXd alfa = Eigen::MatrixXd::Zero(6, 2);
  alfa(2, 0) = alfa(3, 1) = 1.0;
  REQUIRE(in.addConstraint(2, alfa, Eigen::VectorXd::Zero(2)).ok());
  auto message = [&] { return std::string(solve(model, data, in).message()); };
  in.constraints[0].f_ext_pass_through(1) = 1.5;
  CHECK(message() ==
        "f_ext_pass_through[1] must be in [0, 1] (0: the constraint compensates that driver, 1: its effect passes "
        "through), got 1.5");
  in.constraints[0].f_ext_pass_through(1) = 0.0;
  in.constraints[0].ff_pass_through(0) = -1.0;
  CHECK(message().rfind("tau_ff_pass_through[0] (ff_pass_through) must be in [0, 1]", 0) == 0);
  in.constraints[0].ff_pass_through(0) = 0.0;
  Data capped(model, [] {
    SolverOptions o;
    o.max_constraints = 1;
    return o;
  }());
  CHECK(std::string(solve(model, capped, in).message())
            .rfind("this solve has 2 constraint columns; the solver takes "
                   "at most 1 in all",
                   0) == 0);
  FrictionModel fm;
  fm.static_friction = Eigen::VectorXd::Ones(3);
  fm.kinetic_friction = Eigen::VectorXd::Constant(3, 2.0);
  in.friction = &fm;
  CHECK(message() ==
        "friction.kinetic[0] (kinetic_friction(0)) must be in [0, friction.static[0] = 1] (kinetic <= static), got 2");
  fm.kinetic_friction.resize(0);
  fm.static_friction(1) = -1.0;
  CHECK(message() == "friction.static[1] (static_friction(1)) must be finite and >= 0, got -1");
  fm.static_friction(1) = 1.0;
  fm.lower = Eigen::VectorXd::Ones(3);
  fm.upper = -Eigen::VectorXd::Ones(3);
  CHECK(message().find("friction.lower[0] and friction.upper[0]") == 0);
  CHECK(message().find("got 1 > -1") != std::string::npos);
}

TEST_CASE("secondsPerSolve times row 0 and leaves its state, NaN when it fails") {
  RandomGen g(9);
  const Model model(g.chain(4));
  const int n = 4, ns = static_cast<int>(model.nrOfSegments());
  Rows rows(n, ns, 2, g);
  BatchWorkspace w(model, SolverOptions(), KDL::Vector(0, 0, -9.81));
  const double seconds = secondsPerSolve(model, rows.input, w, 3);
  CHECK(std::isfinite(seconds));
  CHECK(seconds > 0.0);
  Outputs timed(n, ns, 1), single(n, ns, 1);
  REQUIRE(timed.out().write(0, w.data, 1, false));
  BatchWorkspace fresh(model, SolverOptions(), KDL::Vector(0, 0, -9.81));
  rows.input.fillRow(0, fresh.input);
  REQUIRE(solve(model, fresh.data, fresh.input).ok());
  REQUIRE(single.out().write(0, fresh.data, 1, false));
  CHECK(timed.qdd == single.qdd);
  rows.q[1] = std::nan("");
  CHECK(std::isnan(secondsPerSolve(model, rows.input, w, 2)));
}

TEST_CASE("PackedRow: offsets, length, description and the output it writes") {
  const PackedRow plain{3, 2, 1, false}, fr{3, 2, 1, true};
  CHECK(plain.offset(PackedRow::Nu) == 6);
  CHECK(plain.offset(PackedRow::LinkAcc) == 7);
  CHECK(plain.offset(PackedRow::End) == 7 + 18);
  CHECK(fr.offset(PackedRow::Status) == 25 + 6);
  CHECK(fr.offset(PackedRow::End) == 25 + 6 + 2);  // 3 int32 in 2 doubles
  CHECK(fr.describe() == "n_joints = 3, n_segments = 2, m = 1 with friction");
  CHECK(!(plain == fr));
  CHECK(plain == PackedRow{3, 2, 1, false});
  CHECK(fr.plausible());
  CHECK(!PackedRow{3, 2, 13, false}.plausible());  // more than 6 columns per segment
  CHECK(!PackedRow{-1, 2, 1, false}.plausible());
  CHECK(!PackedRow{3, 1L << 25, 1, false}.plausible());
  std::vector<double> buffer(static_cast<std::size_t>(fr.offset(PackedRow::End)));
  double smin = 0.0, gauss = 0.0;
  int rank = 0, iterations = 0, outcome = 0;
  const BatchOutput o = fr.output(buffer.data(), &smin, &rank, &gauss, &iterations, &outcome);
  CHECK(o.nu == buffer.data() + 6);
  CHECK(reinterpret_cast<double*>(o.status) == buffer.data() + 31);
  CHECK(o.gauss_value == &gauss);
  CHECK(o.contact_force == nullptr);
  CHECK(plain.output(buffer.data(), &smin, &rank, &gauss, &iterations, &outcome).friction_torque == nullptr);
  CHECK(plain.output(buffer.data(), &smin, &rank, &gauss, &iterations, &outcome).limit_torque == nullptr);
  // Contacts after the friction outputs: 3 doubles of force each, then their statuses as int32.
  const PackedRow ct{3, 2, 1, true, 3};
  CHECK(ct.offset(PackedRow::ContactForce) == fr.offset(PackedRow::End));
  CHECK(ct.offset(PackedRow::ContactStatus) == fr.offset(PackedRow::End) + 9);
  CHECK(ct.offset(PackedRow::End) == fr.offset(PackedRow::End) + 9 + 2);
  CHECK(ct.describe() == "n_joints = 3, n_segments = 2, m = 1 with friction, 3 contacts");
  CHECK(!(ct == fr));
  CHECK(!PackedRow{3, 2, 1, false, -1}.plausible());
  std::vector<double> contact_buffer(static_cast<std::size_t>(ct.offset(PackedRow::End)));
  const BatchOutput oc = ct.output(contact_buffer.data(), &smin, &rank, &gauss, &iterations, &outcome);
  CHECK(oc.contact_force == contact_buffer.data() + ct.offset(PackedRow::ContactForce));
  CHECK(reinterpret_cast<double*>(oc.contact_status) == contact_buffer.data() + ct.offset(PackedRow::ContactStatus));
  CHECK(oc.contact_outcome == &outcome);
}
