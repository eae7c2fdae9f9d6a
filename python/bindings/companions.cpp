// The companions of Chain and Tree (companions.hpp), bound on both by one template: arguments read
// into the C++ library's calls on the model's cached workspace, results checked for overflow.
// Conventions (the solver's): physical gravity, base axes; f_ext ON each segment BY the environment.
#include "companions.hpp"

#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "model_class.hpp"
#include "numpy_fast.hpp"

namespace vsbind {

namespace vs = vereshchagin;
using Vec = Eigen::Map<Eigen::VectorXd>;

CompanionCache::CompanionCache(const vs::Model& m)
    : model(m), dyn(model), f_ext(6, m.nrOfSegments()), n(m.nrOfJoints()) {}

CompanionCache& CompanionModel::companions() const {
  if (!cache_) cache_ = std::make_shared<CompanionCache>(buildModel());
  return *cache_;
}

namespace {

void check(const vs::Status& s) {
  if (!s) raise(s.message());
}

// q-like (n,) or, with `batch`, (N, n) rows: float64 C-contiguous arrays viewed in place,
// anything else converted by toArray (its messages).
struct JointRows {
  JointRows(const py::handle& obj, const char* name, py::ssize_t n, bool batch = false) : n(n) {
    const auto wrong = [&](const std::string& got) {
      raise(std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + got);
    };
    PyObject* arr = obj.ptr();
    if (!detail_np::nativeContiguousF64(arr)) {
      const Array a = toArray(obj, name);
      if (a.ndim() > 3) wrong(shapeStr(a));  // an F64View holds 3 dimensions
      arr = (v.keep = a).ptr();
    }
    detail_np::fill(arr, v);
    batched = batch && v.ndim == 2 && v.shape[1] == n;
    if (!batched && (v.ndim != 1 || v.shape[0] != n)) wrong(v.shapeString());
    requireFiniteView(v, name);
  }
  Eigen::Map<const Eigen::VectorXd> operator[](py::ssize_t r) const { return {v.data + r * n, n}; }
  vs::JointPositions pos() const { return vs::JointPositions((*this)[0]); }
  vs::JointVelocities vel() const { return vs::JointVelocities((*this)[0]); }
  py::ssize_t rows() const { return batched ? v.shape[0] : 1; }
  F64View v;
  py::ssize_t n;
  bool batched = false;
};

// gravity (3,): the default list of three floats read directly, anything else through vec3.
KDL::Vector gravityArg(const py::handle& obj) {
  PyObject* o = obj.ptr();
  if ((PyList_CheckExact(o) || PyTuple_CheckExact(o)) && PySequence_Fast_GET_SIZE(o) == 3) {
    PyObject** x = PySequence_Fast_ITEMS(o);
    if (PyFloat_CheckExact(x[0]) && PyFloat_CheckExact(x[1]) && PyFloat_CheckExact(x[2])) {
      const KDL::Vector g(PyFloat_AS_DOUBLE(x[0]), PyFloat_AS_DOUBLE(x[1]), PyFloat_AS_DOUBLE(x[2]));
      if (std::isfinite(g.x()) && std::isfinite(g.y()) && std::isfinite(g.z())) return g;
    }
  }
  return vec3(obj, "gravity");
}

// Finite inputs can still overflow (|qd| = 1e160): never hand back Inf or NaN.
py::array finite(py::array a, const char* what) {
  if (!Eigen::Map<const Eigen::ArrayXd>(doubles(a), a.size()).allFinite())
    raise(std::string(what) + ": the result overflows the double range");
  return a;
}

vs::FrameRef ref(const FrameTarget& t) {
  return {t.segment, t.link_in_tip};
}

// f_ext into c.f_ext; its column count (0: None). An (n_segments, 6) array is taken as is, a dict
// {segment or link: wrench (6,), moment about that frame's origin} is moved to the tips in C++.
Eigen::Index wrenchColumns(const CompanionModel& m, CompanionCache& c, O f_ext, const JointRows& q) {
  if (f_ext.is_none()) return 0;
  const Eigen::Index ns = c.f_ext.cols();
  if (!py::isinstance<py::dict>(f_ext)) {
    const Array f = toArray(f_ext, "f_ext");
    if (f.ndim() != 2 || f.shape(0) != ns || f.shape(1) != 6)
      raise("f_ext must have shape (" + std::to_string(ns) + ", 6) or be a dict {segment: wrench (6,)}, got " +
            shapeStr(f));
    requireFinite(f, "f_ext");
    c.f_ext = Eigen::Map<const vs::Matrix6X>(f.data(), 6, ns);
    return ns;
  }
  c.f_ext.setZero();
  check(vs::forwardKinematics(c.model, c.kin(), q.pos()));
  for (const auto& item : f_ext.cast<py::dict>()) {
    const std::string label = "f_ext[" + py::repr(item.first).cast<std::string>() + "]";
    const FrameTarget t = m.resolveMoving(item.first.ptr(), label);
    const Array w = vectorArg(item.second, label.c_str(), 6);
    check(vs::addFrameWrench(c.model, c.kin(), ref(t), Eigen::Map<const vs::Vector6>(w.data()), c.f_ext));
  }
  return ns;
}

// n joint torques written by `f` (a vereshchagin call on c's workspace), checked for overflow.
template <class F>
py::array torques(const CompanionCache& c, const char* what, F f) {
  py::array out = newDoubles({c.n});
  check(f(Vec(doubles(out), c.n)));
  return finite(out, what);
}

py::array inverseDynamics(const CompanionModel& m, O q_obj, O qd_obj, O qdd_obj, O f_ext, O gravity) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n), qd(qd_obj, "qd", c.n), qdd(qdd_obj, "qdd", c.n);
  const KDL::Vector g = gravityArg(gravity);
  const Eigen::Index cols = wrenchColumns(m, c, f_ext, q);
  return torques(c, "inverse_dynamics", [&](Vec out) {
    return vs::inverseDynamics(c.model, c.dyn, q.pos(), qd.vel(), vs::JointAccelerations(qdd[0]),
                               c.f_ext.leftCols(cols), g, out);
  });
}

py::array massMatrix(const CompanionModel& m, O q_obj) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n);
  py::array out = newDoubles({c.n, c.n});  // symmetric: row- and column-major alike
  check(vs::massMatrix(c.model, c.dyn, q.pos(), Eigen::Map<Eigen::MatrixXd>(doubles(out), c.n, c.n)));
  return finite(out, "mass_matrix");
}

py::array gravityTorques(const CompanionModel& m, O q_obj, O gravity) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n);
  const KDL::Vector g = gravityArg(gravity);
  return torques(c, "gravity_torques", [&](Vec out) { return vs::gravityTorques(c.model, c.dyn, q.pos(), g, out); });
}

py::array coriolisTorques(const CompanionModel& m, O q_obj, O qd_obj) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n), qd(qd_obj, "qd", c.n);
  return torques(c, "coriolis_torques",
                 [&](Vec out) { return vs::coriolisTorques(c.model, c.dyn, q.pos(), qd.vel(), out); });
}

py::array fkAll(const CompanionModel& m, O q_obj) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n);
  check(vs::forwardKinematics(c.model, c.kin(), q.pos()));
  const auto ns = static_cast<int>(c.model.nrOfSegments());
  py::array out = newDoubles({ns, 4, 4});
  KDL::Frame f;
  for (int i = 0; i < ns; ++i) {
    check(vs::framePose(c.model, c.kin(), vs::FrameRef{i, KDL::Frame::Identity()}, f));
    writeHomogeneous(f, doubles(out) + 16 * i);
  }
  return out;
}

// [classical acceleration of the frame's origin; angular acceleration] at qdd = 0, no gravity.
py::array jacobianDotTimesQd(const CompanionModel& m, O q_obj, O qd_obj, const FrameTarget& target) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n), qd(qd_obj, "qd", c.n);
  check(vs::forwardKinematics(c.model, c.kin(), q.pos(), qd.vel()));
  py::array out = newDoubles({6});
  vs::Vector6 a;
  check(vs::frameBiasAcceleration(c.model, c.kin(), ref(target), a));
  Vec(doubles(out), 6) = a;
  return finite(out, "jacobian_dot_times_qd");
}

py::array fkOf(const CompanionModel& m, const py::handle& q_obj, const FrameTarget& target) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n, true);
  py::array out = q.batched ? newDoubles({q.rows(), 4, 4}) : newDoubles({4, 4});
  KDL::Frame f;
  for (py::ssize_t r = 0; r < q.rows(); ++r) {
    check(vs::forwardKinematics(c.model, c.kin(), vs::JointPositions(q[r])));
    check(vs::framePose(c.model, c.kin(), ref(target), f));
    writeHomogeneous(f, doubles(out) + 16 * r);
  }
  return out;
}

py::array jacobianOf(const CompanionModel& m, const py::handle& q_obj, const FrameTarget& target) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n);
  check(vs::forwardKinematics(c.model, c.kin(), q.pos()));
  const py::ssize_t dims[2] = {6, c.n};
  py::array out = newArray(py::detail::npy_api::NPY_DOUBLE_, 2, dims, /*fortran=*/true);  // written in place
  Eigen::Map<Eigen::MatrixXd> J(doubles(out), 6, c.n);
  check(vs::frameJacobian(c.model, c.kin(), ref(target), J));
  return out;
}

py::array twistOf(const CompanionModel& m, const py::handle& q_obj, const py::handle& qd_obj,
                  const FrameTarget& target) {
  CompanionCache& c = m.companions();
  const JointRows q(q_obj, "q", c.n, true), qd(qd_obj, "qd", c.n, true);
  if (q.batched != qd.batched || q.rows() != qd.rows())
    raise("q and qd must have the same shape, got " + std::to_string(q.rows()) + " and " + std::to_string(qd.rows()) +
          " rows");
  py::array out = q.batched ? newDoubles({q.rows(), 6}) : newDoubles({6});
  vs::Vector6 t;
  for (py::ssize_t r = 0; r < q.rows(); ++r) {
    check(vs::forwardKinematics(c.model, c.kin(), vs::JointPositions(q[r]), vs::JointVelocities(qd[r])));
    check(vs::frameTwist(c.model, c.kin(), ref(target), t));
    Vec(doubles(out) + 6 * r, 6) = t;
  }
  return finite(out, "twist");
}

// A companion as a method of M (pybind11 binds M's methods, not CompanionModel's).
template <typename M, typename... A>
auto on(py::array (*body)(const CompanionModel&, A...)) {
  return [body](const M& m, A... a) { return body(m, a...); };
}

// Binds the companions on Chain or Tree (M): `segment` is the spec of the frame argument of fk,
// jacobian, twist and jacobian_dot_times_qd, `frame` resolves it.
template <typename M, typename SegmentArg, typename Frame>
void bindCompanions(py::class_<M>& cls, const std::string& name, const SegmentArg& segment, Frame frame) {
  const std::vector<double> earth{0.0, 0.0, -9.81};  // physical gravity, base z up, m/s^2
  const auto key = [&name](const char* method) { return doc(name + "." + method); };
  const auto fk = [frame](const M& m, O q, O s) { return fkOf(m, q, frame(m, s)); };
  const auto jacobian = [frame](const M& m, O q, O s) { return jacobianOf(m, q, frame(m, s)); };
  const auto twist = [frame](const M& m, O q, O qd, O s) { return twistOf(m, q, qd, frame(m, s)); };
  const auto jdot = [frame](const M& m, O q, O qd, O s) { return jacobianDotTimesQd(m, q, qd, frame(m, s)); };
  cls.def("fk", fk, py::arg("q"), segment, key("fk"))
      .def("jacobian", jacobian, py::arg("q"), segment, key("jacobian"))
      .def("twist", twist, py::arg("q"), py::arg("qd"), segment, key("twist"))
      .def("inverse_dynamics", on<M>(inverseDynamics), py::arg("q"), py::arg("qd"), py::arg("qdd"),
           py::arg("f_ext") = py::none(), py::arg("gravity") = earth, key("inverse_dynamics"))
      .def("mass_matrix", on<M>(massMatrix), py::arg("q"), key("mass_matrix"))
      .def("gravity_torques", on<M>(gravityTorques), py::arg("q"), py::arg("gravity") = earth, key("gravity_torques"))
      .def("coriolis_torques", on<M>(coriolisTorques), py::arg("q"), py::arg("qd"), key("coriolis_torques"))
      .def("jacobian_dot_times_qd", jdot, py::arg("q"), py::arg("qd"), segment, key("jacobian_dot_times_qd"))
      .def("fk_all", on<M>(fkAll), py::arg("q"), key("fk_all"));
}

}  // namespace

void bindDynamics(py::module_& mod) {
  bindTaskHelpers(mod);
  auto chain = py::reinterpret_borrow<py::class_<PyChain>>(mod.attr("Chain"));
  bindCompanions(chain, "Chain", py::arg("segment") = py::none(),
                 [](const PyChain& c, O s) { return c.resolveOptional(s, "segment"); });
  auto tree = py::reinterpret_borrow<py::class_<PyTree>>(mod.attr("Tree"));
  bindCompanions(tree, "Tree", py::arg("segment"),
                 [](const PyTree& t, O s) { return t.resolveTarget(s.ptr(), "segment"); });
}

}  // namespace vsbind
