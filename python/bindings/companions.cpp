// The companions of Chain and Tree (companions.hpp), bound on both by one template: Python arguments
// converted to arrays and handed, one at a time, to the C++ library's checks (companion_call.hpp),
// which then computes into a numpy array of the shape it reports. Conventions (the solver's):
// physical gravity, base axes; f_ext ON each segment BY the environment.
#include "model_class.hpp"
#include "vereshchagin/companion_call.hpp"

namespace vsbind {

namespace vs = vereshchagin;
using K = vs::Companion;

vs::DynamicsData& CompanionModel::companions() const {
  if (!cache_) cache_ = std::make_shared<vs::DynamicsData>(buildModel());
  return *cache_;
}

namespace {

void check(const vs::Status& s) {
  if (!s) raise(s.message());
}

// An f_ext dict {segment or link: wrench (6,), moment about that frame's origin} as the
// (n_segments, 6) rows of the tip wrenches at q (C++ addFrameWrench), held by the view.
F64View wrenchRows(const CompanionModel& m, vs::DynamicsData& d, const py::dict& f_ext, const vs::ArrayArg& q) {
  const py::ssize_t ns = d.model().nrOfSegments();
  F64View rows;
  rows.keep = newDoubles({ns, 6});
  Eigen::Map<vs::Matrix6X> sums(doubles(rows.keep), 6, ns);
  sums.setZero();
  check(vs::forwardKinematics(d.model(), d.kinematics(),
                              vs::JointPositions(Eigen::Map<const Eigen::VectorXd>(q.data, q.size()))));
  for (const auto& item : f_ext) {
    const std::string label = "f_ext[" + py::repr(item.first).cast<std::string>() + "]";
    const FrameTarget t = m.resolveMoving(item.first.ptr(), label);
    const F64View w = vectorView(item.second.ptr(), label.c_str(), 6);
    check(vs::addFrameWrench(d.model(), d.kinematics(), {t.segment, t.link_in_tip},
                             Eigen::Map<const vs::Vector6>(w.data), sums));
  }
  static_cast<vs::ArrayArg&>(rows) = asF64(rows.keep.ptr(), "f_ext");
  return rows;
}

// Companion `kind` of m on its Python arguments in vs::CompanionArg order (q, qd, qdd, gravity,
// f_ext; an empty handle where it takes none, f_ext None for no wrenches), each converted and
// checked in turn.
py::array run(const CompanionModel& m, K kind, std::array<py::handle, 5> args, const FrameTarget& frame = {}) {
  static const char* const names[5] = {"q", "qd", "qdd", "gravity", "f_ext"};
  vs::DynamicsData& d = m.companions();
  vs::CompanionCall call{kind, {}, {frame.segment, frame.link_in_tip}};
  F64View views[5];
  for (int k = 0; k < 5; ++k) {
    if (!args[k] || (k == 4 && args[k].is_none())) continue;
    const bool dict = k == 4 && PyDict_Check(args[k].ptr());
    views[k] = dict ? wrenchRows(m, d, args[k].cast<py::dict>(), views[0]) : asF64(args[k].ptr(), names[k]);
    call.args[k] = views[k];
    check(vs::checkCompanionArg(d.kinematics(), call, static_cast<vs::CompanionArg>(k)));
  }
  int ndim = 0;
  py::ssize_t shape[3];
  check(vs::companionShape(d.kinematics(), call, ndim, shape));
  py::array out = newArray(py::detail::npy_api::NPY_DOUBLE_, ndim, shape, /*fortran=*/kind == K::Jacobian);
  check(vs::callCompanion(d.model(), d, call, doubles(out)));
  return out;
}

// Binds the companions on Chain or Tree (M): `segment` is the spec of the frame argument of fk,
// jacobian, twist and jacobian_dot_times_qd, `frame` resolves it.
template <typename M, typename S, typename F>
void bindCompanions(py::class_<M>& cls, const std::string& name, const S& segment, F frame) {
  const py::array earth = newDoubles({3});  // physical gravity, base z up, m/s^2 (viewed in place)
  Eigen::Map<Eigen::Vector3d>(doubles(earth)) << 0.0, 0.0, -9.81;
  const py::arg_v gravity("gravity", earth, "[0.0, 0.0, -9.81]");
  const auto key = [&name](const char* method) { return doc(name + "." + method); };
  cls.def(
         "fk", [frame](const M& m, O q, O s) { return run(m, K::Fk, {q}, frame(m, s)); }, py::arg("q"), segment,
         key("fk"))
      .def(
          "jacobian", [frame](const M& m, O q, O s) { return run(m, K::Jacobian, {q}, frame(m, s)); }, py::arg("q"),
          segment, key("jacobian"))
      .def(
          "twist",
          [frame](const M& m, O q, O qd, O s) {
            return run(m, K::Twist, {q, qd}, frame(m, s));
          },
          py::arg("q"), py::arg("qd"), segment, key("twist"))
      .def(
          "inverse_dynamics",
          [](const M& m, O q, O qd, O qdd, O f, O g) {
            return run(m, K::InverseDynamics, {q, qd, qdd, g, f});
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("f_ext") = py::none(), gravity, key("inverse_dynamics"))
      .def(
          "mass_matrix", [](const M& m, O q) { return run(m, K::MassMatrix, {q}); }, py::arg("q"), key("mass_matrix"))
      .def(
          "gravity_torques",
          [](const M& m, O q, O g) {
            return run(m, K::GravityTorques, {q, {}, {}, g});
          },
          py::arg("q"), gravity, key("gravity_torques"))
      .def(
          "coriolis_torques",
          [](const M& m, O q, O qd) {
            return run(m, K::CoriolisTorques, {q, qd});
          },
          py::arg("q"), py::arg("qd"), key("coriolis_torques"))
      .def(
          "jacobian_dot_times_qd",
          [frame](const M& m, O q, O qd, O s) {
            return run(m, K::JacobianDotTimesQd, {q, qd}, frame(m, s));
          },
          py::arg("q"), py::arg("qd"), segment, key("jacobian_dot_times_qd"))
      .def(
          "fk_all", [](const M& m, O q) { return run(m, K::FkAll, {q}); }, py::arg("q"), key("fk_all"));
}

}  // namespace

void bindDynamics(py::module_& mod) {
  auto chain = py::reinterpret_borrow<py::class_<PyChain>>(mod.attr("Chain"));
  bindCompanions(chain, "Chain", py::arg("segment") = py::none(),
                 [](const PyChain& c, O s) { return c.resolveOptional(s, "segment"); });
  auto tree = py::reinterpret_borrow<py::class_<PyTree>>(mod.attr("Tree"));
  bindCompanions(tree, "Tree", py::arg("segment"),
                 [](const PyTree& t, O s) { return t.resolveTarget(s.ptr(), "segment"); });
}

}  // namespace vsbind
