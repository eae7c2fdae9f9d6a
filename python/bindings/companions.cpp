// Companions of Chain and Tree (companions.hpp) on the C++ kinematics and dynamics.
#include "companions.hpp"

#include <optional>
#include <string>

#include "dynamics_common.hpp"
#include "numpy_fast.hpp"
#include "vereshchagin/task.hpp"

namespace vsbind {

namespace vs = vereshchagin;

CompanionCache::CompanionCache(const vs::Model& m)
    : model(m), dyn(model), f_ext(vs::Matrix6X::Zero(6, static_cast<Eigen::Index>(m.nrOfSegments()))) {}

CompanionCache& CompanionModel::companions() const {
  if (!cache_) cache_ = std::make_shared<CompanionCache>(buildModel());
  return *cache_;
}

namespace {

// Joint-space rows: one (n,) vector, or (with `batch`) N of them as an (N, n) array. float64
// C-contiguous arrays are read in place; anything else goes through toArray (its messages).
struct JointRows {
  const double* data = nullptr;
  py::ssize_t rows = 1;
  bool batched = false;
  py::object keep;
  Eigen::Map<const Eigen::VectorXd> row(py::ssize_t r, py::ssize_t n) const { return {data + r * n, n}; }
};

JointRows jointRows(const py::handle& obj, const char* name, py::ssize_t n, bool batch = false) {
  F64View v;
  if (detail_np::nativeContiguousF64(obj.ptr())) {
    detail_np::fill(obj.ptr(), v);
  } else {
    Array a = toArray(obj, name);
    v.keep = a;
    detail_np::fill(a.ptr(), v);
  }
  JointRows out;
  out.data = v.data;
  out.keep = v.keep;
  if (batch && v.ndim == 2 && v.shape[1] == n) {
    out.rows = v.shape[0];
    out.batched = true;
  } else if (v.ndim != 1 || v.shape[0] != n) {
    raise(std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + v.shapeString());
  }
  requireFiniteView(v, name);
  return out;
}

// gravity (3,): a list or tuple of three Python floats read directly (the default argument),
// anything else through vec3 (its messages).
KDL::Vector gravityArg(const py::handle& obj) {
  PyObject* o = obj.ptr();
  if ((PyList_CheckExact(o) || PyTuple_CheckExact(o)) && PySequence_Fast_GET_SIZE(o) == 3) {
    PyObject** items = PySequence_Fast_ITEMS(o);
    if (PyFloat_CheckExact(items[0]) && PyFloat_CheckExact(items[1]) && PyFloat_CheckExact(items[2])) {
      const KDL::Vector g(PyFloat_AS_DOUBLE(items[0]), PyFloat_AS_DOUBLE(items[1]), PyFloat_AS_DOUBLE(items[2]));
      if (std::isfinite(g.x()) && std::isfinite(g.y()) && std::isfinite(g.z())) return g;
    }
  }
  return vec3(obj, "gravity");
}

void check(const vs::Status& s) {
  if (!s) raise(s.message());
}

vs::FrameRef frameRef(const FrameTarget& t) {
  return vs::FrameRef{t.segment, t.link_in_tip};
}

void writePose(const KDL::Frame& f, double* out) {
  writeHomogeneous(f, out);
}

py::array finiteResult(py::array a, const char* what) {
  requireFiniteResult(doubles(a), static_cast<std::size_t>(a.size()), what);
  return a;
}

}  // namespace

py::array fkOf(const CompanionModel& m, const py::handle& q_obj, const FrameTarget& target) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n, true);
  py::array out = q.batched ? newDoubles({q.rows, 4, 4}) : newDoubles({4, 4});
  KDL::Frame f;
  for (py::ssize_t r = 0; r < q.rows; ++r) {
    check(vs::forwardKinematics(c.model, c.kin(), vs::JointPositions(q.row(r, n))));
    check(vs::framePose(c.model, c.kin(), frameRef(target), f));
    writePose(f, doubles(out) + 16 * r);
  }
  return out;
}

py::array jacobianOf(const CompanionModel& m, const py::handle& q_obj, const FrameTarget& target) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n);
  check(vs::forwardKinematics(c.model, c.kin(), vs::JointPositions(q.row(0, n))));
  py::array out = newDoubles({6, n});
  // numpy's (6, n) row-major is Eigen's column-major n x 6 transposed.
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(doubles(out), 6, n);
  Eigen::MatrixXd Jc(6, n);
  check(vs::frameJacobian(c.model, c.kin(), frameRef(target), Jc));
  J = Jc;
  return out;
}

py::array twistOf(const CompanionModel& m, const py::handle& q_obj, const py::handle& qd_obj,
                  const FrameTarget& target) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n, true);
  const JointRows qd = jointRows(qd_obj, "qd", n, true);
  if (q.batched != qd.batched || q.rows != qd.rows)
    raise("q and qd must have the same shape, got " + std::to_string(q.rows) + " and " + std::to_string(qd.rows) +
          " rows");
  py::array out = q.batched ? newDoubles({q.rows, 6}) : newDoubles({6});
  vs::Vector6 t;
  for (py::ssize_t r = 0; r < q.rows; ++r) {
    check(vs::forwardKinematics(c.model, c.kin(), vs::JointPositions(q.row(r, n)), vs::JointVelocities(qd.row(r, n))));
    check(vs::frameTwist(c.model, c.kin(), frameRef(target), t));
    std::copy(t.data(), t.data() + 6, doubles(out) + 6 * r);
  }
  return finiteResult(out, "twist");
}

py::array jacobianDotTimesQdOf(const CompanionModel& m, const py::handle& q_obj, const py::handle& qd_obj,
                               const FrameTarget& target) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n), qd = jointRows(qd_obj, "qd", n);
  check(vs::forwardKinematics(c.model, c.kin(), vs::JointPositions(q.row(0, n)), vs::JointVelocities(qd.row(0, n))));
  vs::Vector6 a;
  check(vs::frameBiasAcceleration(c.model, c.kin(), frameRef(target), a));
  py::array out = newDoubles({6});
  std::copy(a.data(), a.data() + 6, doubles(out));
  return finiteResult(out, "jacobian_dot_times_qd");
}

py::array fkAllOf(const CompanionModel& m, const py::handle& q_obj) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n);
  check(vs::forwardKinematics(c.model, c.kin(), vs::JointPositions(q.row(0, n))));
  const int ns = static_cast<int>(c.model.nrOfSegments());
  py::array out = newDoubles({ns, 4, 4});
  KDL::Frame f;
  for (int i = 0; i < ns; ++i) {
    check(vs::framePose(c.model, c.kin(), vs::FrameRef{i, KDL::Frame::Identity()}, f));
    writePose(f, doubles(out) + 16 * i);
  }
  return out;
}

py::array inverseDynamicsOf(const CompanionModel& m, const py::handle& q_obj, const py::handle& qd_obj,
                            const py::handle& qdd_obj, const py::object& f_ext, const py::handle& gravity) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n), qd = jointRows(qd_obj, "qd", n), qdd = jointRows(qdd_obj, "qdd", n);
  const KDL::Vector g = gravityArg(gravity);
  Eigen::Index wrench_cols = 0;
  if (!f_ext.is_none()) {  // the dict form needs the tip orientations at q
    check(vs::forwardKinematics(c.model, c.kin(), vs::JointPositions(q.row(0, n))));
    const auto rows = externalWrenchRows(f_ext, m, [&c](int s) {
      const vs::Matrix3& R = c.kin().tipPose(s).R;
      return KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
    });
    for (std::size_t i = 0; i < rows.size(); ++i) c.f_ext.col(static_cast<Eigen::Index>(i)) = rows[i];
    wrench_cols = static_cast<Eigen::Index>(rows.size());
  }
  py::array out = newDoubles({n});
  Eigen::Map<Eigen::VectorXd> tau(doubles(out), n);
  check(vs::inverseDynamics(c.model, c.dyn, vs::JointPositions(q.row(0, n)), vs::JointVelocities(qd.row(0, n)),
                            vs::JointAccelerations(qdd.row(0, n)), c.f_ext.leftCols(wrench_cols), g, tau));
  return finiteResult(out, "inverse_dynamics");
}

py::array massMatrixOf(const CompanionModel& m, const py::handle& q_obj) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n);
  py::array out = newDoubles({n, n});
  Eigen::Map<Eigen::MatrixXd> H(doubles(out), n, n);  // symmetric: row- and column-major alike
  check(vs::massMatrix(c.model, c.dyn, vs::JointPositions(q.row(0, n)), H));
  return finiteResult(out, "mass_matrix");
}

py::array gravityTorquesOf(const CompanionModel& m, const py::handle& q_obj, const py::handle& gravity) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n);
  const KDL::Vector g = gravityArg(gravity);
  py::array out = newDoubles({n});
  Eigen::Map<Eigen::VectorXd> tau(doubles(out), n);
  check(vs::gravityTorques(c.model, c.dyn, vs::JointPositions(q.row(0, n)), g, tau));
  return finiteResult(out, "gravity_torques");
}

py::array coriolisTorquesOf(const CompanionModel& m, const py::handle& q_obj, const py::handle& qd_obj) {
  CompanionCache& c = m.companions();
  const auto n = static_cast<py::ssize_t>(c.model.nrOfJoints());
  const JointRows q = jointRows(q_obj, "q", n), qd = jointRows(qd_obj, "qd", n);
  py::array out = newDoubles({n});
  Eigen::Map<Eigen::VectorXd> tau(doubles(out), n);
  check(vs::coriolisTorques(c.model, c.dyn, vs::JointPositions(q.row(0, n)), vs::JointVelocities(qd.row(0, n)), tau));
  return finiteResult(out, "coriolis_torques");
}

}  // namespace vsbind

// ---- task.py's beta_for on the C++ helper (task.hpp) ----

namespace vsbind {

namespace {

// A float64 view of a real array, or nothing (nullopt: not convertible, left to task.py's checks).
std::optional<F64View> realView(const py::handle& obj) {
  F64View v;
  if (detail_np::nativeContiguousF64(obj.ptr())) {
    detail_np::fill(obj.ptr(), v);
  } else {
    if (PyBool_Check(obj.ptr()) || obj.is_none()) return std::nullopt;
    py::array any = py::array::ensure(obj);
    if (!any) {
      PyErr_Clear();
      return std::nullopt;
    }
    const char kind = any.dtype().kind();
    if ((kind != 'f' && kind != 'i' && kind != 'u') || any.ndim() > 3) return std::nullopt;
    Array a = Array::ensure(any);
    if (!a) {
      PyErr_Clear();
      return std::nullopt;
    }
    v.keep = a;
    detail_np::fill(a.ptr(), v);
  }
  for (py::ssize_t k = 0; k < v.size(); ++k)
    if (!std::isfinite(v.data[k])) return std::nullopt;
  return v;
}

// beta (m,) or, for N twists (N, 6), beta rows (N, m); None when an input is not plainly valid
// (task.py then raises its own message).
py::object betaFor(const py::handle& alpha, const py::handle& a_desired, const py::handle& twist,
                   const py::handle& gravity) {
  const auto A = realView(alpha), a = realView(a_desired), t = realView(twist), g = realView(gravity);
  if (!A || !a || !t || !g || g->size() != 3) return py::none();
  py::ssize_t m = 0;
  if (A->ndim == 1 && A->shape[0] == 6)
    m = 1;
  else if (A->ndim == 2 && A->shape[0] == 6)
    m = A->shape[1];
  else
    return py::none();
  const bool batched = t->ndim == 2 && t->shape[1] == 6 && t->size() != 6;
  const py::ssize_t rows = batched ? t->shape[0] : 1;
  if (!batched && t->size() != 6) return py::none();
  const bool a_rows = a->size() != 6;
  if (a_rows && !(batched && a->ndim == 2 && a->shape[0] == rows && a->shape[1] == 6)) return py::none();
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const RowMajor> alfa(A->data, 6, m);
  const KDL::Vector grav(g->data[0], g->data[1], g->data[2]);
  py::array out = batched ? newDoubles({rows, m}) : newDoubles({m});
  for (py::ssize_t r = 0; r < rows; ++r) {
    const vereshchagin::Vector6 acc = Eigen::Map<const vereshchagin::Vector6>(a->data + (a_rows ? 6 * r : 0));
    const vereshchagin::Vector6 tw = Eigen::Map<const vereshchagin::Vector6>(t->data + 6 * r);
    Eigen::Map<Eigen::VectorXd> beta(doubles(out) + m * r, m);
    beta.noalias() = alfa.transpose() * vereshchagin::spatialFromClassical(acc, tw, grav);
  }
  if (!Eigen::Map<const Eigen::VectorXd>(doubles(out), out.size()).allFinite())
    raise("beta_for: the result overflows the double range (inputs too large)");
  return std::move(out);
}

}  // namespace

// Task.solve's beta: the chain tip's twist at (q, qd) and beta_for in one call; None as betaFor.
py::object taskBeta(const CompanionModel& m, const FrameTarget& tip, const py::handle& q, const py::handle& qd,
                    const py::handle& alpha, const py::handle& a_desired, const py::handle& gravity) {
  return betaFor(alpha, a_desired, twistOf(m, q, qd, tip), gravity);
}

void bindTaskHelpers(py::module_& mod) {
  mod.def("_beta_for", &betaFor, py::arg("alpha"), py::arg("a_desired"), py::arg("twist"), py::arg("gravity"),
          doc("_core._beta_for"));
}

}  // namespace vsbind
