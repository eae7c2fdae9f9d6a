// BatchArgs (batch_args.hpp): arrays checked into the rows of a BatchInput, shared or with a batch
// axis, and the messages the Python package reports for shapes, non-finite values, batch sizes,
// constraint columns per segment and repeated frames, and the arrays of a friction model.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "random_chain.hpp"
#include "vereshchagin/batch_args.hpp"

using namespace vereshchagin;
using testutil::RandomGen;

namespace {

ArrayArg array(const std::vector<double>& v, std::vector<long> shape) {
  ArrayArg a;
  a.data = v.data();
  a.ndim = static_cast<int>(shape.size());
  for (int k = 0; k < a.ndim; ++k) a.shape[k] = shape[k];
  return a;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("shared and batched rows get strides, and one batch size") {
  RandomGen g(1);
  const Model model(g.chain(3));
  BatchArgs args;
  args.start(true, model);
  const std::vector<double> q(4 * 3, 0.5), qd(3, 0.0), bad_rows(5 * 3, 0.0);
  CHECK(args.vector(args.input.q, "q", array(q, {4, 3}), 3) == "");
  CHECK(args.input.rows == 4);
  CHECK(args.input.q.stride == 3);
  CHECK(args.vector(args.input.q_dot, "qd", array(qd, {3}), 3) == "");
  CHECK(args.input.q_dot.stride == 0);
  const std::string why = args.vector(args.input.ff_torques, "tau_ff", array(bad_rows, {5, 3}), 3);
  CHECK(why == "tau_ff has a batch axis (axis 0) of 5 rows (shape (5, 3)), but q (4, 3) has 4");
  args.start(false, model);  // one solve: no batch axis
  CHECK(contains(args.vector(args.input.q, "q", array(q, {4, 3}), 3), "q must have shape (3,), got (4, 3)"));
}

TEST_CASE("non-finite values name the row and the flat index within it") {
  RandomGen g(2);
  const Model model(g.chain(2));
  BatchArgs args;
  args.start(true, model);
  std::vector<double> q(3 * 2, 0.0);
  q[5] = std::nan("");
  CHECK(args.vector(args.input.q, "q", array(q, {3, 2}), 2) == "batch row 2: q contains NaN or Inf (flat index 1)");
  std::vector<double> beta(3, 1.0);
  args.start(true, model);
  CHECK(args.vector(args.input.q, "beta", array(beta, {3}), 1, true) == "");  // (B,) for one column
  CHECK(args.input.rows == 3);
}

TEST_CASE("blocks: columns, set-points, columns per segment and one entry per frame") {
  RandomGen g(3);
  const Model model(g.chain(3));
  BatchArgs args;
  args.start(false, model);
  const std::vector<double> alpha(6 * 4, 0.0), beta(4, 0.0), seven(6 * 7, 0.0);
  CHECK(args.block(2, array(seven, {6, 7}), "alpha") == "alpha has 7 columns; at most 6 constraints per segment");
  args.start(false, model);
  CHECK(args.block(2, array(alpha, {6, 4}), "alpha") == "");
  CHECK(args.setPoint(nullptr, false, "beta", "") == "beta is required when alpha is given (shape (4,))");
  const ArrayArg b = array(beta, {4});
  CHECK(args.setPoint(&b, false, "beta", "") == "");
  CHECK(args.columns == 4);
  CHECK(args.frame(2, Vector3(0.0, 0.0, 0.1), "constraints['a']") == "");
  CHECK(args.block(2, array(alpha, {6, 4}), "constraints['a'] alpha") == "");
  const std::string why = args.setPoint(&b, false, "constraints['a'] beta", "constraints['a']");
  CHECK(contains(why, "constraints['a']: more than 6 constraint columns on segment '"));
  CHECK(contains(why, "(alpha and every key on it count)"));
  CHECK(args.frame(2, Vector3(0.0, 0.0, 0.1), "constraints[-1]") ==
        "constraints[-1]: the same frame as constraints['a'] (one entry per frame: put all its columns in one alpha)");
  CHECK(args.frame(1, Vector3(0.0, 0.0, 0.1), "constraints[1]") == "");
}

TEST_CASE("a classical set-point is (6,) and finite") {
  RandomGen g(4);
  const Model model(g.chain(2));
  BatchArgs args;
  args.start(false, model);
  std::vector<double> alpha(6, 0.0), acc(6, 0.0);
  CHECK(args.block(1, array(alpha, {6}), "alpha") == "");  // (6,): one column
  CHECK(args.input.blocks.back().columns == 1);
  acc[3] = std::nan("");
  const ArrayArg a = array(acc, {6});
  CHECK(args.setPoint(&a, true, "a_desired", "") == "a_desired must be finite (no NaN or Inf), flat index 3");
  acc[3] = 0.0;
  CHECK(args.setPoint(&a, true, "a_desired", "") == "");
  CHECK(args.input.blocks.back().classical.data == acc.data());
}

TEST_CASE("friction arrays: shapes, NaN in limits, one-sided limits") {
  FrictionModel fm;
  const std::vector<double> f(3, 0.5), two(2, 0.5), lower{-1.0, -std::numeric_limits<double>::infinity(), 0.0};
  CHECK(frictionFromArrays(fm, 3, array(two, {2}), nullptr, 1e-6, nullptr, nullptr, 0.0) ==
        "friction.static must have shape (3,), got (2,)");
  const ArrayArg lo = array(lower, {3});
  CHECK(frictionFromArrays(fm, 3, array(f, {3}), nullptr, 1e-5, &lo, nullptr, 1e-3) == "");
  CHECK(fm.kinetic_friction.size() == 0);
  CHECK(fm.velocity_tolerance == 1e-5);
  CHECK(fm.lower(0) == -1.0);
  CHECK(fm.upper(2) == std::numeric_limits<double>::infinity());
  CHECK(fm.limit_tolerance == 1e-3);
  std::vector<double> bad = lower;
  bad[1] = std::nan("");
  const ArrayArg up = array(bad, {3});
  CHECK(frictionFromArrays(fm, 3, array(f, {3}), nullptr, 1e-6, nullptr, &up, 0.0) == "friction.upper contains NaN");
  CHECK(frictionFromArrays(fm, 3, array(f, {3}), nullptr, 1e-6, nullptr, nullptr, 0.0) == "");
  CHECK(fm.lower.size() == 0);
}

TEST_CASE("friction of the joints: their static friction and limits") {
  std::vector<JointInfo> joints(2);
  joints[0].friction = 0.5;
  joints[0].lower = -1.0;
  joints[1].upper = 2.0;
  const FrictionModel fm = frictionOfJoints(joints);
  CHECK(fm.static_friction(0) == 0.5);
  CHECK(fm.static_friction(1) == 0.0);
  CHECK(fm.kinetic_friction.size() == 0);
  CHECK(fm.lower(0) == -1.0);
  CHECK(fm.lower(1) == -std::numeric_limits<double>::infinity());
  CHECK(fm.upper(1) == 2.0);
  CHECK(fm.velocity_tolerance == FrictionModel().velocity_tolerance);
  CHECK(frictionOfJoints({}).static_friction.size() == 0);
}

TEST_CASE("end-segment arguments: alpha on a tree, beta with a_desired, a set-point without alpha") {
  CHECK(endBlockArgs(false, false, false, true) == "");
  CHECK(endBlockArgs(true, true, false, false) == "");
  CHECK(endBlockArgs(true, false, true, false) == "");
  CHECK(contains(endBlockArgs(true, true, false, true), "a Tree has no last segment"));
  CHECK(contains(endBlockArgs(true, true, true, false), "beta and a_desired given"));
  CHECK(endBlockArgs(false, true, false, false) == "beta given without alpha");
  CHECK(endBlockArgs(false, true, true, false) == "a_desired given without alpha");
}
