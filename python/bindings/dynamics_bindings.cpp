// Dynamics companions of the Python Chain: thin wrappers of KDL's ChainIdSolver_RNE (inverse
// dynamics), ChainDynParam (mass matrix, gravity and Coriolis torques), ChainJntToJacDotSolver
// (Jdot qd) and ChainFkSolverPos_recursive (every segment's pose), in the conventions of the
// hybrid solver: physical gravity in the base frame, external wrenches in base-frame axes with the
// moment about each segment's tip origin, applied ON the segment BY the environment.
#include <pybind11/stl.h>

#include <vector>

#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainfksolvervel_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacdotsolver.hpp>
#include <kdl/jntarrayvel.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>

#include "chain_bindings.hpp"
#include "dynamics_common.hpp"
#include "dynamics_docs.hpp"

namespace vsbind {

namespace {

// Tip frame of every segment in the base frame (empty for a chain without segments).
std::vector<KDL::Frame> tipFrames(const KDL::Chain& chain, const KDL::JntArray& q) {
  std::vector<KDL::Frame> frames(chain.getNrOfSegments());
  if (frames.empty()) return frames;
  KDL::ChainFkSolverPos_recursive fk(chain);
  if (fk.JntToCart(q, frames) < 0) raise("forward kinematics failed");
  return frames;
}

// Our f_ext (n_segments, 6): rows [force, moment], base-frame axes, moment about the segment's tip
// origin, applied ON the segment. KDL's RNE wants the same wrench (same sign: it subtracts f_ext
// from the wrench the segment needs) in the segment's tip-frame axes: rotate both halves.
KDL::Wrenches externalWrenches(const py::object& f_ext, const PyChain& c, const KDL::JntArray& q) {
  const KDL::Chain& chain = c.robot.chain;
  const unsigned int ns = chain.getNrOfSegments();
  KDL::Wrenches out(ns, KDL::Wrench::Zero());
  if (f_ext.is_none()) return out;
  const std::vector<KDL::Frame> tips = tipFrames(chain, q);
  const auto rows = externalWrenchRows(f_ext, c, [&tips](int s) { return tips[static_cast<std::size_t>(s)].M; });
  for (unsigned int i = 0; i < ns; ++i) {
    const Eigen::Matrix<double, 6, 1>& r = rows[i];
    out[i] = tips[i].M.Inverse(KDL::Wrench(KDL::Vector(r(0), r(1), r(2)), KDL::Vector(r(3), r(4), r(5))));
  }
  return out;
}

py::array_t<double> inverseDynamics(const PyChain& c, const py::object& q_obj, const py::object& qd_obj,
                                    const py::object& qdd_obj, const py::object& f_ext, const py::object& gravity) {
  const KDL::Chain& chain = c.robot.chain;
  const unsigned int n = chain.getNrOfJoints();
  const KDL::JntArray q = jntArrayArg(q_obj, "q", n);
  const KDL::JntArray qd = jntArrayArg(qd_obj, "qd", n);
  const KDL::JntArray qdd = jntArrayArg(qdd_obj, "qdd", n);
  const KDL::Vector g = vec3(gravity, "gravity");
  const KDL::Wrenches wrenches = externalWrenches(f_ext, c, q);
  KDL::JntArray tau(n);
  KDL::ChainIdSolver_RNE rne(chain, g);  // KDL takes physical gravity here (base accelerates by -g)
  if (rne.CartToJnt(q, qd, qdd, wrenches, tau) < 0)
    raise("inverse dynamics failed: " + std::string(rne.strError(rne.getError())));
  return jointTorques(tau, "inverse_dynamics");
}

py::array_t<double> massMatrix(const PyChain& c, const py::object& q_obj) {
  const KDL::Chain& chain = c.robot.chain;
  const unsigned int n = chain.getNrOfJoints();
  const KDL::JntArray q = jntArrayArg(q_obj, "q", n);
  KDL::JntSpaceInertiaMatrix H(n);
  KDL::ChainDynParam dyn(chain, KDL::Vector::Zero());
  if (dyn.JntToMass(q, H) < 0) raise("mass matrix computation failed: " + std::string(dyn.strError(dyn.getError())));
  return jointMatrix(H.data, "mass_matrix");
}

py::array_t<double> gravityTorques(const PyChain& c, const py::object& q_obj, const py::object& gravity) {
  const KDL::Chain& chain = c.robot.chain;
  const KDL::JntArray q = jntArrayArg(q_obj, "q", chain.getNrOfJoints());
  KDL::JntArray tau(chain.getNrOfJoints());
  KDL::ChainDynParam dyn(chain, vec3(gravity, "gravity"));
  if (dyn.JntToGravity(q, tau) < 0) raise("gravity torques failed: " + std::string(dyn.strError(dyn.getError())));
  return jointTorques(tau, "gravity_torques");
}

py::array_t<double> coriolisTorques(const PyChain& c, const py::object& q_obj, const py::object& qd_obj) {
  const KDL::Chain& chain = c.robot.chain;
  const unsigned int n = chain.getNrOfJoints();
  const KDL::JntArray q = jntArrayArg(q_obj, "q", n);
  const KDL::JntArray qd = jntArrayArg(qd_obj, "qd", n);
  KDL::JntArray tau(n);
  KDL::ChainDynParam dyn(chain, KDL::Vector::Zero());
  if (dyn.JntToCoriolis(q, qd, tau) < 0) raise("Coriolis torques failed: " + std::string(dyn.strError(dyn.getError())));
  return jointTorques(tau, "coriolis_torques");
}

// d/dt(J) qd of the (6, n) base-axes Jacobian of a segment tip or merged link origin: [classical
// linear acceleration of that point; angular acceleration] at qdd = 0, gravity not included.
py::array_t<double> jacobianDotTimesQd(const PyChain& c, const py::object& q_obj, const py::object& qd_obj,
                                       const py::object& segment) {
  const KDL::Chain& chain = c.robot.chain;
  const unsigned int n = chain.getNrOfJoints();
  const KDL::JntArrayVel state(jntArrayArg(q_obj, "q", n), jntArrayArg(qd_obj, "qd", n));
  const PyChain::Target target = c.resolveOptional(segment, "segment");
  const int seg = target.segment;
  const KDL::Frame& link_in_tip = target.link_in_tip;
  py::array_t<double> out(6);
  std::fill(out.mutable_data(), out.mutable_data() + 6, 0.0);
  if (seg < 0) return out;                  // a base link does not move
  KDL::ChainJntToJacDotSolver jdot(chain);  // HYBRID: base axes, reference point the tip origin
  KDL::Twist at_tip;
  if (jdot.JntToJacDot(state, at_tip, seg + 1) < 0)
    raise("Jdot qd failed: " + std::string(jdot.strError(jdot.getError())));
  KDL::ChainFkSolverVel_recursive fkv(chain);
  KDL::FrameVel tip;
  if (fkv.JntToCart(state, tip, seg + 1) < 0) raise("forward velocity kinematics failed");
  // A point fixed at r from the tip origin: d/dt (v + w x r) = dv + dw x r + w x (w x r).
  const KDL::Vector r = tip.M.R * link_in_tip.p;
  const KDL::Vector w = tip.GetTwist().rot;
  const KDL::Vector lin = at_tip.vel + at_tip.rot * r + w * (w * r);
  const double values[6] = {lin.x(), lin.y(), lin.z(), at_tip.rot.x(), at_tip.rot.y(), at_tip.rot.z()};
  requireFiniteResult(values, 6, "jacobian_dot_times_qd");
  std::copy(values, values + 6, out.mutable_data());
  return out;
}

py::array_t<double> fkAll(const PyChain& c, const py::object& q_obj) {
  const KDL::Chain& chain = c.robot.chain;
  const std::vector<KDL::Frame> tips = tipFrames(chain, jntArrayArg(q_obj, "q", chain.getNrOfJoints()));
  return homogeneousStack(tips);
}

}  // namespace

void bindDynamics(py::module_& mod) {
  auto chain = py::reinterpret_borrow<py::class_<PyChain>>(mod.attr("Chain"));
  chain.def("inverse_dynamics", &inverseDynamics, py::arg("q"), py::arg("qd"), py::arg("qdd"),
            py::arg("f_ext") = py::none(), py::arg("gravity") = kEarthGravity,
            docs::inverseDynamicsDoc("recursive Newton-Euler, KDL's ChainIdSolver_RNE", "",
                                     "; converted to KDL's\n    tip-frame axes internally", "")
                .c_str());
  chain.def("mass_matrix", &massMatrix, py::arg("q"),
            docs::massMatrixDoc("KDL's ChainDynParam::JntToMass", "").c_str());
  chain.def("gravity_torques", &gravityTorques, py::arg("q"), py::arg("gravity") = kEarthGravity,
            docs::gravityTorquesDoc("chain", " (KDL's ChainDynParam::JntToGravity)").c_str());
  chain.def("coriolis_torques", &coriolisTorques, py::arg("q"), py::arg("qd"),
            docs::coriolisTorquesDoc(" (KDL's ChainDynParam::JntToCoriolis)").c_str());
  chain.def(
      "jacobian_dot_times_qd", &jacobianDotTimesQd, py::arg("q"), py::arg("qd"), py::arg("segment") = py::none(),
      docs::jacobianDotDoc("jacobian_dot_times_qd(q, qd)",
                           "Computed by KDL's ChainJntToJacDotSolver (HYBRID representation), the reference point "
                           "then\nmoved to the link origin.",
                           "segment : str or int, optional\n"
                           "    As in :meth:`fk`: a segment name or index (negative from the end), or a merged "
                           "link's name;\n    default the last segment. A base link gives zeros.\n")
          .c_str());
  chain.def("fk_all", &fkAll, py::arg("q"), docs::fkAllDoc("").c_str());
}

}  // namespace vsbind
