// Error paths and rank-deficient tasks.
//  * Every invalid input returns its documented code with a readable errorMessage() naming the
//    argument, leaves the previous results untouched, and prints nothing (stdout and stderr are
//    captured around every solver call).
//  * Invalid models (negative mass, non-PSD inertia, negative rotor inertia) and invalid options.
//  * responseColumns() before any solve, with bad indices or output sizes.
//  * Rank-deficient constraint sets, whose rank is derived by hand: a planar 2-link arm with six
//    constraints (rank 2), duplicated constraint columns, and a fully stretched arm constrained
//    along itself (rank 0) or along and across itself (rank 1). Outputs stay finite under both
//    singularity policies, and the satisfiable part of the constraints holds.
//  * The chain is copied: a solver built from a temporary chain works like one built from a
//    persistent chain.
#include <unistd.h>

#include <cstdio>
#include <functional>

#include <doctest/doctest.h>
#include <kdl/chainfksolverpos_recursive.hpp>

#include "random_chain.hpp"
#include "test_common.hpp"
#include "vereshchagin/chain_hd_solver.hpp"

using testutil::relErr;
using testutil::str;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using Solver = vereshchagin::ChainHdSolver;

namespace {

std::string g_output;  // whatever the solver printed

// Redirects a file descriptor (1 = stdout, 2 = stderr) to a temporary file until stop().
class CaptureFd {
 public:
  explicit CaptureFd(int fd) : fd_(fd) {
    std::fflush(stdout);
    std::fflush(stderr);
    tmp_ = std::tmpfile();
    saved_ = dup(fd_);
    if (tmp_ && saved_ >= 0) dup2(fileno(tmp_), fd_);
  }
  ~CaptureFd() { stop(); }
  // Restores the descriptor and returns what was written meanwhile.
  const std::string& stop() {
    if (stopped_) return text_;
    stopped_ = true;
    std::fflush(stdout);
    std::fflush(stderr);
    if (saved_ >= 0) {
      dup2(saved_, fd_);
      close(saved_);
    }
    if (tmp_) {
      std::fseek(tmp_, 0, SEEK_SET);
      char buf[256];
      std::size_t k;
      while ((k = std::fread(buf, 1, sizeof buf, tmp_)) > 0) text_.append(buf, k);
      std::fclose(tmp_);
    }
    return text_;
  }

 private:
  int fd_, saved_ = -1;
  FILE* tmp_ = nullptr;
  bool stopped_ = false;
  std::string text_;
};

// Runs f with stdout and stderr captured; appends what was written to g_output.
template <typename F>
auto quiet(F&& f) -> decltype(f()) {
  struct Both {
    CaptureFd out{1}, err{2};
    ~Both() {
      g_output += err.stop();
      g_output += out.stop();
    }
  } both;
  return f();
}

using Inputs = testutil::SolveInputs;
using testutil::randomInputs;

int solveWith(Solver& s, const Inputs& in) {
  return quiet([&] { return s.solve(in.q, in.qd, in.alfa, in.beta, in.fext, in.ff); });
}

// 2-link planar arm in the x-y plane: RotZ joints, unit links along x, 1 kg at mid-link.
KDL::Chain planarArm() {
  KDL::Chain ch;
  for (int i = 0; i < 2; ++i) {
    ch.addSegment(
        KDL::Segment("link" + str(i), KDL::Joint("joint" + str(i), KDL::Joint::RotZ), KDL::Frame(KDL::Vector(1, 0, 0)),
                     KDL::RigidBodyInertia(1.0, KDL::Vector(-0.5, 0, 0), KDL::RotationalInertia(0.01, 0.08, 0.08))));
  }
  return ch;
}

KDL::Chain makeChainByValue() {
  testutil::RandomGen g(4242);
  testutil::ChainSpec spec;
  spec.n_joints = 6;
  spec.fixed_before = {3};
  return g.chain(spec);
}

Matrix6X unitColumns(std::initializer_list<Eigen::Matrix<double, 6, 1>> cols) {
  Matrix6X a(6, static_cast<Eigen::Index>(cols.size()));
  int c = 0;
  for (const auto& v : cols) a.col(c++) = v.normalized();
  return a;
}

Eigen::Matrix<double, 6, 1> vec6(double a, double b, double c, double d, double e, double f) {
  Eigen::Matrix<double, 6, 1> v;
  v << a, b, c, d, e, f;
  return v;
}

// Every test case runs with stdout captured from its start (solver constructors included) and
// checks at its end that nothing was printed; solver calls are additionally wrapped in quiet() for
// stderr. doctest writes its reports to stdout too: a failed check inside a test case is therefore
// also reported, verbatim, by the final check (and `-s`, which prints passing checks, fails it).
class PrintsNothing {
 public:
  ~PrintsNothing() {
    CHECK_MESSAGE(g_output.empty(), "the solver printed: \"" << g_output << "\"");
    g_output.clear();
    const std::string printed = whole_stdout_.stop();
    CHECK_MESSAGE(printed.empty(), "something was printed on stdout: \"" << printed << "\"");
  }

 private:
  CaptureFd whole_stdout_{1};
};

// 4 joints, 5 segments: joint and segment counts differ.
KDL::Chain argumentChain(testutil::RandomGen& g) {
  testutil::ChainSpec spec;
  spec.n_joints = 4;
  spec.fixed_before = {2};
  return g.chain(spec);
}

// A valid model, one solver and valid inputs with two constraints.
struct Fixture : PrintsNothing {
  const KDL::Twist grav{KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()};
  testutil::RandomGen g{2024};
  const KDL::Chain chain = argumentChain(g);
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
  Solver solver{chain, grav};
  const Inputs good = randomInputs(g, n, ns, 2);
  Eigen::VectorXd qdd_ok, tau_ok, nu_ok;  // the results of solveGood()

  Fixture() {
    CHECK_MESSAGE((solver.modelError() == 0 && solver.nrOfJoints() == n && solver.nrOfSegments() == ns),
                  "valid model rejected");
  }

  // The valid solve whose results the failing calls must leave untouched.
  void solveGood() {
    CHECK_MESSAGE(solveWith(solver, good) == 0, "valid solve failed: " << std::string(solver.errorMessage()));
    qdd_ok = solver.qdd();
    tau_ok = solver.commandTorques();
    nu_ok = solver.nu();
  }

  // A rank-deficient task under both singularity policies: finite outputs, the expected rank (and
  // `extra`'s checks) under the truncated one.
  void rankCase(const std::string& what, const KDL::Chain& ch, const Eigen::VectorXd& q, const Matrix6X& alfa,
                int expected_rank, const std::function<void(Solver&, const Eigen::VectorXd& beta)>& extra) {
    const unsigned int nn = ch.getNrOfJoints(), nns = ch.getNrOfSegments();
    const int nc = static_cast<int>(alfa.cols());
    const Eigen::VectorXd qd = Eigen::VectorXd::LinSpaced(nn, 0.3, -0.4);
    const Eigen::VectorXd ff = Eigen::VectorXd::LinSpaced(nn, 1.0, -2.0);
    const Matrix6X fext = Matrix6X::Zero(6, nns);
    const Eigen::VectorXd beta = Eigen::VectorXd::LinSpaced(nc, 1.0, 3.0);
    for (int p = 0; p < 2; ++p) {
      vereshchagin::SolverOptions o;
      if (p == 1) o.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
      Solver s(ch, grav, o);
      const std::string tag = what + (p ? " [damped]" : " [truncated]");
      const int rc = quiet([&] { return s.solve(q, qd, alfa, beta, fext, ff); });
      if (!CHECK_MESSAGE(rc == 0, tag << ": solve returned " << str(rc) << " " << s.errorMessage())) continue;
      CHECK_MESSAGE((s.qdd().allFinite() && s.nu().allFinite() && s.commandTorques().allFinite() &&
                     s.linkAccelerations().allFinite()),
                    tag << ": non-finite outputs: qdd " << testutil::mat(s.qdd()) << ", nu " << testutil::mat(s.nu()));
      CHECK_MESSAGE(s.constraintCount() == nc, tag << ": constraintCount");
      if (p == 0) {
        CHECK_MESSAGE(s.constraintRank() == expected_rank,
                      tag << ": constraintRank " << str(s.constraintRank()) << ", expected " << str(expected_rank));
        CHECK_MESSAGE(s.smallestSingularValue() <= 1e-12,
                      tag << ": smallestSingularValue " << str(s.smallestSingularValue()));
        if (extra) extra(s, beta);
      }
      Eigen::MatrixXd a(nn, nn), b(nn, nn);
      const Eigen::VectorXi all = Eigen::VectorXi::LinSpaced(nn, 0, nn - 1);
      CHECK_MESSAGE((quiet([&] { return s.responseColumns(all, a, b); }) == 0 && a.allFinite() && b.allFinite()),
                    tag << ": non-finite response columns");
    }
  }

  // Unconstrained solution of a chain, for comparisons.
  Eigen::VectorXd freeQdd(const KDL::Chain& ch, const Eigen::VectorXd& q) {
    Solver s(ch, grav);
    const unsigned int nn = ch.getNrOfJoints();
    quiet([&] {
      return s.solve(q, Eigen::VectorXd::LinSpaced(nn, 0.3, -0.4), Matrix6X(6, 0), Eigen::VectorXd(0),
                     Matrix6X::Zero(6, ch.getNrOfSegments()), Eigen::VectorXd::LinSpaced(nn, 1.0, -2.0));
    });
    return Eigen::VectorXd(s.qdd());
  }
};

}  // namespace

TEST_CASE_FIXTURE(Fixture, "responseColumns before any solve: E_NO_SOLUTION with a message") {
  Eigen::MatrixXd a(n, 1), b(n, 1);
  Eigen::VectorXi j(1);
  j << 0;
  const int rc = quiet([&] { return solver.responseColumns(j, a, b); });
  CHECK_MESSAGE(rc == Solver::E_NO_SOLUTION, "responseColumns before solve: got " << str(rc));
  CHECK_MESSAGE(std::string(solver.errorMessage()).size() > 0, "responseColumns before solve: empty message");
}

TEST_CASE_FIXTURE(Fixture, "invalid arguments: documented code, message naming the argument, results untouched") {
  solveGood();
  struct Bad {
    std::string what, arg;
    Inputs in;
    int code;
  };
  std::vector<Bad> bad;
  auto with = [&](std::function<void(Inputs&)> f) {
    Inputs in = good;
    f(in);
    return in;
  };
  for (int d : {-1, 1}) {
    bad.push_back({"q size " + str(n + d), "q", with([&](Inputs& in) {
                     in.q.resize(n + d);
                     in.q.setZero();
                   }),
                   Solver::E_SIZE_MISMATCH});
    bad.push_back({"q_dot size " + str(n + d), "q_dot", with([&](Inputs& in) {
                     in.qd.resize(n + d);
                     in.qd.setZero();
                   }),
                   Solver::E_SIZE_MISMATCH});
    bad.push_back({"ff_torques size " + str(n + d), "ff_torques", with([&](Inputs& in) {
                     in.ff.resize(n + d);
                     in.ff.setZero();
                   }),
                   Solver::E_SIZE_MISMATCH});
    bad.push_back({"f_ext columns " + str(ns + d), "f_ext",
                   with([&](Inputs& in) { in.fext = Matrix6X::Zero(6, ns + d); }), Solver::E_SIZE_MISMATCH});
    bad.push_back({"beta size " + str(2 + d), "beta", with([&](Inputs& in) { in.beta = Eigen::VectorXd::Zero(2 + d); }),
                   Solver::E_SIZE_MISMATCH});
  }
  bad.push_back({"q empty", "q", with([&](Inputs& in) { in.q.resize(0); }), Solver::E_SIZE_MISMATCH});
  bad.push_back({"f_ext with one column per joint", "f_ext", with([&](Inputs& in) { in.fext = Matrix6X::Zero(6, n); }),
                 Solver::E_SIZE_MISMATCH});
  bad.push_back({"beta size 1 without constraints", "beta", with([&](Inputs& in) {
                   in.alfa.resize(6, 0);
                   in.beta = Eigen::VectorXd::Zero(1);
                 }),
                 Solver::E_SIZE_MISMATCH});
  bad.push_back({"alfa with 7 columns", "alfa", with([&](Inputs& in) {
                   in.alfa = g.alfa(7).data;
                   in.beta = Eigen::VectorXd::Zero(7);
                 }),
                 Solver::E_TOO_MANY_CONSTRAINTS});
  const double nonfinite[] = {NAN, INFINITY, -INFINITY};
  for (double x : nonfinite) {
    const std::string xs = str(x);
    bad.push_back({"q has " + xs, "q", with([&](Inputs& in) { in.q(n - 1) = x; }), Solver::E_NONFINITE_INPUT});
    bad.push_back({"q_dot has " + xs, "q_dot", with([&](Inputs& in) { in.qd(1) = x; }), Solver::E_NONFINITE_INPUT});
    bad.push_back({"alfa has " + xs, "alfa", with([&](Inputs& in) { in.alfa(4, 1) = x; }), Solver::E_NONFINITE_INPUT});
    bad.push_back({"beta has " + xs, "beta", with([&](Inputs& in) { in.beta(0) = x; }), Solver::E_NONFINITE_INPUT});
    bad.push_back(
        {"f_ext has " + xs, "f_ext", with([&](Inputs& in) { in.fext(5, ns - 1) = x; }), Solver::E_NONFINITE_INPUT});
    bad.push_back(
        {"ff_torques has " + xs, "ff_torques", with([&](Inputs& in) { in.ff(2) = x; }), Solver::E_NONFINITE_INPUT});
  }
  for (const Bad& b : bad) {
    const int rc = solveWith(solver, b.in);
    const std::string msg = solver.errorMessage();
    CHECK_MESSAGE(rc == b.code, b.what << ": expected " << str(b.code) << ", got " << str(rc) << " (" << msg << ")");
    CHECK_MESSAGE(msg.find(b.arg) != std::string::npos,
                  b.what << ": errorMessage does not name '" << b.arg << "': " << msg);
    CHECK_MESSAGE(solver.getError() == rc,
                  b.what << ": getError() " << str(solver.getError()) << " != returned " << str(rc));
    CHECK_MESSAGE((solver.qdd() == qdd_ok && solver.commandTorques() == tau_ok && solver.nu() == nu_ok),
                  b.what << ": the previous results were modified");
  }
}

TEST_CASE_FIXTURE(Fixture, "empty f_ext and ff_torques mean zero") {
  Inputs in = good;
  in.fext.setZero();
  in.ff.setZero();
  CHECK_MESSAGE(solveWith(solver, in) == 0, "zero f_ext / ff solve");
  const Eigen::VectorXd qdd_zero = solver.qdd();
  in.fext.resize(6, 0);
  in.ff.resize(0);
  CHECK_MESSAGE((solveWith(solver, in) == 0 && solver.qdd() == qdd_zero), "empty f_ext / ff_torques are not zero");
}

TEST_CASE_FIXTURE(Fixture, "every solver-specific error code has its own description") {
  for (int code : {Solver::E_NONFINITE_INPUT, Solver::E_INVALID_MODEL, Solver::E_DEGENERATE_INERTIA,
                   Solver::E_TOO_MANY_CONSTRAINTS, Solver::E_NO_SOLUTION, Solver::E_INVALID_OPTIONS}) {
    CHECK_MESSAGE((std::string(solver.strError(code)) != solver.strError(123456) &&
                   std::string(solver.strError(code)).size() > 0),
                  "strError(" << str(code) << ") is not specific");
  }
}

TEST_CASE_FIXTURE(Fixture, "non-finite root acceleration, from the constructor and setRootAcceleration") {
  solveGood();
  Solver s(chain, KDL::Twist(KDL::Vector(0, NAN, 9.81), KDL::Vector::Zero()));
  int rc = solveWith(s, good);
  CHECK_MESSAGE(rc == Solver::E_NONFINITE_INPUT, "NaN root_acc (constructor): got " << str(rc));
  CHECK_MESSAGE(std::string(s.errorMessage()).size() > 0, "NaN root_acc: empty message");
  s.setRootAcceleration(grav);
  CHECK_MESSAGE((solveWith(s, good) == 0 && s.qdd() == qdd_ok), "fixing root_acc with setRootAcceleration");
  s.setRootAcceleration(KDL::Twist(KDL::Vector::Zero(), KDL::Vector(INFINITY, 0, 0)));
  rc = solveWith(s, good);
  CHECK_MESSAGE(rc == Solver::E_NONFINITE_INPUT, "Inf root_acc (setRootAcceleration): got " << str(rc));
}

TEST_CASE_FIXTURE(Fixture, "KDL entry point: sizes, messages and non-finite inputs") {
  solveGood();
  const Inputs& in = good;
  KDL::JntArray q(n), qd(n), ff(n), beta(2), qdd(n), tau(n);
  q.data = in.q;
  qd.data = in.qd;
  ff.data = in.ff;
  beta.data = in.beta;
  KDL::Jacobian alfa(2);
  alfa.data = in.alfa;
  KDL::Wrenches fext(ns);
  for (unsigned int i = 0; i < ns; ++i) fext[i] = testutil::toWrench(in.fext.col(i));
  auto run = [&](KDL::JntArray& q_, KDL::JntArray& qd_, KDL::JntArray& qdd_, KDL::Jacobian& a_, KDL::JntArray& b_,
                 KDL::Wrenches& f_, KDL::JntArray& ff_, KDL::JntArray& t_) {
    return quiet([&] { return solver.CartToJnt(q_, qd_, qdd_, a_, b_, f_, ff_, t_); });
  };
  CHECK_MESSAGE((run(q, qd, qdd, alfa, beta, fext, ff, tau) == 0 && qdd.data == qdd_ok), "KDL entry point: valid call");
  KDL::JntArray shortj(n - 1), longj(n + 1);
  KDL::Wrenches fshort(ns - 1), flong(ns + 1);
  KDL::Jacobian alfa7(7);
  alfa7.data = g.alfa(7).data;
  KDL::JntArray beta7(7), beta3(3);
  struct K {
    std::string what, arg;
    int rc, code;
  };
  const std::vector<K> cases = {
      {"q_dotdot short", "q_dotdot", run(q, qd, shortj, alfa, beta, fext, ff, tau), Solver::E_SIZE_MISMATCH},
      {"command_torques long", "command_torques", run(q, qd, qdd, alfa, beta, fext, ff, longj),
       Solver::E_SIZE_MISMATCH},
      {"q short", "q", run(shortj, qd, qdd, alfa, beta, fext, ff, tau), Solver::E_SIZE_MISMATCH},
      {"q_dot long", "q_dot", run(q, longj, qdd, alfa, beta, fext, ff, tau), Solver::E_SIZE_MISMATCH},
      {"f_ext short", "f_ext", run(q, qd, qdd, alfa, beta, fshort, ff, tau), Solver::E_SIZE_MISMATCH},
      {"f_ext long", "f_ext", run(q, qd, qdd, alfa, beta, flong, ff, tau), Solver::E_SIZE_MISMATCH},
      {"ff_torques short", "ff_torques", run(q, qd, qdd, alfa, beta, fext, shortj, tau), Solver::E_SIZE_MISMATCH},
      {"beta size 3 for 2 constraints", "beta", run(q, qd, qdd, alfa, beta3, fext, ff, tau), Solver::E_SIZE_MISMATCH},
      {"alfa with 7 columns", "alfa", run(q, qd, qdd, alfa7, beta7, fext, ff, tau), Solver::E_TOO_MANY_CONSTRAINTS},
  };
  // (errorMessage() only holds the last error, so the message of each case is checked right after
  // it below by re-running it.)
  for (const K& c : cases)
    CHECK_MESSAGE(c.rc == c.code,
                  "KDL entry point, " << c.what << ": expected " << str(c.code) << ", got " << str(c.rc));
  run(q, qd, shortj, alfa, beta, fext, ff, tau);
  CHECK_MESSAGE(std::string(solver.errorMessage()).find("q_dotdot") != std::string::npos,
                "q_dotdot message: " << std::string(solver.errorMessage()));
  run(q, qd, qdd, alfa, beta, fext, ff, longj);
  CHECK_MESSAGE(std::string(solver.errorMessage()).find("command_torques") != std::string::npos,
                "command_torques message: " << std::string(solver.errorMessage()));
  run(q, qd, qdd, alfa, beta, flong, ff, tau);
  CHECK_MESSAGE(std::string(solver.errorMessage()).find("f_ext") != std::string::npos,
                "f_ext message: " << std::string(solver.errorMessage()));
  KDL::JntArray qnan = q;
  qnan(0) = NAN;
  CHECK_MESSAGE(run(qnan, qd, qdd, alfa, beta, fext, ff, tau) == Solver::E_NONFINITE_INPUT, "KDL entry point: NaN q");
  KDL::Wrenches fnan = fext;
  fnan[1].torque.data[2] = INFINITY;
  CHECK_MESSAGE(run(q, qd, qdd, alfa, beta, fnan, ff, tau) == Solver::E_NONFINITE_INPUT, "KDL entry point: Inf f_ext");
}

TEST_CASE_FIXTURE(Fixture, "responseColumns argument errors after a solve") {
  CHECK_MESSAGE(solveWith(solver, good) == 0, "solve before responseColumns");
  Eigen::MatrixXd a(n, 2), b(n, 2), a_bad(n + 1, 2), b_bad(n, 1);
  Eigen::VectorXi j(2);
  for (int bad_index : {-1, static_cast<int>(n), 1000}) {
    j << 0, bad_index;
    const int rc = quiet([&] { return solver.responseColumns(j, a, b); });
    CHECK_MESSAGE(rc == Solver::E_OUT_OF_RANGE, "responseColumns index " << str(bad_index) << ": got " << str(rc));
    CHECK_MESSAGE(std::string(solver.errorMessage()).size() > 0, "responseColumns index: empty message");
  }
  j << 0, 1;
  CHECK_MESSAGE(quiet([&] { return solver.responseColumns(j, a_bad, b); }) == Solver::E_SIZE_MISMATCH,
                "responseColumns dqdd size");
  CHECK_MESSAGE(quiet([&] { return solver.responseColumns(j, a, b_bad); }) == Solver::E_SIZE_MISMATCH,
                "responseColumns dtau size");
  CHECK_MESSAGE(quiet([&] { return solver.responseColumns(j, a, b); }) == 0, "responseColumns valid call");
}

TEST_CASE_FIXTURE(Fixture, "invalid models: negative mass, indefinite inertia, negative rotor inertia") {
  auto modelCase = [&](const std::string& what, const KDL::Chain& ch) {
    Solver s(ch, grav);
    const unsigned int nn = ch.getNrOfJoints(), nns = ch.getNrOfSegments();
    testutil::RandomGen gg(5);
    const Inputs in = randomInputs(gg, nn, nns, 1);
    CHECK_MESSAGE(s.modelError() == Solver::E_INVALID_MODEL, what << ": modelError " << str(s.modelError()));
    const int rc = solveWith(s, in);
    CHECK_MESSAGE(rc == Solver::E_INVALID_MODEL, what << ": solve returned " << str(rc));
    CHECK_MESSAGE(std::string(s.errorMessage()).size() > 0, what << ": empty message");
    CHECK_MESSAGE(s.qdd().allFinite(), what << ": non-finite qdd");
    KDL::JntArray q(nn), qdd(nn), tau(nn), beta(1);
    KDL::Jacobian alfa(1);
    alfa.data = in.alfa;
    KDL::Wrenches f(nns, KDL::Wrench::Zero());
    CHECK_MESSAGE(quiet([&] { return s.CartToJnt(q, q, qdd, alfa, beta, f, q, tau); }) == Solver::E_INVALID_MODEL,
                  what << ": CartToJnt does not return E_INVALID_MODEL");
  };
  auto replace = [](const KDL::Chain& ch, unsigned int idx, const KDL::Segment& seg) {
    KDL::Chain out;
    for (unsigned int i = 0; i < ch.getNrOfSegments(); ++i) out.addSegment(i == idx ? seg : ch.getSegment(i));
    return out;
  };
  const KDL::Segment& s1 = chain.getSegment(1);
  modelCase("negative mass", replace(chain, 1,
                                     KDL::Segment(s1.getName(), s1.getJoint(), s1.getFrameToTip(),
                                                  KDL::RigidBodyInertia(-1.0, KDL::Vector(0.1, 0, 0),
                                                                        KDL::RotationalInertia(0.1, 0.1, 0.1)))));
  modelCase("negative-definite rotational inertia",
            replace(chain, 1,
                    KDL::Segment(
                        s1.getName(), s1.getJoint(), s1.getFrameToTip(),
                        KDL::RigidBodyInertia(1.0, KDL::Vector(0.1, 0, 0), KDL::RotationalInertia(-0.1, 0.1, 0.1)))));
  modelCase("negative rotor inertia",
            replace(chain, 0,
                    KDL::Segment("s0", KDL::Joint("j0", KDL::Joint::RotY, 1.0, 0.0, -0.2),
                                 chain.getSegment(0).getFrameToTip(), chain.getSegment(0).getInertia())));
}

TEST_CASE_FIXTURE(Fixture, "invalid options are refused, not applied, and refused at construction") {
  solveGood();
  Solver s(chain, grav);
  vereshchagin::SolverOptions o;
  o.rcond = -1e-3;
  int rc = quiet([&] { return s.setOptions(o); });
  CHECK_MESSAGE(rc == Solver::E_INVALID_OPTIONS, "negative rcond: got " << str(rc));
  CHECK_MESSAGE(std::string(s.errorMessage()).find("rcond") != std::string::npos,
                "negative rcond message: " << std::string(s.errorMessage()));
  CHECK_MESSAGE(s.options().rcond == vereshchagin::SolverOptions().rcond, "rejected options were applied");
  o.rcond = NAN;
  CHECK_MESSAGE(quiet([&] { return s.setOptions(o); }) == Solver::E_INVALID_OPTIONS, "NaN rcond accepted");
  o = vereshchagin::SolverOptions();
  o.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
  o.damping = 0.0;
  CHECK_MESSAGE(quiet([&] { return s.setOptions(o); }) == Solver::E_INVALID_OPTIONS,
                "zero damping accepted for the damped policy");
  o.damping = -1.0;
  CHECK_MESSAGE(quiet([&] { return s.setOptions(o); }) == Solver::E_INVALID_OPTIONS, "negative damping accepted");
  CHECK_MESSAGE((solveWith(s, good) == 0 && s.qdd() == qdd_ok), "solver unusable after rejected options");

  o.damping = -1.0;
  Solver bad_ctor(chain, grav, o);
  rc = solveWith(bad_ctor, good);
  CHECK_MESSAGE((bad_ctor.modelError() != 0 && rc == Solver::E_INVALID_OPTIONS),
                "invalid options at construction: modelError " << str(bad_ctor.modelError()) << ", solve " << str(rc));
}

TEST_CASE_FIXTURE(Fixture, "rank-deficient: planar 2R arm with six constraints and with three consistent ones") {
  const KDL::Chain arm = planarArm();
  // Six independent unit wrenches on a planar 2R arm at a regular configuration: the tip can only
  // move in x, y (linear) and z (angular), two of them independent -> rank 2.
  Eigen::VectorXd q(2);
  q << 0.3, 0.7;
  rankCase("planar 2R, alfa = I6", arm, q, Matrix6X::Identity(6, 6), 2, nullptr);
  // Three in-plane constraints (vx, vy, wz) on two joints: still rank 2. Consistent set-points
  // (those of a reference motion) must be met exactly, which fixes qdd to the reference's.
  Matrix6X a3 = unitColumns({vec6(1, 0, 0, 0, 0, 0), vec6(0, 1, 0, 0, 0, 0), vec6(0, 0, 0, 0, 0, 1)});
  {
    Solver ref(arm, grav);
    const Eigen::VectorXd qd = Eigen::VectorXd::LinSpaced(2, 0.3, -0.4);
    const Eigen::VectorXd tau_ref = Eigen::VectorXd::LinSpaced(2, 1.0, -2.0) + Eigen::Vector2d(3.0, -1.5);
    quiet([&] { return ref.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(0), Matrix6X::Zero(6, 2), tau_ref); });
    const Eigen::VectorXd beta_ref = a3.transpose() * ref.linkAccelerations().col(2);
    Solver s(arm, grav);
    const int rc = quiet(
        [&] { return s.solve(q, qd, a3, beta_ref, Matrix6X::Zero(6, 2), Eigen::VectorXd::LinSpaced(2, 1.0, -2.0)); });
    CHECK_MESSAGE((rc == 0 && s.constraintRank() == 2),
                  "planar 2R, 3 consistent constraints: rc " << str(rc) << ", rank " << str(s.constraintRank()));
    CHECK_MESSAGE(relErr(s.qdd(), ref.qdd()) <= 1e-9, "planar 2R, 3 consistent constraints: qdd "
                                                          << testutil::mat(s.qdd()) << " vs reference "
                                                          << testutil::mat(ref.qdd()));
    CHECK_MESSAGE(relErr(a3.transpose() * s.linkAccelerations().col(2), beta_ref) <= 1e-9,
                  "planar 2R, 3 consistent constraints: not met");
    CHECK_MESSAGE(relErr(s.commandTorques(), Eigen::Vector2d(3.0, -1.5)) <= 1e-9,
                  "planar 2R, 3 consistent constraints: command torques " << testutil::mat(s.commandTorques())
                                                                          << ", expected 3 -1.5");
  }
}

TEST_CASE_FIXTURE(Fixture, "rank-deficient: duplicated constraint columns") {
  // Duplicated constraint columns on a 6-joint spatial arm: [a1, a2, a1] has rank 2 and must
  // produce the same motion and the same total constraint wrench as [a1, a2].
  testutil::RandomGen gg(31337);
  const KDL::Chain ch = gg.chain(6, false, true);
  const Eigen::VectorXd q = gg.q(6).data;
  const Matrix6X a2 = gg.alfa(2).data;
  Matrix6X a_dup(6, 3);
  a_dup << a2.col(0), a2.col(1), a2.col(0);
  rankCase("duplicated columns [a1 a2 a1]", ch, q, a_dup, 2, nullptr);
  Solver s2(ch, grav), s3(ch, grav);
  const Eigen::VectorXd qd = Eigen::VectorXd::LinSpaced(6, 0.3, -0.4), ff = Eigen::VectorXd::LinSpaced(6, 1.0, -2.0);
  const Eigen::Vector2d b2(1.5, -0.5);
  const Eigen::Vector3d b3(1.5, -0.5, 1.5);
  const int r2 = quiet([&] { return s2.solve(q, qd, a2, b2, Matrix6X::Zero(6, 6), ff); });
  const int r3 = quiet([&] { return s3.solve(q, qd, a_dup, b3, Matrix6X::Zero(6, 6), ff); });
  CHECK_MESSAGE((r2 == 0 && r3 == 0), "duplicated columns: solves failed");
  CHECK_MESSAGE(relErr(s3.qdd(), s2.qdd()) <= 1e-8,
                "duplicated columns: qdd " << testutil::mat(s3.qdd()) << " vs " << testutil::mat(s2.qdd()));
  const Eigen::VectorXd w2 = a2 * s2.nu(), w3 = a_dup * s3.nu();
  CHECK_MESSAGE(relErr(w3, w2) <= 1e-8, "duplicated columns: total constraint wrench differs");
  CHECK_MESSAGE(relErr(s3.commandTorques(), s2.commandTorques()) <= 1e-8, "duplicated columns: command torques differ");
  CHECK_MESSAGE(std::abs(s3.nu()(0) - s3.nu()(2)) <= 1e-8 * std::max(1.0, std::abs(s3.nu()(0))),
                "duplicated columns: minimum-norm split expected nu_1 = nu_3, got " << testutil::mat(s3.nu()));
}

TEST_CASE_FIXTURE(Fixture, "rank-deficient: stretched arm constrained along and across itself, also tilted") {
  const KDL::Chain arm = planarArm();
  // Fully stretched arm along x (q = 0): no joint can move the tip along the arm.
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(2);
  const Eigen::VectorXd free0 = freeQdd(arm, q0);
  rankCase("stretched along x, constraint along the arm", arm, q0, unitColumns({vec6(1, 0, 0, 0, 0, 0)}), 0,
           [&](Solver& s, const Eigen::VectorXd&) {
             CHECK_MESSAGE((relErr(s.qdd(), free0) <= 1e-9 && s.nu().cwiseAbs().maxCoeff() <= 1e-9),
                           "stretched along x: an ineffective constraint changed the motion: qdd "
                               << testutil::mat(s.qdd()) << " free " << testutil::mat(free0) << " nu "
                               << testutil::mat(s.nu()));
           });
  rankCase("stretched along x, constraints along and across the arm", arm, q0,
           unitColumns({vec6(1, 0, 0, 0, 0, 0), vec6(0, 1, 0, 0, 0, 0)}), 1,
           [&](Solver& s, const Eigen::VectorXd& beta) {
             CHECK_MESSAGE(std::abs(s.linkAccelerations()(1, 2) - beta(1)) <= 1e-9 * std::max(1.0, std::abs(beta(1))),
                           "stretched along x: the satisfiable constraint (across) is not met");
           });
  // The same with a generic orientation: a fixed first segment tilts the arm's plane, so the
  // coupling along the arm is zero only up to round-off (about 1e-32 instead of exactly 0). The
  // constraint still cannot act: rank 0, the free motion, no constraint force.
  KDL::Chain tilted;
  tilted.addSegment(KDL::Segment("tilt", KDL::Joint(KDL::Joint::Fixed),
                                 KDL::Frame(KDL::Rotation::RPY(0.4, -0.9, 1.3), KDL::Vector(0.1, 0.2, 0.3))));
  for (const KDL::Segment& sg : arm.segments) tilted.addSegment(sg);
  for (double th : {0.5, -2.1, 2.9}) {
    Eigen::VectorXd q1(2);
    q1 << th, 0.0;
    KDL::JntArray qk(2);
    qk.data = q1;
    KDL::ChainFkSolverPos_recursive fk(tilted);
    KDL::Frame F1, F3;
    fk.JntToCart(qk, F1, 1);
    fk.JntToCart(qk, F3, 3);
    KDL::Vector along = F3.p - F1.p;
    along.Normalize();
    KDL::Vector across = F1.M.UnitZ() * along;
    across.Normalize();
    const Eigen::VectorXd free1 = freeQdd(tilted, q1);
    const std::string name = "tilted stretched arm (q1 = " + str(th) + ")";
    rankCase(name + ", constraint along the arm", tilted, q1,
             unitColumns({vec6(along.x(), along.y(), along.z(), 0, 0, 0)}), 0,
             [&, name](Solver& s, const Eigen::VectorXd&) {
               CHECK_MESSAGE((relErr(s.qdd(), free1) <= 1e-9 && s.nu().cwiseAbs().maxCoeff() <= 1e-6),
                             name << ": an ineffective constraint changed the motion: qdd " << testutil::mat(s.qdd())
                                  << " free " << testutil::mat(free1) << " nu " << testutil::mat(s.nu())
                                  << " smallest eigenvalue " << str(s.smallestSingularValue()));
             });
    rankCase(name + ", constraints along and across the arm", tilted, q1,
             unitColumns(
                 {vec6(along.x(), along.y(), along.z(), 0, 0, 0), vec6(across.x(), across.y(), across.z(), 0, 0, 0)}),
             1, [&, name, across](Solver& s, const Eigen::VectorXd& beta) {
               const Eigen::Vector3d acr(across.x(), across.y(), across.z());
               const double achieved = acr.dot(s.linkAccelerations().col(3).head<3>());
               CHECK_MESSAGE(std::abs(achieved - beta(1)) <= 1e-9 * std::max(1.0, std::abs(beta(1))),
                             name << ": the satisfiable constraint (across) is not met: " << str(achieved) << " vs "
                                  << str(beta(1)));
             });
  }
}

TEST_CASE_FIXTURE(Fixture,
                  "the chain is copied: a solver from a temporary chain works like one from a persistent chain") {
  testutil::RandomGen gg(8);
  Solver from_temp(makeChainByValue(), grav);
  {
    // Reuse the freed memory of the temporary.
    std::vector<KDL::Chain> junk;
    for (int i = 0; i < 20; ++i) junk.push_back(gg.chain(8));
  }
  KDL::Chain persistent = makeChainByValue();
  Solver from_persistent(persistent, grav);
  const unsigned int nn = persistent.getNrOfJoints(), nns = persistent.getNrOfSegments();
  CHECK_MESSAGE((from_temp.nrOfJoints() == nn && from_temp.nrOfSegments() == nns && from_temp.modelError() == 0),
                "solver from a temporary chain: wrong model");
  const Inputs in = randomInputs(gg, nn, nns, 3);
  const int r1 = solveWith(from_temp, in), r2 = solveWith(from_persistent, in);
  CHECK_MESSAGE((r1 == 0 && r2 == 0), "solver from a temporary chain: solve failed");
  CHECK_MESSAGE((from_temp.qdd() == from_persistent.qdd() && from_temp.nu() == from_persistent.nu() &&
                 from_temp.commandTorques() == from_persistent.commandTorques() &&
                 from_temp.linkAccelerations() == from_persistent.linkAccelerations()),
                "solver from a temporary chain gives different results");
  // Changing the caller's chain afterwards does not affect the solver.
  persistent.addSegment(KDL::Segment(KDL::Joint("extra", KDL::Joint::RotX), KDL::Frame::Identity(), gg.inertia()));
  const Eigen::VectorXd qdd_before = from_persistent.qdd();
  CHECK_MESSAGE((solveWith(from_persistent, in) == 0 && from_persistent.qdd() == qdd_before &&
                 from_persistent.nrOfJoints() == nn),
                "solver is affected by later changes to the caller's chain");
}
