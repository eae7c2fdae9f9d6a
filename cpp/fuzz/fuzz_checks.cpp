// Properties checked on every fuzz input; see fuzz_checks.hpp.
#include "fuzz_checks.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/chainidsolver.hpp>  // KDL::Wrenches
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>

#include "fuzz_input.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"
#include "vereshchagin/tree_hd_solver.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace fuzzutil {

namespace {

using vereshchagin::ChainHdSolver;
using vereshchagin::FrictionSolver;
using Matrix6X = ChainHdSolver::Matrix6X;

// "" if rc is a success with finite outputs or an error with a message; else the violation.
template <typename Outputs>
std::string verdict(const char* call, int rc, const char* message, Outputs&& outputs_finite) {
  if (rc == 0) return outputs_finite() ? "" : std::string(call) + " returned 0 with non-finite outputs";
  if (rc > 0) return std::string(call) + " returned a positive code " + std::to_string(rc);
  if (message == nullptr || message[0] == '\0')
    return std::string(call) + " failed with code " + std::to_string(rc) + " but an empty message";
  return "";
}

// Solves a chain with every entry point; inputs drawn from r.
std::string exerciseChain(const KDL::Chain& chain, ByteReader& r, const Eigen::VectorXd* urdf_friction,
                          const Eigen::VectorXd* lower, const Eigen::VectorXd* upper) {
  const unsigned int n = chain.getNrOfJoints(), ns = chain.getNrOfSegments();
  const KDL::Twist root_acc(KDL::Vector(r.value(-1, 1), r.value(-1, 1), 9.81), KDL::Vector(0, 0, r.value(-1, 1)));
  vereshchagin::SolverOptions opt;
  if (r.byte() & 1) {
    opt.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
    opt.damping = r.value(1e-9, 1e-2);
  }
  if (r.byte() & 1) opt.rcond = r.value(0.0, 1e-6);

  ChainHdSolver hd(chain, root_acc, opt);
  if (hd.modelError() != 0) {
    if (hd.errorMessage()[0] == '\0') return "modelError() set with an empty message";
  }
  Eigen::VectorXd q(n), qd(n), ff(n);
  for (unsigned int k = 0; k < n; ++k) {
    q(k) = r.value(-3.2, 3.2);
    qd(k) = r.byte() < 64 ? 0.0 : r.value(-3.0, 3.0);  // resting joints for the friction solver
    ff(k) = r.value(-10.0, 10.0);
  }
  const int m = r.integer(0, 7);
  Matrix6X alfa(6, m);
  Eigen::VectorXd beta(m);
  for (int c = 0; c < m; ++c) {
    for (int k = 0; k < 6; ++k) alfa(k, c) = r.value(-1.0, 1.0);
    beta(c) = r.value(-10.0, 10.0);
  }
  Matrix6X fext = Matrix6X::Zero(6, (r.byte() & 1) ? ns : 0);
  for (Eigen::Index c = 0; c < fext.cols(); ++c)
    for (int k = 0; k < 6; ++k) fext(k, c) = r.value(-5.0, 5.0);

  int rc = hd.solve(q, qd, alfa, beta, fext, ff);
  std::string bad = verdict("ChainHdSolver::solve", rc, hd.errorMessage(), [&] {
    return hd.qdd().allFinite() && hd.commandTorques().allFinite() && hd.nu().allFinite() &&
           hd.linkAccelerations().allFinite();
  });
  if (bad.empty() && rc == 0 && !std::isfinite(hd.smallestSingularValue()))
    bad = "ChainHdSolver::smallestSingularValue non-finite after success";
  if (!bad.empty()) return bad;
  if (rc == 0 && n > 0) {
    const Eigen::VectorXi all = Eigen::VectorXi::LinSpaced(n, 0, static_cast<int>(n) - 1);
    Eigen::MatrixXd dqdd(n, n), dtau(n, n);
    rc = hd.responseColumns(all, dqdd, dtau);
    bad = verdict("responseColumns", rc, hd.errorMessage(), [&] { return dqdd.allFinite() && dtau.allFinite(); });
    if (!bad.empty()) return bad;
  }

  // Constraints on any segments: each column on a drawn segment (sometimes out of range, or more
  // than 6 on one segment: errors), with response columns and their d(nu).
  {
    Eigen::VectorXi segs(m);
    for (int c = 0; c < m; ++c) segs(c) = r.integer(-1, static_cast<int>(ns));
    rc = hd.solve(q, qd, alfa, beta, segs, fext, ff);
    bad = verdict("ChainHdSolver::solve(segments)", rc, hd.errorMessage(), [&] {
      return hd.qdd().allFinite() && hd.commandTorques().allFinite() && hd.nu().allFinite() &&
             hd.linkAccelerations().allFinite() && std::isfinite(hd.smallestSingularValue());
    });
    if (!bad.empty()) return bad;
    if (rc == 0 && n > 0) {
      const Eigen::VectorXi all = Eigen::VectorXi::LinSpaced(n, 0, static_cast<int>(n) - 1);
      Eigen::MatrixXd dqdd(n, n), dtau(n, n), dnu(std::max(m, 1), n);
      rc = hd.responseColumns(all, dqdd, dtau, dnu);
      bad = verdict("responseColumns(segments)", rc, hd.errorMessage(),
                    [&] { return dqdd.allFinite() && dtau.allFinite() && dnu.topRows(m).allFinite(); });
      if (!bad.empty()) return bad;
    }
  }

  // The KDL entry point with the same values (only m <= 6 fits a KDL::Jacobian meaningfully).
  if (m <= 6) {
    KDL::JntArray kq(n), kqd(n), kqdd(n), kff(n), ktau(n), kbeta(m);
    kq.data = q;
    kqd.data = qd;
    kff.data = ff;
    kbeta.data = beta;
    KDL::Jacobian kalfa(m);
    kalfa.data = alfa;
    KDL::Wrenches kf(ns, KDL::Wrench::Zero());
    rc = hd.CartToJnt(kq, kqd, kqdd, kalfa, kbeta, kf, kff, ktau);
    bad = verdict("CartToJnt", rc, hd.errorMessage(), [&] { return kqdd.data.allFinite() && ktau.data.allFinite(); });
    if (!bad.empty()) return bad;
  }

  // Friction: from the URDF, or drawn (any values; kinetic <= static most of the time).
  vereshchagin::FrictionModel fm;
  fm.static_friction.resize(n);
  fm.kinetic_friction.resize((r.byte() & 1) ? n : 0);
  for (unsigned int k = 0; k < n; ++k) {
    fm.static_friction(k) = urdf_friction ? (*urdf_friction)(k) : r.value(0.0, 20.0);
    if (fm.kinetic_friction.size()) fm.kinetic_friction(k) = fm.static_friction(k) * r.unit(0.0, 1.05);
  }
  fm.velocity_tolerance = r.byte() < 200 ? 1e-6 : r.value(0.0, 1.0);
  if (lower && upper) {
    fm.lower = *lower;
    fm.upper = *upper;
  } else if (r.byte() & 1) {
    fm.lower.resize(n);
    fm.upper.resize(n);
    for (unsigned int k = 0; k < n; ++k) {
      fm.lower(k) = r.value(-3.0, 0.5);
      fm.upper(k) = r.value(-0.5, 3.0);
    }
  }
  FrictionSolver fs(chain, root_acc, opt);
  rc = fs.solve(q, qd, alfa, beta, fext, ff, fm);
  bad = verdict("FrictionSolver::solve", rc, fs.errorMessage(), [&] {
    return fs.qdd().allFinite() && fs.commandTorques().allFinite() && fs.frictionTorques().allFinite() &&
           fs.limitTorques().allFinite() && fs.nu().allFinite();
  });
  if (!bad.empty()) return bad;
  if (rc == 0) {
    if (!fs.linkAccelerations().allFinite()) return "FrictionSolver::linkAccelerations non-finite after success";
    if (!std::isfinite(fs.gaussValue())) {
      // Allowed only when the unconstrained motion it compares with overflows (documented).
      Eigen::VectorXd tau0 = ff;
      for (unsigned int k = 0; k < n; ++k)
        if (std::abs(qd(k)) > fm.velocity_tolerance)
          tau0(k) -=
              (fm.kinetic_friction.size() ? fm.kinetic_friction(k) : fm.static_friction(k)) * (qd(k) > 0 ? 1 : -1);
      ChainHdSolver free(chain, root_acc, opt);
      const int free_rc = free.solve(q, qd, Matrix6X(6, 0), Eigen::VectorXd(0), fext, tau0);
      // Or the value itself is beyond the double range: its terms (friction or torque times
      // acceleration) reach 1e300.
      double terms = 0.0;
      for (unsigned int k = 0; free_rc == 0 && k < n; ++k)
        terms += (fm.static_friction(k) + std::abs(fs.commandTorques()(k)) + std::abs(fs.frictionTorques()(k)) +
                  std::abs(fs.limitTorques()(k))) *
                 (std::abs(fs.qdd()(k)) + std::abs(free.qdd()(k)));
      if (free_rc != ChainHdSolver::E_NONFINITE_RESULT && std::isfinite(terms) && terms < 1e300)
        return "FrictionSolver::gaussValue non-finite after success: " + std::to_string(fs.gaussValue());
    }
    for (unsigned int k = 0; k < n; ++k) {
      const double f = fs.frictionTorques()(k);
      const double bound = std::abs(qd(k)) > fm.velocity_tolerance
                               ? (fm.kinetic_friction.size() ? fm.kinetic_friction(k) : fm.static_friction(k))
                               : fm.static_friction(k);
      if (std::abs(f) > bound * (1.0 + 1e-12)) return "friction torque exceeds its bound at joint " + std::to_string(k);
    }
  }
  return "";
}

// The same segments as a tree (each one's parent drawn among the earlier ones or the base) and
// every entry point of TreeHdSolver and of FrictionSolver on it. Reads nothing unless the next
// byte asks for a tree (inputs that end before it, as the chain-only corpus does, skip this).
std::string exerciseTree(const std::vector<KDL::Segment>& segments, ByteReader& r) {
  if (segments.empty() || r.byte() % 4 == 0) return "";
  KDL::Tree tree("base");
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const int p = r.integer(-1, static_cast<int>(i) - 1);
    tree.addSegment(segments[i], p < 0 ? "base" : segments[p].getName());
  }
  const KDL::Twist root_acc(KDL::Vector(r.value(-1, 1), r.value(-1, 1), 9.81), KDL::Vector(0, 0, r.value(-1, 1)));
  vereshchagin::TreeHdSolver hd(tree, root_acc);
  if (hd.modelError() != 0 && hd.errorMessage()[0] == '\0') return "tree modelError() set with an empty message";
  const unsigned int n = hd.nrOfJoints(), ns = hd.nrOfSegments();
  Eigen::VectorXd q(n), qd(n), ff(n);
  for (unsigned int k = 0; k < n; ++k) {
    q(k) = r.value(-3.2, 3.2);
    qd(k) = r.byte() < 96 ? 0.0 : r.value(-3.0, 3.0);
    ff(k) = r.value(-10.0, 10.0);
  }
  const int m = r.integer(0, 13);
  Matrix6X alfa(6, m);
  Eigen::VectorXd beta(m);
  Eigen::VectorXi segs(m);
  for (int c = 0; c < m; ++c) {
    for (int k = 0; k < 6; ++k) alfa(k, c) = r.value(-1.0, 1.0);
    beta(c) = r.value(-10.0, 10.0);
    segs(c) = r.integer(-1, static_cast<int>(ns));
  }
  Matrix6X fext = Matrix6X::Zero(6, (r.byte() & 1) ? ns : 0);
  for (Eigen::Index c = 0; c < fext.cols(); ++c)
    for (int k = 0; k < 6; ++k) fext(k, c) = r.value(-5.0, 5.0);
  const auto finite = [&] {
    return hd.qdd().allFinite() && hd.commandTorques().allFinite() && hd.nu().allFinite() &&
           hd.linkAccelerations().allFinite() && std::isfinite(hd.smallestSingularValue());
  };
  const int m_last = std::min(m, 7);
  int rc = hd.solve(q, qd, alfa.leftCols(m_last), beta.head(m_last), fext, ff);
  std::string bad = verdict("TreeHdSolver::solve", rc, hd.errorMessage(), finite);
  if (!bad.empty()) return bad;
  rc = hd.solve(q, qd, alfa, beta, segs, fext, ff);
  bad = verdict("TreeHdSolver::solve(segments)", rc, hd.errorMessage(), finite);
  if (!bad.empty()) return bad;
  if (rc == 0 && n > 0) {
    const Eigen::VectorXi all = Eigen::VectorXi::LinSpaced(n, 0, static_cast<int>(n) - 1);
    Eigen::MatrixXd dqdd(n, n), dtau(n, n), dnu(std::max(m, 1), n);
    rc = hd.responseColumns(all, dqdd, dtau, dnu);
    bad = verdict("TreeHdSolver::responseColumns", rc, hd.errorMessage(),
                  [&] { return dqdd.allFinite() && dtau.allFinite() && dnu.topRows(m).allFinite(); });
    if (!bad.empty()) return bad;
  }
  vereshchagin::FrictionModel fm;
  fm.static_friction.resize(n);
  for (unsigned int k = 0; k < n; ++k) fm.static_friction(k) = r.value(0.0, 20.0);
  FrictionSolver fs(tree, root_acc);
  rc = fs.solve(q, qd, alfa, beta, segs, fext, ff, fm);
  return verdict("FrictionSolver::solve(tree)", rc, fs.errorMessage(), [&] {
    return fs.qdd().allFinite() && fs.commandTorques().allFinite() && fs.frictionTorques().allFinite() &&
           fs.nu().allFinite() && fs.linkAccelerations().allFinite();
  });
}

KDL::Joint drawJoint(ByteReader& r, const std::string& name) {
  const double rotor = r.byte() < 128 ? 0.0 : r.value(0.0, 0.5);
  switch (r.integer(0, 8)) {
    case 0:
      return KDL::Joint(name, KDL::Joint::RotX, 1.0, 0.0, rotor);
    case 1:
      return KDL::Joint(name, KDL::Joint::RotY, 1.0, 0.0, rotor);
    case 2:
      return KDL::Joint(name, KDL::Joint::RotZ, 1.0, 0.0, rotor);
    case 3:
      return KDL::Joint(name, KDL::Joint::TransX, 1.0, 0.0, rotor);
    case 4:
      return KDL::Joint(name, KDL::Joint::TransY, 1.0, 0.0, rotor);
    case 5:
      return KDL::Joint(name, KDL::Joint::TransZ, 1.0, 0.0, rotor);
    case 6:
    case 7: {
      const KDL::Vector origin(r.value(-0.5, 0.5), r.value(-0.5, 0.5), r.value(-0.5, 0.5));
      KDL::Vector axis(r.value(-1, 1), r.value(-1, 1), r.value(-1, 1));
      return KDL::Joint(name, origin, axis, r.byte() & 1 ? KDL::Joint::RotAxis : KDL::Joint::TransAxis, 1.0, 0.0,
                        rotor);
    }
    default:
      return KDL::Joint(name, KDL::Joint::Fixed);
  }
}

}  // namespace

namespace {

// The tree loader on the same text: ok with an empty message or a failure with one; a loaded
// tree's segment order, parents, q_nr and joint metadata agree with each other.
std::string checkUrdfTree(const std::string& xml) {
  const vereshchagin::UrdfTreeResult res = vereshchagin::treeFromUrdfString(xml);
  if (!res.ok) return res.message.empty() ? "URDF tree rejected with an empty message" : "";
  if (!res.message.empty()) return "URDF tree loaded but with a message";
  const vereshchagin::RobotTree& robot = res.robot;
  const std::size_t ns = robot.segment_names.size();
  if (robot.tree.getNrOfSegments() != ns || robot.tree.getNrOfJoints() != ns || robot.joints.size() != ns ||
      robot.parent.size() != ns)
    return "tree: segment, joint and parent counts differ";
  std::vector<KDL::SegmentMap::const_iterator> order;
  std::vector<int> parent;
  vereshchagin::treeSegmentOrder(robot.tree, order, parent);
  if (parent != robot.parent) return "tree: parent array differs from treeSegmentOrder";
  for (std::size_t i = 0; i < ns; ++i) {
    if (order[i]->first != robot.segment_names[i]) return "tree: segment order differs from treeSegmentOrder";
    if (GetTreeElementQNr(order[i]->second) != i || robot.joints[i].segment != i) return "tree: q_nr is not preorder";
    if (robot.parent[i] >= static_cast<int>(i)) return "tree: a parent follows its child";
    const auto& j = robot.joints[i];
    if (!(j.friction >= 0.0) || !std::isfinite(j.friction) || !(j.lower <= j.upper) || !(j.damping >= 0.0))
      return "tree: loaded joint '" + j.name + "' has invalid friction, damping or limits";
  }
  return "";
}

}  // namespace

std::string checkUrdf(const std::uint8_t* data, std::size_t size) {
  const std::string xml(reinterpret_cast<const char*>(data), size);
  const std::string tree_violation = checkUrdfTree(xml);
  if (!tree_violation.empty()) return tree_violation;
  const vereshchagin::UrdfResult res = vereshchagin::chainFromUrdfString(xml);
  if (!res.ok) return res.message.empty() ? "URDF rejected with an empty message" : "";
  if (!res.message.empty()) return "URDF loaded but with a message";
  const auto& robot = res.robot;
  const unsigned int n = robot.chain.getNrOfJoints();
  if (robot.joints.size() != n) return "JointInfo count differs from the chain's joints";
  Eigen::VectorXd friction(n), lower(n), upper(n);
  for (unsigned int k = 0; k < n; ++k) {
    const auto& j = robot.joints[k];
    if (!(j.friction >= 0.0) || !std::isfinite(j.friction) || !(j.lower <= j.upper) || !(j.damping >= 0.0))
      return "loaded joint '" + j.name + "' has invalid friction, damping or limits";
    friction(k) = j.friction;
    lower(k) = j.lower;
    upper(k) = j.upper;
  }
  // Solver inputs: a fixed pseudo-random stream derived from the text's length.
  std::uint8_t stream[512];
  for (std::size_t k = 0; k < sizeof stream; ++k) stream[k] = static_cast<std::uint8_t>((k * 131u + size * 17u) & 0x7f);
  ByteReader r(stream, sizeof stream);
  return exerciseChain(robot.chain, r, &friction, &lower, &upper);
}

std::string checkSolver(const std::uint8_t* data, std::size_t size) {
  ByteReader r(data, size);
  KDL::Chain chain;
  const int segments = r.integer(0, 8);
  for (int i = 0; i < segments; ++i) {
    const KDL::Joint joint = drawJoint(r, "j" + std::to_string(i));
    const KDL::Frame tip(KDL::Rotation::RPY(r.value(-3.2, 3.2), r.value(-3.2, 3.2), r.value(-3.2, 3.2)),
                         KDL::Vector(r.value(-1, 1), r.value(-1, 1), r.value(-1, 1)));
    const double mass = r.value(0.0, 5.0);
    const KDL::Vector com(r.value(-0.3, 0.3), r.value(-0.3, 0.3), r.value(-0.3, 0.3));
    // Rotational inertia about the centre of mass: mostly a valid diagonal, sometimes anything.
    const double a = r.value(0.0, 0.5), b = r.value(0.0, 0.5), c = r.value(0.0, 0.5);
    const double xy = r.byte() < 200 ? 0.0 : r.value(-0.5, 0.5);
    chain.addSegment(KDL::Segment("s" + std::to_string(i), joint, tip,
                                  KDL::RigidBodyInertia(mass, com, KDL::RotationalInertia(a, b, c, xy, 0.0, 0.0))));
  }
  const std::string bad = exerciseChain(chain, r, nullptr, nullptr, nullptr);
  if (!bad.empty()) return bad;
  return exerciseTree(chain.segments, r);
}

}  // namespace fuzzutil
