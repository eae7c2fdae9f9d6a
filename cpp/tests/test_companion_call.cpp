// companion_call.hpp and array_arg.hpp: the Python face's companions on row-major arrays. Every
// argument check with its message, the result shapes, the results equal (bit for bit) to the
// kinematics and dynamics functions called directly, f_ext as rows or as frame wrenches, and an
// overflow reported under the companion's Python name.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "kuka_lwr4.hpp"
#include "vereshchagin/companion_call.hpp"

namespace {

namespace vs = vereshchagin;
using vs::Companion;
using vs::CompanionArg;

vs::ArrayArg array(const std::vector<double>& v, std::initializer_list<long> shape) {
  vs::ArrayArg a;
  a.data = v.data();
  for (const long d : shape) a.shape[a.ndim++] = d;
  return a;
}

// Checks every argument the test gives, then the shape; the first failure's status.
vs::Status prepare(vs::KinematicsData& kd, vs::CompanionCall& call, int& ndim, long shape[3]) {
  for (int k = 0; k < 5; ++k)
    if (call.args[k].data)
      if (const vs::Status s = vs::checkCompanionArg(kd, call, static_cast<CompanionArg>(k)); !s) return s;
  return vs::companionShape(kd, call, ndim, shape);
}

struct Arm {
  vs::Model model{testutil::kukaLwr4()};
  vs::DynamicsData dd{model};
  long n = static_cast<long>(model.nrOfJoints()), ns = static_cast<long>(model.nrOfSegments());
  std::vector<double> q, qd, qdd, g{0.0, 0.0, -9.81};
  Arm() {
    for (long j = 0; j < n; ++j) {
      q.push_back(0.3 * static_cast<double>(j) - 0.7);
      qd.push_back(0.2 - 0.1 * static_cast<double>(j));
      qdd.push_back(0.5 * std::sin(static_cast<double>(j)));
    }
  }
  // The message of the first failure of `call` ("" if it passes every check).
  std::string failure(vs::CompanionCall call) {
    int ndim = 0;
    long shape[3];
    const vs::Status s = prepare(dd.kinematics(), call, ndim, shape);
    return s ? "" : s.message();
  }
};

}  // namespace

TEST_CASE("array arguments print their shapes and name what is wrong with them") {
  const std::vector<double> v{1.0, NAN, 3.0, 4.0, 5.0, 6.0};
  CHECK(array(v, {}).shapeString() == "()");
  CHECK(array(v, {6}).shapeString() == "(6,)");
  CHECK(array(v, {2, 3}).shapeString() == "(2, 3)");
  CHECK(array(v, {1, 2, 3}).size() == 6);
  CHECK(vs::nonfiniteMessage(array(v, {6}), "x") == "x contains NaN or Inf (flat index 1)");
  CHECK(vs::vectorMessage(array(v, {2, 3}), "x", 6) == "x must have shape (6,), got (2, 3)");
  CHECK(vs::vectorMessage(array(v, {6}), "x", 6) == "x contains NaN or Inf (flat index 1)");
  CHECK(vs::vectorMessage(array(v, {1}), "x", 1).empty());
}

TEST_CASE("arguments that are no real array are named with why") {
  CHECK(vs::notArrayMessage("q", true) == "q must be a real array, got None");
  CHECK(vs::notArrayMessage("q", false) == "q must be a real number or array, got bool");
  CHECK(vs::unconvertedMessage("q", "list", "") == "q must be a real array (numbers of equal-length rows), got list");
  CHECK(vs::unconvertedMessage("q", "list", "ValueError: ragged") ==
        "q must be a real array (numbers of equal-length rows), got list (its conversion raised ValueError: ragged)");
  CHECK(vs::dtypeMessage("q", 'c', "complex128", 1) == "q must hold real numbers (int or float), got dtype complex128");
  CHECK(vs::dtypeMessage("q", 'f', "float32", 4) == "q has 4 dimensions; at most 3 are meaningful");
  CHECK(vs::dtypeMessage("q", 'u', "uint8", 3).empty());
  CHECK(vs::realDtype('i', 0));
  CHECK(!vs::realDtype('b', 1));
  CHECK(!vs::realDtype('f', 4));
}

TEST_CASE("companion arguments are checked in order with the Python messages") {
  Arm arm;
  const std::vector<double> short_q(static_cast<std::size_t>(arm.n - 1), 0.0), rows(2 * arm.n, 0.0);
  std::vector<double> bad_qd = arm.qd;
  bad_qd[2] = INFINITY;
  const std::string n = std::to_string(arm.n), ns = std::to_string(arm.ns);
  vs::CompanionCall call{Companion::MassMatrix};
  call.args[0] = array(short_q, {arm.n - 1});
  CHECK(arm.failure(call) == "q must have shape (" + n + ",), got (" + std::to_string(arm.n - 1) + ",)");
  call.args[0] = array(rows, {2, arm.n});
  CHECK(arm.failure(call) == "q must have shape (" + n + ",), got (2, " + n + ")");
  call.kind = Companion::Fk;  // fk and twist take one state per row
  CHECK(arm.failure(call).empty());
  call = vs::CompanionCall{Companion::CoriolisTorques};
  call.args[0] = array(arm.q, {arm.n});
  call.args[1] = array(bad_qd, {arm.n});
  CHECK(arm.failure(call) == "qd contains NaN or Inf (flat index 2)");
  call = vs::CompanionCall{Companion::InverseDynamics};
  call.args[0] = array(arm.q, {arm.n});
  call.args[1] = array(arm.qd, {arm.n});
  call.args[2] = array(arm.qdd, {arm.n});
  call.args[3] = array(arm.g, {2});
  CHECK(arm.failure(call) == "gravity must have shape (3,), got (2,)");
  call.args[3] = array(arm.g, {3});
  call.args[4] = array(rows, {arm.ns, 2});
  CHECK(arm.failure(call) ==
        "f_ext must have shape (" + ns + ", 6) or be a dict {segment: wrench (6,)}, got (" + ns + ", 2)");
  call = vs::CompanionCall{Companion::Twist};
  const std::vector<double> three(3 * arm.n, 0.0);
  call.args[0] = array(rows, {2, arm.n});
  call.args[1] = array(three, {3, arm.n});
  CHECK(arm.failure(call) == "q and qd must have the same shape, got 2 and 3 rows");
  call.args[1] = array(arm.qd, {arm.n});
  CHECK(arm.failure(call) == "q and qd must have the same shape, got 2 and 1 rows");
  CHECK(std::string(vs::companionName(Companion::JacobianDotTimesQd)) == "jacobian_dot_times_qd");
  CHECK(std::string(vs::companionArgName(CompanionArg::FExt)) == "f_ext");
}

TEST_CASE("companion calls equal the kinematics and dynamics functions bit for bit") {
  Arm arm;
  const vs::JointPositions q(Eigen::Map<const Eigen::VectorXd>(arm.q.data(), arm.n));
  const vs::JointVelocities qd(Eigen::Map<const Eigen::VectorXd>(arm.qd.data(), arm.n));
  const vs::JointAccelerations qdd(Eigen::Map<const Eigen::VectorXd>(arm.qdd.data(), arm.n));
  const vs::FrameRef frame{static_cast<int>(arm.ns) - 2,
                           KDL::Frame(KDL::Rotation::RotY(0.4), KDL::Vector(0.1, 0, 0.2))};
  const auto run = [&](Companion kind, std::vector<double>& out) {
    vs::CompanionCall call{kind, {}, frame};
    call.args[0] = array(arm.q, {arm.n});
    call.args[1] = array(arm.qd, {arm.n});
    call.args[2] = array(arm.qdd, {arm.n});
    call.args[3] = array(arm.g, {3});
    int ndim = 0;
    long shape[3];
    REQUIRE(prepare(arm.dd.kinematics(), call, ndim, shape).ok());
    long size = 1;
    for (int k = 0; k < ndim; ++k) size *= shape[k];
    out.assign(static_cast<std::size_t>(size), 0.0);
    REQUIRE(vs::callCompanion(arm.model, arm.dd, call, out.data()).ok());
    return ndim;
  };
  std::vector<double> out;
  vs::DynamicsData ref(arm.model);
  Eigen::MatrixXd H(arm.n, arm.n);
  REQUIRE(run(Companion::MassMatrix, out) == 2);
  REQUIRE(vs::massMatrix(arm.model, ref, q, H).ok());
  CHECK(Eigen::Map<Eigen::MatrixXd>(out.data(), arm.n, arm.n) == H);
  Eigen::VectorXd tau(arm.n);
  run(Companion::InverseDynamics, out);
  REQUIRE(vs::inverseDynamics(arm.model, ref, q, qd, qdd, vs::Matrix6X(6, 0), KDL::Vector(0, 0, -9.81), tau).ok());
  CHECK(Eigen::Map<Eigen::VectorXd>(out.data(), arm.n) == tau);
  run(Companion::Jacobian, out);  // column-major 6 x n
  Eigen::MatrixXd J(6, arm.n);
  REQUIRE(vs::forwardKinematics(arm.model, ref.kinematics(), q).ok());
  REQUIRE(vs::frameJacobian(arm.model, ref.kinematics(), frame, J).ok());
  CHECK(Eigen::Map<Eigen::MatrixXd>(out.data(), 6, arm.n) == J);
  CHECK(run(Companion::Fk, out) == 2);  // row-major 4 x 4
  KDL::Frame pose;
  REQUIRE(vs::framePose(arm.model, ref.kinematics(), frame, pose).ok());
  CHECK(Eigen::Map<vs::Homogeneous>(out.data()) == vs::homogeneous(pose));
  CHECK(run(Companion::FkAll, out) == 3);
  CHECK(out.size() == static_cast<std::size_t>(16 * arm.ns));
}

TEST_CASE("inverse_dynamics takes f_ext as rows or as wrenches on frames") {
  Arm arm;
  vs::CompanionCall call{Companion::InverseDynamics};
  call.args[0] = array(arm.q, {arm.n});
  call.args[1] = array(arm.qd, {arm.n});
  call.args[2] = array(arm.qdd, {arm.n});
  call.args[3] = array(arm.g, {3});
  call.frame_wrenches_given = true;
  vs::Vector6 w;
  w << 1.0, -2.0, 3.0, 0.5, 0.25, -1.0;
  const vs::FrameRef frame{2, KDL::Frame(KDL::Vector(0.1, 0.2, 0.3))};
  call.frame_wrenches.push_back({frame, w});
  std::vector<double> by_frames(static_cast<std::size_t>(arm.n)), by_rows(by_frames);
  REQUIRE(vs::callCompanion(arm.model, arm.dd, call, by_frames.data()).ok());
  vs::Matrix6X sums = vs::Matrix6X::Zero(6, arm.ns);  // the same wrench moved to the tip by hand
  REQUIRE(vs::addFrameWrench(arm.model, arm.dd.kinematics(), frame, w, sums).ok());
  const std::vector<double> rows(sums.data(), sums.data() + sums.size());  // (ns, 6) rows = 6 x ns columns
  call.frame_wrenches_given = false;
  call.args[4] = array(rows, {arm.ns, 6});
  REQUIRE(vs::checkCompanionArg(arm.dd.kinematics(), call, CompanionArg::FExt).ok());
  REQUIRE(vs::callCompanion(arm.model, arm.dd, call, by_rows.data()).ok());
  CHECK(by_rows == by_frames);
  call.args[4] = vs::ArrayArg{};  // none: different torques
  REQUIRE(vs::callCompanion(arm.model, arm.dd, call, by_rows.data()).ok());
  CHECK(by_rows != by_frames);
}

TEST_CASE("an overflowing result is NonfiniteResult under the companion's Python name") {
  Arm arm;
  const std::vector<double> huge(static_cast<std::size_t>(arm.n), 1e160);
  for (const Companion kind : {Companion::CoriolisTorques, Companion::InverseDynamics}) {
    vs::CompanionCall call{kind};
    call.args[0] = array(arm.q, {arm.n});
    call.args[1] = array(huge, {arm.n});
    call.args[2] = array(arm.qdd, {arm.n});
    call.args[3] = array(arm.g, {3});
    std::vector<double> out(static_cast<std::size_t>(arm.n));
    const vs::Status s = vs::callCompanion(arm.model, arm.dd, call, out.data());
    CHECK(s.code() == vs::Error::NonfiniteResult);
    CHECK(std::string(s.message()) == std::string(vs::companionName(kind)) + ": the result overflows the double range");
  }
}
