// The companions of Chain and Tree (model_class.hpp: CompanionModel), bound on both by one template, and task.py's
// fast path _core._beta_for (task.hpp's betaShape, betaFromArrays). Each Python argument becomes an
// array that the C++ library checks (companion_call.hpp) and computes on, into a numpy array of the
// shape it reports. Conventions (the solver's): physical gravity, base axes; f_ext ON each segment.
#include "model_class.hpp"
#include "vereshchagin/companion_call.hpp"
#include "vereshchagin/task.hpp"

namespace vsbind {

namespace vs = vereshchagin;
using K = vs::Companion;

namespace {

// gravity as a list or tuple of three Python floats, read into g (storage) and viewed by `arg`
// without numpy (false: anything else, converted by asF64). Values are checked with the others'.
bool floatTriple(PyObject* obj, double g[3], vs::ArrayArg& arg) {
  if ((!PyList_CheckExact(obj) && !PyTuple_CheckExact(obj)) || PySequence_Fast_GET_SIZE(obj) != 3) return false;
  PyObject** x = PySequence_Fast_ITEMS(obj);
  for (int k = 0; k < 3; ++k) {
    if (!PyFloat_CheckExact(x[k])) return false;
    g[k] = PyFloat_AS_DOUBLE(x[k]);
  }
  arg = vs::ArrayArg{g, 1, {3, 0, 0}};
  return true;
}

// An f_ext dict {segment or link: wrench (6,), moment about that frame's origin}: frame wrenches.
void frameWrenches(const CompanionModel& m, vs::CompanionCall& call, const py::handle& f_ext) {
  call.frame_wrenches_given = true;
  for (const auto& item : f_ext.cast<py::dict>()) {
    const std::string label = "f_ext[" + py::repr(item.first).cast<std::string>() + "]";
    const FrameTarget t = m.resolveMoving(item.first.ptr(), label);
    const F64View w = vectorView(item.second.ptr(), label.c_str(), 6);
    call.frame_wrenches.push_back({{t.segment, t.link_in_tip}, Eigen::Map<const vs::Vector6>(w.data)});
  }
}

// Companion `kind` of m on its Python arguments in vs::CompanionArg order (q, qd, qdd, gravity,
// f_ext; an empty handle where it takes none, f_ext None for no wrenches), each converted and
// checked in turn; float64 arrays are viewed in place, converted copies live in `keep`.
py::array run(const CompanionModel& m, K kind, std::array<py::handle, 5> args, const FrameTarget& frame = {}) {
  vs::DynamicsData& d = m.companions();  // d.kinematics() holds every message
  vs::CompanionCall call{kind, {}, {frame.segment, frame.link_in_tip}};
  py::object keep[5];
  double g[3];
  for (int k = 0; k < 5; ++k) {
    PyObject* obj = args[k].ptr();
    if (obj == nullptr || (k == 4 && obj == Py_None)) continue;
    if (k == 4 && PyDict_Check(obj)) {
      frameWrenches(m, call, args[k]);  // checked there; the f_ext rows stay none
    } else if (k != 3 || !floatTriple(obj, g, call.args[3])) {
      F64View v = asF64(obj, vs::companionArgName(static_cast<vs::CompanionArg>(k)));
      call.args[k] = v;
      keep[k] = std::move(v.keep);
    }
    check(vs::checkCompanionArg(d.kinematics(), call, static_cast<vs::CompanionArg>(k)));
  }
  int ndim = 0;
  py::ssize_t shape[3];
  check(vs::companionShape(d.kinematics(), call, ndim, shape));
  py::array out = newArray(py::detail::npy_api::NPY_DOUBLE_, ndim, shape,
                           /*fortran=*/kind == K::Jacobian || kind == K::CenterOfMassJacobian);
  check(vs::callCompanion(d.model(), d, call, doubles(out)));
  return out;
}

// _beta_for: alpha (6,) or (6, m), a_desired (6,) or one row per twist, twist (6,) or (N, 6),
// gravity (3,): beta (m,) or (N, m) rows; None for inputs that are not plainly valid (task.py then
// checks them and raises its own messages).
py::object betaFor(O alpha, O a_desired, O twist, O gravity) {
  F64View v[4];
  try {
    int k = 0;
    for (const py::handle obj : {alpha, a_desired, twist, gravity}) v[k++] = asF64(obj.ptr(), "");
  } catch (const SolverError&) {
    return py::none();
  }
  int ndim = 0;
  py::ssize_t shape[2];
  if (!vs::betaShape(v[0], v[1], v[2], v[3], ndim, shape)) return py::none();
  py::array out = newArray(py::detail::npy_api::NPY_DOUBLE_, ndim, shape);
  if (!vs::betaFromArrays(v[0], v[1], v[2], v[3], doubles(out)))
    raise("beta_for: the result overflows the double range (inputs too large)");
  return std::move(out);
}

// Binds the companions on Chain or Tree (M): `segment` is the spec of the frame argument of fk,
// jacobian, twist and jacobian_dot_times_qd, `frame` resolves it.
template <typename M, typename S, typename F>
void bindCompanions(py::class_<M>& cls, const std::string& name, const S& segment, F frame) {
  const double earth[3] = {0.0, 0.0, -9.81};  // physical gravity, base z up, m/s^2 (a float64 array: viewed)
  const py::arg_v gravity("gravity", py::array_t<double>(3, earth), "[0.0, 0.0, -9.81]");
  const auto key = [&name](const char* method) { return doc(name + "." + method); };
  const auto fk = [frame](const M& m, O q, O s) { return run(m, K::Fk, {q}, frame(m, s)); };
  const auto jacobian = [frame](const M& m, O q, O s) { return run(m, K::Jacobian, {q}, frame(m, s)); };
  const auto twist = [frame](const M& m, O q, O qd, O s) { return run(m, K::Twist, {q, qd}, frame(m, s)); };
  const auto jdot = [frame](const M& m, O q, O qd, O s) { return run(m, K::JacobianDotTimesQd, {q, qd}, frame(m, s)); };
  const auto id = [](const M& m, O q, O qd, O qdd, O f, O g) { return run(m, K::InverseDynamics, {q, qd, qdd, g, f}); };
  // mass_matrix: a q of the right length straight into the library (the generic path's argument
  // table costs about 5 % of this call); another shape, or a failure, through run() for its message.
  const auto mass = [](const M& m, O q) {
    vs::DynamicsData& d = m.companions();
    const py::ssize_t nq = d.model().nq(), n = d.model().nv();  // a floating base's state too
    const F64View v = asF64(q.ptr(), "q");                      // v.keep: a converted copy, alive for this call
    if (v.ndim != 1 || v.shape[0] != nq) return run(m, K::MassMatrix, {q});
    py::array out = newDoubles({n, n});
    const vs::JointPositions jq(Eigen::Map<const Eigen::VectorXd>(v.data, nq));
    if (!vs::massMatrix(d.model(), d, jq, Eigen::Map<Eigen::MatrixXd>(doubles(out), n, n)))
      return run(m, K::MassMatrix, {q});
    return out;
  };
  const auto grav = [](const M& m, O q, O g) { return run(m, K::GravityTorques, {q, {}, {}, g}); };
  const auto of_q = [](K kind) { return [kind](const M& m, O q) { return run(m, kind, {q}); }; };
  const auto of_state = [](K kind) { return [kind](const M& m, O q, O qd) { return run(m, kind, {q, qd}); }; };
  cls.def("fk", fk, py::arg("q"), segment, key("fk"))
      .def("jacobian", jacobian, py::arg("q"), segment, key("jacobian"))
      .def("twist", twist, py::arg("q"), py::arg("qd"), segment, key("twist"))
      .def("inverse_dynamics", id, py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("f_ext") = py::none(), gravity,
           key("inverse_dynamics"))
      .def("mass_matrix", mass, py::arg("q"), key("mass_matrix"))
      .def("gravity_torques", grav, py::arg("q"), gravity, key("gravity_torques"))
      .def("coriolis_torques", of_state(K::CoriolisTorques), py::arg("q"), py::arg("qd"), key("coriolis_torques"))
      .def("jacobian_dot_times_qd", jdot, py::arg("q"), py::arg("qd"), segment, key("jacobian_dot_times_qd"))
      .def("fk_all", of_q(K::FkAll), py::arg("q"), key("fk_all"))
      .def("center_of_mass", of_q(K::CenterOfMass), py::arg("q"), key("center_of_mass"))
      .def("center_of_mass_jacobian", of_q(K::CenterOfMassJacobian), py::arg("q"), key("center_of_mass_jacobian"))
      .def("center_of_mass_velocity", of_state(K::CenterOfMassVelocity), py::arg("q"), py::arg("qd"),
           key("center_of_mass_velocity"))
      .def("centroidal_momentum", of_state(K::CentroidalMomentum), py::arg("q"), py::arg("qd"),
           key("centroidal_momentum"))
      .def("integrate", of_state(K::Integrate), py::arg("q"), py::arg("v"), key("integrate"));
}

}  // namespace

void bindDynamics(py::module_& mod) {
  mod.def("_beta_for", &betaFor, py::arg("alpha"), py::arg("a_desired"), py::arg("twist"), py::arg("gravity"),
          doc("_core._beta_for"));
  auto chain = py::reinterpret_borrow<py::class_<PyChain>>(mod.attr("Chain"));
  const auto chainFrame = [](const PyChain& c, O s) {  // None: the last segment (Chain.fk's default)
    return s.is_none() ? FrameTarget{c.names().segmentCount() - 1} : c.resolveTarget(s.ptr(), "segment");
  };
  bindCompanions(chain, "Chain", py::arg("segment") = py::none(), chainFrame);
  auto tree = py::reinterpret_borrow<py::class_<PyTree>>(mod.attr("Tree"));
  bindCompanions(tree, "Tree", py::arg("segment"),
                 [](const PyTree& t, O s) { return t.resolveTarget(s.ptr(), "segment"); });
}

}  // namespace vsbind
