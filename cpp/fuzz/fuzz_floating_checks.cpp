// checkFloating (fuzz_checks.hpp): random floating trees (free-flyer and planar bases, base_kind.hpp)
// and random inputs through the (model, data, input) API: solve with segment constraints, the
// dynamics and momentum companions, step, stepSymplectic and integrateConfiguration. The base's
// quaternion (or (cos, sin)) is drawn unit, slightly off (within and beyond the accepted 1e-6), or
// anything. Properties: every call returns ok with finite outputs, or an error with a message; a
// finite base configuration whose norm is off 1 by more than 1e-5 is refused by solve() with a
// message naming the unit norm.
#include <cmath>
#include <string>

#include <Eigen/Core>
#include <kdl/tree.hpp>

#include "fuzz_checks.hpp"
#include "fuzz_input.hpp"
#include "vereshchagin/base_kind.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/input.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/momentum.hpp"

namespace fuzzutil {

namespace {

using vereshchagin::Status;

// "" if s is ok with finite outputs or an error with a message; else the violation.
template <typename Outputs>
std::string judge(const char* call, const Status& s, Outputs&& outputs_finite) {
  if (s.ok()) return outputs_finite() ? "" : std::string(call) + " succeeded with non-finite outputs";
  if (s.message() == nullptr || s.message()[0] == '\0')
    return std::string(call) + " failed with code " + std::to_string(static_cast<int>(s.code())) +
           " but an empty message";
  return "";
}

KDL::Joint floatingJoint(ByteReader& r, const std::string& name) {
  const KDL::Vector origin(r.value(-0.5, 0.5), r.value(-0.5, 0.5), r.value(-0.5, 0.5));
  const KDL::Vector axis(r.value(-1, 1), r.value(-1, 1), r.value(-1, 1));
  switch (r.integer(0, 4)) {
    case 0:
      return KDL::Joint(name, KDL::Joint::RotZ);
    case 1:
      return KDL::Joint(name, KDL::Joint::TransX);
    case 2:
      return KDL::Joint(name, KDL::Joint::Fixed);
    default:
      return KDL::Joint(name, origin, axis, r.byte() & 1 ? KDL::Joint::RotAxis : KDL::Joint::TransAxis);
  }
}

// A tree of 0..8 segments under "root", each on a drawn earlier segment (or the root).
KDL::Tree floatingTree(ByteReader& r) {
  KDL::Tree tree("root");
  const int segments = r.integer(0, 8);
  for (int i = 0; i < segments; ++i) {
    const int parent = r.integer(-1, i - 1);
    const KDL::Frame tip(KDL::Rotation::RPY(r.value(-3.2, 3.2), r.value(-3.2, 3.2), r.value(-3.2, 3.2)),
                         KDL::Vector(r.value(-1, 1), r.value(-1, 1), r.value(-1, 1)));
    const double a = r.value(0.0, 0.5), b = r.value(0.0, 0.5), c = r.value(0.0, 0.5);
    const KDL::RigidBodyInertia inertia(r.value(0.0, 5.0), KDL::Vector(r.value(-0.3, 0.3), 0.0, r.value(-0.3, 0.3)),
                                        KDL::RotationalInertia(a, b, c, 0.0, 0.0, 0.0));
    const std::string name = "s" + std::to_string(i);
    tree.addSegment(KDL::Segment(name, floatingJoint(r, "j" + std::to_string(i)), tip, inertia),
                    parent < 0 ? "root" : "s" + std::to_string(parent));
  }
  return tree;
}

// The base's configuration entries: position, then a unit (or nearly, or any) quaternion / (cos,
// sin). Returns how far its norm is from 1 (NaN when not finite).
double drawBase(ByteReader& r, vereshchagin::BaseKind kind, Eigen::Ref<Eigen::VectorXd> q) {
  const bool ff = kind == vereshchagin::BaseKind::FreeFlyer;
  const int p = ff ? 3 : 2, k = ff ? 4 : 2;
  for (int i = 0; i < p; ++i) q(i) = r.value(-2.0, 2.0);
  for (int i = 0; i < k; ++i) q(p + i) = r.unit(-1.0, 1.0);
  if (q.segment(p, k).norm() < 1e-3) q(p + k - 1) = 1.0;
  q.segment(p, k).normalize();
  const std::uint8_t mode = r.byte();
  if (mode >= 128 && mode < 208) {  // slightly off: 1e-12 .. 1e-3 relative
    q.segment(p, k) *= 1.0 + std::pow(10.0, -r.unit(3.0, 12.0)) * (mode & 1 ? 1.0 : -1.0);
  } else if (mode >= 208) {
    for (int i = 0; i < k; ++i) q(p + i) = r.value(-1.0, 1.0);
  }
  return std::abs(q.segment(p, k).norm() - 1.0);
}

// The companions on the input's state; "" or the violation.
std::string companions(const vereshchagin::Model& model, const vereshchagin::SolveInput& in) {
  using namespace vereshchagin;
  const long nv = static_cast<long>(model.nv());
  DynamicsData dd(model);
  Eigen::MatrixXd H(nv, nv), Jc(3, nv);
  Eigen::VectorXd tau(nv), acc = in.q_dot;
  Eigen::Vector3d c, cv;
  Vector6 h;
  const JointPositions q(in.q);
  const JointVelocities qd(in.q_dot);
  std::string bad = judge("massMatrix", massMatrix(model, dd, q, H), [&] { return H.allFinite(); });
  if (bad.empty())
    bad =
        judge("inverseDynamics", inverseDynamics(model, dd, q, qd, JointAccelerations(acc), in.f_ext, in.gravity, tau),
              [&] { return tau.allFinite(); });
  if (bad.empty())
    bad = judge("gravityTorques", gravityTorques(model, dd, q, in.gravity, tau), [&] { return tau.allFinite(); });
  if (bad.empty())
    bad = judge("coriolisTorques", coriolisTorques(model, dd, q, qd, tau), [&] { return tau.allFinite(); });
  if (bad.empty()) bad = judge("centerOfMass", centerOfMass(model, dd, q, c), [&] { return c.allFinite(); });
  if (bad.empty())
    bad = judge("centerOfMassJacobian", centerOfMassJacobian(model, dd, q, Jc), [&] { return Jc.allFinite(); });
  if (bad.empty())
    bad = judge("centerOfMassVelocity", centerOfMassVelocity(model, dd, q, qd, cv), [&] { return cv.allFinite(); });
  if (bad.empty())
    bad = judge("centroidalMomentum", centroidalMomentum(model, dd, q, qd, h), [&] { return h.allFinite(); });
  return bad;
}

// solve, step, stepSymplectic and integrateConfiguration on the input; "" or the violation.
// `clean`: every input finite and no constraint, so that only the base's norm can be refused.
std::string solves(const vereshchagin::Model& model, vereshchagin::SolveInput& in, double off_unit, bool clean) {
  using namespace vereshchagin;
  Data data(model);
  const Status s = solve(model, data, in);
  std::string bad = judge(
      "solve", s, [&] { return data.qdd().allFinite() && data.commandTorques().allFinite() && data.nu().allFinite(); });
  if (!bad.empty()) return bad;
  if (s.ok() && off_unit > 1e-5)
    return "solve accepted a base configuration whose norm is off 1 by " + std::to_string(off_unit);
  if (!s.ok() && clean && off_unit > 1e-5 && std::string(s.message()).find("unit") == std::string::npos)
    return std::string("a non-unit base configuration refused without saying so: ") + s.message();
  const long nq = static_cast<long>(model.nq()), nv = static_cast<long>(model.nv());
  Eigen::VectorXd q_next(nq), qd_next(nv), p_next(nv);
  in.time_step = 1e-3;
  bad =
      judge("step", step(model, data, in, q_next, qd_next), [&] { return q_next.allFinite() && qd_next.allFinite(); });
  if (!bad.empty()) return bad;
  const Eigen::VectorXd momentum = in.q_dot;
  bad = judge("stepSymplectic", stepSymplectic(model, data, in, momentum, q_next, qd_next, p_next),
              [&] { return q_next.allFinite() && qd_next.allFinite() && p_next.allFinite(); });
  in.time_step = 0.0;
  if (!bad.empty() || !(off_unit <= 1e-6) || !in.q.allFinite() || !in.q_dot.allFinite()) return bad;
  integrateConfiguration(model.baseKind(), in.q, in.q_dot, 1e-3, q_next);
  if (!q_next.allFinite() && in.q_dot.cwiseAbs().maxCoeff() < 1e6) return "integrateConfiguration: non-finite q_next";
  return "";
}

}  // namespace

std::string checkFloating(const std::uint8_t* bytes, std::size_t size) {
  using namespace vereshchagin;
  ByteReader r(bytes, size);
  ModelOptions options;
  options.base = r.byte() & 1 ? BaseKind::Planar : BaseKind::FreeFlyer;
  const bool odd = r.byte() >= 230;  // the base's inertia: mostly a rigid body, sometimes anything
  const double a = odd ? r.value(-1.0, 1.0) : r.unit(0.01, 1.0), b = odd ? r.value(-1.0, 1.0) : r.unit(0.01, 1.0);
  options.base_inertia = KDL::RigidBodyInertia(odd ? r.value(-1.0, 10.0) : r.unit(0.1, 10.0),
                                               KDL::Vector(r.value(-0.2, 0.2), r.value(-0.2, 0.2), 0.0),
                                               KDL::RotationalInertia(a, b, a + b, 0.0, 0.0, 0.0));
  const Model model(floatingTree(r), "", options);
  if (!model.status()) return model.status().message()[0] == '\0' ? "model refused with an empty message" : "";
  const long nq = static_cast<long>(model.nq()), nv = static_cast<long>(model.nv());
  const int nbq = static_cast<int>(nq - model.nrOfJoints()), nbv = static_cast<int>(nv - model.nrOfJoints());
  SolveInput in(model, 3, 0);
  const double off_unit = drawBase(r, options.base, in.q);
  for (long i = nbq; i < nq; ++i) in.q(i) = r.value(-3.2, 3.2);
  for (long i = 0; i < nv; ++i) in.q_dot(i) = r.value(-3.0, 3.0);
  for (long i = 0; i < nv; ++i) in.ff_torques(i) = i < nbv && r.byte() < 192 ? 0.0 : r.value(-10.0, 10.0);
  in.gravity = KDL::Vector(r.value(-1.0, 1.0), r.value(-1.0, 1.0), -9.81);
  if (r.byte() & 1)
    for (long c = 0; c < in.f_ext.cols(); ++c)
      for (int k = 0; k < 6; ++k) in.f_ext(k, c) = r.value(-5.0, 5.0);
  const int blocks = r.integer(0, 3);
  for (int b = 0; b < blocks; ++b) {
    const int seg = r.integer(-1, static_cast<int>(model.nrOfSegments()));
    const int k = r.integer(1, 6);
    Eigen::MatrixXd alfa(6, k);
    Eigen::VectorXd beta(k);
    for (int c = 0; c < k; ++c) {
      for (int i = 0; i < 6; ++i) alfa(i, c) = r.value(-1.0, 1.0);
      beta(c) = r.value(-10.0, 10.0);
    }
    const Status s = in.addConstraint(seg, alfa, beta);
    if (!s.ok() && s.message()[0] == '\0') return "addConstraint failed with an empty message";
  }
  const bool clean = blocks == 0 && in.q.allFinite() && in.q_dot.allFinite() && in.ff_torques.allFinite() &&
                     in.f_ext.allFinite() && std::isfinite(in.gravity.Norm());
  const std::string bad = solves(model, in, off_unit, clean);
  return bad.empty() ? companions(model, in) : bad;
}

}  // namespace fuzzutil
