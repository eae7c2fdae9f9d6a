// task.hpp's array entry points of the Python face's beta_for: betaShape's accepted shapes (and
// everything it refuses), betaFromArrays equal to betaFromClassical row by row, and its overflow.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "vereshchagin/task.hpp"

namespace {

namespace vs = vereshchagin;

vs::ArrayArg array(const std::vector<double>& v, std::initializer_list<long> shape) {
  vs::ArrayArg a;
  a.data = v.data();
  for (const long d : shape) a.shape[a.ndim++] = d;
  return a;
}

std::vector<double> ramp(int n, double step) {
  std::vector<double> v;
  for (int k = 0; k < n; ++k) v.push_back(step * (k - n / 2));
  return v;
}

}  // namespace

TEST_CASE("betaShape takes alpha (6,) or (6, m) and one twist or rows of them") {
  const std::vector<double> alfa = ramp(12, 0.1), acc = ramp(6, 0.5), tw = ramp(6, 0.3), rows = ramp(18, 0.2),
                            g{0.0, 0.0, -9.81};
  int ndim = 0;
  long shape[2];
  REQUIRE(vs::betaShape(array(alfa, {6, 2}), array(acc, {6}), array(tw, {6}), array(g, {3}), ndim, shape));
  CHECK((ndim == 1 && shape[0] == 2));
  REQUIRE(vs::betaShape(array(alfa, {6}), array(acc, {6}), array(rows, {3, 6}), array(g, {3}), ndim, shape));
  CHECK((ndim == 2 && shape[0] == 3 && shape[1] == 1));
  REQUIRE(vs::betaShape(array(alfa, {6, 2}), array(rows, {3, 6}), array(rows, {3, 6}), array(g, {3}), ndim, shape));
  CHECK((ndim == 2 && shape[0] == 3 && shape[1] == 2));
  CHECK_FALSE(vs::betaShape(array(alfa, {2, 6}), array(acc, {6}), array(tw, {6}), array(g, {3}), ndim, shape));
  CHECK_FALSE(vs::betaShape(array(alfa, {6, 2}), array(acc, {3}), array(tw, {6}), array(g, {3}), ndim, shape));
  CHECK_FALSE(vs::betaShape(array(alfa, {6, 2}), array(rows, {3, 6}), array(tw, {6}), array(g, {3}), ndim, shape));
  CHECK_FALSE(vs::betaShape(array(alfa, {6, 2}), array(acc, {6}), array(tw, {6}), array(g, {2}), ndim, shape));
  std::vector<double> nan_acc = acc;
  nan_acc[4] = NAN;
  CHECK_FALSE(vs::betaShape(array(alfa, {6, 2}), array(nan_acc, {6}), array(tw, {6}), array(g, {3}), ndim, shape));
}

TEST_CASE("betaFromArrays is betaFromClassical per row, and reports an overflow") {
  const std::vector<double> alfa = ramp(12, 0.1), rows = ramp(18, 0.2), twists = ramp(18, -0.15), g{0.5, 0.0, -9.81};
  std::vector<double> beta(6);
  REQUIRE(
      vs::betaFromArrays(array(alfa, {6, 2}), array(rows, {3, 6}), array(twists, {3, 6}), array(g, {3}), beta.data()));
  const Eigen::Matrix<double, 6, 2> A = Eigen::Map<const Eigen::Matrix<double, 2, 6>>(alfa.data()).transpose();
  for (int r = 0; r < 3; ++r) {
    Eigen::VectorXd expected(2);
    vs::betaFromClassical(A, Eigen::Map<const vs::Vector6>(rows.data() + 6 * r),
                          Eigen::Map<const vs::Vector6>(twists.data() + 6 * r), KDL::Vector(0.5, 0.0, -9.81), expected);
    CHECK(std::abs(beta[2 * r] - expected(0)) <= 1e-12 * (1.0 + std::abs(expected(0))));
    CHECK(std::abs(beta[2 * r + 1] - expected(1)) <= 1e-12 * (1.0 + std::abs(expected(1))));
  }
  const std::vector<double> big(6, 1e308), acc{1e308, 1e308, 0, 0, 0, 0}, tw(6, 0.0);
  CHECK_FALSE(vs::betaFromArrays(array(big, {6}), array(acc, {6}), array(tw, {6}), array(g, {3}), beta.data()));
}
