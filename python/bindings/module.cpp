// pybind11 bindings of the vereshchagin C++ library: module vereshchagin._core.
// Shapes and values are checked here (clear messages naming the argument); the C++ solver checks
// again and its error codes become vereshchagin.SolverError (a ValueError).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <functional>
#include <mutex>
#include <sstream>
#include <string>

#include <kdl/chain.hpp>

#include "vereshchagin/chain_hd_solver.hpp"

namespace py = pybind11;
using vereshchagin::ChainHdSolver;

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

struct SolverError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void raise(const std::string& msg) { throw SolverError(msg); }

std::string shapeStr(const py::array& a) {
  std::ostringstream s;
  s << "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s << (k ? ", " : "") << a.shape(k);
  if (a.ndim() == 1) s << ",";
  s << ")";
  return s.str();
}

Array toArray(const py::handle& obj, const char* name) {
  Array a = Array::ensure(obj);
  if (!a) {
    PyErr_Clear();
    raise(std::string(name) + " must be a numeric array-like of floats");
  }
  return a;
}

void requireFinite(const Array& a, const char* name) {
  const double* p = a.data();
  for (py::ssize_t k = 0; k < a.size(); ++k) {
    if (!std::isfinite(p[k])) {
      raise(std::string(name) + " contains NaN or Inf (flat index " + std::to_string(k) + ")");
    }
  }
}

Array vectorArg(const py::handle& obj, const char* name, py::ssize_t n) {
  Array a = toArray(obj, name);
  if (a.ndim() != 1 || a.shape(0) != n) {
    raise(std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + shapeStr(a));
  }
  requireFinite(a, name);
  return a;
}

KDL::Frame frameFrom4x4(const py::handle& obj, const char* name) {
  Array T = toArray(obj, name);
  if (T.ndim() != 2 || T.shape(0) != 4 || T.shape(1) != 4) {
    raise(std::string(name) + " must be a 4x4 homogeneous transform, got shape " + shapeStr(T));
  }
  requireFinite(T, name);
  auto t = T.unchecked<2>();
  if (std::abs(t(3, 0)) > 1e-12 || std::abs(t(3, 1)) > 1e-12 || std::abs(t(3, 2)) > 1e-12 ||
      std::abs(t(3, 3) - 1.0) > 1e-12) {
    raise(std::string(name) + " must have last row [0, 0, 0, 1]");
  }
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = t(r, c);
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-9 ||
      R.determinant() < 0.0) {
    raise(std::string(name) + ": the upper-left 3x3 block must be a rotation matrix (orthonormal, det +1)");
  }
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0),
                                  R(2, 1), R(2, 2)),
                    KDL::Vector(t(0, 3), t(1, 3), t(2, 3)));
}

KDL::Vector vec3(const py::handle& obj, const char* name) {
  Array a = vectorArg(obj, name, 3);
  return KDL::Vector(a.at(0), a.at(1), a.at(2));
}

// A joint description before it is attached to a segment (name and rotor inertia come later).
struct JointSpec {
  KDL::Joint::JointType type = KDL::Joint::Fixed;
  KDL::Vector origin = KDL::Vector::Zero();
  KDL::Vector axis = KDL::Vector(0, 0, 1);
  bool has_axis = false;
  std::string repr() const {
    std::ostringstream s;
    if (type == KDL::Joint::Fixed) return "Joint.fixed()";
    s << (type == KDL::Joint::RotAxis ? "Joint.revolute(" : "Joint.prismatic(") << "axis=[" << axis.x()
      << ", " << axis.y() << ", " << axis.z() << "], origin=[" << origin.x() << ", " << origin.y()
      << ", " << origin.z() << "])";
    return s.str();
  }
};

JointSpec makeAxisJoint(KDL::Joint::JointType type, const py::handle& axis, const py::handle& origin) {
  JointSpec j;
  j.type = type;
  j.axis = vec3(axis, "axis");
  const double norm = j.axis.Norm();
  if (!(norm > 1e-12)) raise("axis must be a non-zero 3-vector");
  j.axis = j.axis / norm;
  j.origin = origin.is_none() ? KDL::Vector::Zero() : vec3(origin, "origin");
  j.has_axis = true;
  return j;
}

JointSpec jointFromString(const std::string& s) {
  static const std::pair<const char*, KDL::Joint::JointType> table[] = {
      {"rot_x", KDL::Joint::RotX},     {"rot_y", KDL::Joint::RotY},     {"rot_z", KDL::Joint::RotZ},
      {"trans_x", KDL::Joint::TransX}, {"trans_y", KDL::Joint::TransY}, {"trans_z", KDL::Joint::TransZ},
      {"fixed", KDL::Joint::Fixed}};
  for (const auto& e : table) {
    if (s == e.first) {
      JointSpec j;
      j.type = e.second;
      return j;
    }
  }
  raise("unknown joint type '" + s +
        "': use 'rot_x', 'rot_y', 'rot_z', 'trans_x', 'trans_y', 'trans_z', 'fixed', "
        "Joint.revolute(axis, origin) or Joint.prismatic(axis, origin)");
}

// The Python Chain: a KDL::Chain built segment by segment.
struct PyChain {
  KDL::Chain chain;

  void addSegment(const std::string& name, const py::object& joint, const py::object& tip, double mass,
                  const py::object& com, const py::object& inertia, double rotor_inertia,
                  const std::string& joint_name) {
    JointSpec spec;
    if (py::isinstance<py::str>(joint)) {
      spec = jointFromString(joint.cast<std::string>());
    } else if (py::isinstance<JointSpec>(joint)) {
      spec = joint.cast<JointSpec>();
    } else {
      raise("joint must be a joint-type string such as 'rot_z' or a vereshchagin.Joint");
    }
    const KDL::Frame f_tip = tip.is_none() ? KDL::Frame::Identity() : frameFrom4x4(tip, "tip");
    if (!std::isfinite(mass) || mass < 0.0) raise("mass must be finite and >= 0, got " + std::to_string(mass));
    const KDL::Vector c = com.is_none() ? KDL::Vector::Zero() : vec3(com, "com");
    Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
    if (!inertia.is_none()) {
      Array a = toArray(inertia, "inertia");
      if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
        raise("inertia must be a 3x3 matrix (about the centre of mass, tip-frame axes), got shape " + shapeStr(a));
      requireFinite(a, "inertia");
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) I(r, k) = a.at(r, k);
    }
    const double scale = std::max(1.0, I.cwiseAbs().maxCoeff());
    if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) raise("inertia must be symmetric");
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(I, Eigen::EigenvaluesOnly);
    if (es.eigenvalues().minCoeff() < -1e-12 * scale)
      raise("inertia must be positive semi-definite (smallest eigenvalue " +
            std::to_string(es.eigenvalues().minCoeff()) + ")");
    if (!std::isfinite(rotor_inertia) || rotor_inertia < 0.0)
      raise("rotor_inertia must be finite and >= 0, got " + std::to_string(rotor_inertia));
    if (spec.type == KDL::Joint::Fixed && rotor_inertia != 0.0) raise("a fixed joint has no rotor inertia");
    const std::string jname = joint_name.empty() ? name + "_joint" : joint_name;
    KDL::Joint j = spec.has_axis ? KDL::Joint(jname, spec.origin, spec.axis, spec.type, 1.0, 0.0, rotor_inertia)
                                 : KDL::Joint(jname, spec.type, 1.0, 0.0, rotor_inertia);
    const KDL::RotationalInertia Ic(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
    chain.addSegment(KDL::Segment(name, j, f_tip, KDL::RigidBodyInertia(mass, c, Ic)));
  }

  std::vector<std::string> segmentNames() const {
    std::vector<std::string> out;
    for (unsigned int i = 0; i < chain.getNrOfSegments(); ++i) out.push_back(chain.getSegment(i).getName());
    return out;
  }
  std::vector<std::string> jointNames() const {
    std::vector<std::string> out;
    for (unsigned int i = 0; i < chain.getNrOfSegments(); ++i) {
      const KDL::Joint& j = chain.getSegment(i).getJoint();
      if (j.getType() != KDL::Joint::Fixed) out.push_back(j.getName());
    }
    return out;
  }
};

struct SolveResult {
  py::array_t<double> qdd, tau_command, nu, link_acc;
  int constraint_rank = 0;
  double smallest_singular_value = 0.0;
};

py::array_t<double> copyVector(const double* p, py::ssize_t n) {
  py::array_t<double> a(n);
  std::copy(p, p + n, a.mutable_data());
  return a;
}

class PySolver {
 public:
  PySolver(const PyChain& chain, const py::object& gravity, double rcond, py::object damping)
      : solver_(chain.chain, KDL::Twist::Zero()) {
    if (solver_.modelError() != ChainHdSolver::E_NOERROR) raise(std::string("invalid chain: ") + solver_.errorMessage());
    setGravity(gravity);
    vereshchagin::SolverOptions opt;
    opt.rcond = rcond;
    if (!damping.is_none()) {
      opt.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
      opt.damping = damping.cast<double>();
    }
    if (solver_.setOptions(opt) != ChainHdSolver::E_NOERROR) raise(solver_.errorMessage());
    nj_ = solver_.nrOfJoints();
    ns_ = solver_.nrOfSegments();
  }

  void setGravity(const py::object& gravity) {
    const KDL::Vector g = vec3(gravity, "gravity");
    gravity_ = g;
    solver_.setRootAcceleration(KDL::Twist(-g, KDL::Vector::Zero()));  // base accelerates up
  }
  py::array_t<double> gravity() const { return copyVector(gravity_.data, 3); }

  // Checked, converted inputs of one solve (views into numpy memory, kept alive by the arrays).
  struct Inputs {
    Array q, qd, alpha, beta, f_ext, tau;
    bool has_f_ext = false, has_tau = false;
    py::ssize_t m = 0;
  };

  Inputs parse(const py::object& q, const py::object& qd, const py::object& alpha, const py::object& beta,
               const py::object& f_ext, const py::object& tau_ff) const {
    Inputs in;
    in.q = vectorArg(q, "q", nj_);
    in.qd = vectorArg(qd, "qd", nj_);
    if (!alpha.is_none()) {
      in.alpha = toArray(alpha, "alpha");
      if (in.alpha.ndim() == 1 && in.alpha.shape(0) == 6) in.alpha = in.alpha.reshape({6, 1});
      if (in.alpha.ndim() != 2 || in.alpha.shape(0) != 6)
        raise("alpha must have shape (6, m) with rows [force; moment], got " + shapeStr(in.alpha));
      in.m = in.alpha.shape(1);
      if (in.m > 6) raise("alpha has " + std::to_string(in.m) + " columns; at most 6 constraints are supported");
      requireFinite(in.alpha, "alpha");
    }
    if (beta.is_none()) {
      if (in.m > 0) raise("beta is required when alpha is given (shape (" + std::to_string(in.m) + ",))");
    } else {
      if (alpha.is_none()) raise("beta given without alpha");
      in.beta = vectorArg(beta, "beta", in.m);
    }
    if (!f_ext.is_none()) {
      in.f_ext = toArray(f_ext, "f_ext");
      if (in.f_ext.ndim() != 2 || in.f_ext.shape(0) != static_cast<py::ssize_t>(ns_) || in.f_ext.shape(1) != 6)
        raise("f_ext must have shape (" + std::to_string(ns_) + ", 6) (one [force, moment] row per segment), got " +
              shapeStr(in.f_ext));
      requireFinite(in.f_ext, "f_ext");
      in.has_f_ext = true;
    }
    if (!tau_ff.is_none()) {
      in.tau = vectorArg(tau_ff, "tau_ff", nj_);
      in.has_tau = true;
    }
    return in;
  }

  // Runs the C++ solve without the GIL. Caller holds mutex_.
  void run(const Inputs& in) {
    using Map6X = Eigen::Map<const ChainHdSolver::Matrix6X>;
    using MapV = Eigen::Map<const Eigen::VectorXd>;
    const auto m = in.m;
    for (py::ssize_t r = 0; r < 6; ++r)
      for (py::ssize_t c = 0; c < m; ++c) alfa_(r, c) = in.alpha.data()[r * m + c];
    const MapV q(in.q.data(), nj_), qd(in.qd.data(), nj_);
    const MapV beta(m ? in.beta.data() : nullptr, m);
    const Map6X f(in.has_f_ext ? in.f_ext.data() : nullptr, 6, in.has_f_ext ? ns_ : 0);
    const MapV tau(in.has_tau ? in.tau.data() : nullptr, in.has_tau ? nj_ : 0);
    int rc;
    {
      py::gil_scoped_release release;
      rc = solver_.solve(q, qd, alfa_.leftCols(m), beta, f, tau);
    }
    if (rc != ChainHdSolver::E_NOERROR) raise(solver_.errorMessage());
  }

  SolveResult result() const {
    SolveResult r;
    r.qdd = copyVector(solver_.qdd().data(), nj_);
    r.tau_command = copyVector(solver_.commandTorques().data(), nj_);
    r.nu = copyVector(solver_.nu().data(), solver_.constraintCount());
    r.link_acc = py::array_t<double>({static_cast<py::ssize_t>(ns_ + 1), static_cast<py::ssize_t>(6)});
    std::copy(solver_.linkAccelerations().data(), solver_.linkAccelerations().data() + 6 * (ns_ + 1),
              r.link_acc.mutable_data());
    r.constraint_rank = solver_.constraintRank();
    r.smallest_singular_value = solver_.smallestSingularValue();
    return r;
  }

  SolveResult solve(const py::object& q, const py::object& qd, const py::object& alpha, const py::object& beta,
                    const py::object& f_ext, const py::object& tau_ff) {
    Inputs in = parse(q, qd, alpha, beta, f_ext, tau_ff);
    std::lock_guard<std::mutex> lock(mutex_);
    run(in);
    return result();
  }

  py::dict solveBatch(const py::object& Q, const py::object& QD, const py::object& alpha, const py::object& beta,
                      const py::object& f_ext, const py::object& tau_ff) {
    Array q = toArray(Q, "q"), qd = toArray(QD, "qd");
    if (q.ndim() != 2 || q.shape(1) != static_cast<py::ssize_t>(nj_))
      raise("q must have shape (B, " + std::to_string(nj_) + "), got " + shapeStr(q));
    const py::ssize_t B = q.shape(0);
    if (qd.ndim() != 2 || qd.shape(0) != B || qd.shape(1) != static_cast<py::ssize_t>(nj_))
      raise("qd must have shape (" + std::to_string(B) + ", " + std::to_string(nj_) + "), got " + shapeStr(qd));
    // Per-row argument: either one value shared by all rows or a leading batch axis.
    auto rowOf = [B](const py::object& obj, int single_ndim, const char* name) -> std::function<py::object(py::ssize_t)> {
      if (obj.is_none()) return [](py::ssize_t) { return py::object(py::none()); };
      Array a = toArray(obj, name);
      if (a.ndim() == single_ndim + 1) {
        if (a.shape(0) != B)
          raise(std::string(name) + " has a batch axis of " + std::to_string(a.shape(0)) + " rows, expected " +
                std::to_string(B));
        return [a](py::ssize_t b) { return py::object(a[py::int_(b)]); };
      }
      return [a](py::ssize_t) { return py::object(a); };
    };
    const int alpha_nd = (!alpha.is_none() && toArray(alpha, "alpha").ndim() == 1) ? 1 : 2;
    auto alphaRow = rowOf(alpha, alpha_nd, "alpha");
    auto betaRow = rowOf(beta, 1, "beta");
    auto fRow = rowOf(f_ext, 2, "f_ext");
    auto tauRow = rowOf(tau_ff, 1, "tau_ff");
    std::vector<Inputs> rows;
    rows.reserve(B);
    for (py::ssize_t b = 0; b < B; ++b) {
      try {
        rows.push_back(parse(q[py::int_(b)], qd[py::int_(b)], alphaRow(b), betaRow(b), fRow(b), tauRow(b)));
      } catch (const SolverError& e) {
        raise("batch row " + std::to_string(b) + ": " + e.what());
      }
    }
    py::ssize_t m_max = 0;
    for (const auto& r : rows) m_max = std::max(m_max, r.m);
    py::array_t<double> qdd({B, static_cast<py::ssize_t>(nj_)}), tau({B, static_cast<py::ssize_t>(nj_)});
    py::array_t<double> nu({B, m_max}), acc({B, static_cast<py::ssize_t>(ns_ + 1), static_cast<py::ssize_t>(6)});
    py::array_t<int> rank(B);
    py::array_t<double> smin(B);
    std::fill(nu.mutable_data(), nu.mutable_data() + nu.size(), std::nan(""));
    std::lock_guard<std::mutex> lock(mutex_);
    for (py::ssize_t b = 0; b < B; ++b) {
      try {
        run(rows[b]);
      } catch (const SolverError& e) {
        raise("batch row " + std::to_string(b) + ": " + e.what());
      }
      std::copy(solver_.qdd().data(), solver_.qdd().data() + nj_, qdd.mutable_data() + b * nj_);
      std::copy(solver_.commandTorques().data(), solver_.commandTorques().data() + nj_, tau.mutable_data() + b * nj_);
      std::copy(solver_.nu().data(), solver_.nu().data() + solver_.constraintCount(), nu.mutable_data() + b * m_max);
      std::copy(solver_.linkAccelerations().data(), solver_.linkAccelerations().data() + 6 * (ns_ + 1),
                acc.mutable_data() + b * 6 * (ns_ + 1));
      rank.mutable_data()[b] = solver_.constraintRank();
      smin.mutable_data()[b] = solver_.smallestSingularValue();
    }
    py::dict out;
    out["qdd"] = qdd;
    out["tau_command"] = tau;
    out["nu"] = nu;
    out["link_acc"] = acc;
    out["constraint_rank"] = rank;
    out["smallest_singular_value"] = smin;
    return out;
  }

  py::tuple responseColumns(const py::object& joints) {
    const char* what = "joints must be a 1-D sequence of integer joint indices";
    if (joints.is_none() || py::isinstance<py::str>(joints)) raise(what);
    py::array idx_any = py::array::ensure(joints);
    if (!idx_any) {
      PyErr_Clear();
      raise(what);
    }
    if (idx_any.ndim() != 1 || (idx_any.size() > 0 && idx_any.dtype().kind() != 'i' && idx_any.dtype().kind() != 'u'))
      raise(std::string(what) + ", got shape " + shapeStr(idx_any) + " of dtype " + std::string(py::str(idx_any.dtype())));
    auto idx = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(idx_any);
    const py::ssize_t k = idx.shape(0);
    Eigen::VectorXi j(k);
    for (py::ssize_t c = 0; c < k; ++c) {
      const long long v = idx.at(c);
      if (v < 0 || v >= static_cast<long long>(nj_))
        raise("joints: index " + std::to_string(v) + " out of range [0, " + std::to_string(nj_) + ")");
      j(c) = static_cast<int>(v);
    }
    Eigen::MatrixXd dq(nj_, k), dt(nj_, k);
    std::lock_guard<std::mutex> lock(mutex_);
    int rc;
    {
      py::gil_scoped_release release;
      rc = solver_.responseColumns(j, dq, dt);
    }
    if (rc != ChainHdSolver::E_NOERROR) raise(solver_.errorMessage());
    auto toNumpy = [&](const Eigen::MatrixXd& M) {
      py::array_t<double> a({static_cast<py::ssize_t>(nj_), k});
      auto v = a.mutable_unchecked<2>();
      for (py::ssize_t r = 0; r < static_cast<py::ssize_t>(nj_); ++r)
        for (py::ssize_t c = 0; c < k; ++c) v(r, c) = M(r, c);
      return a;
    };
    return py::make_tuple(toNumpy(dq), toNumpy(dt));
  }

  unsigned int nj_ = 0, ns_ = 0;

 private:
  ChainHdSolver solver_;
  KDL::Vector gravity_;
  Eigen::Matrix<double, 6, 6> alfa_ = Eigen::Matrix<double, 6, 6>::Zero();
  std::mutex mutex_;
};

}  // namespace

PYBIND11_MODULE(_core, mod) {
  mod.doc() = "C++ core of vereshchagin (Popov-Vereshchagin hybrid dynamics on KDL chains).";
  py::register_exception<SolverError>(mod, "SolverError", PyExc_ValueError);

  py::class_<JointSpec>(mod, "Joint")
      .def_static("revolute", [](const py::object& axis, const py::object& origin) {
        return makeAxisJoint(KDL::Joint::RotAxis, axis, origin); }, py::arg("axis"), py::arg("origin") = py::none())
      .def_static("prismatic", [](const py::object& axis, const py::object& origin) {
        return makeAxisJoint(KDL::Joint::TransAxis, axis, origin); }, py::arg("axis"), py::arg("origin") = py::none())
      .def_static("fixed", []() { return JointSpec(); })
      .def("__repr__", &JointSpec::repr);

  py::class_<PyChain>(mod, "Chain")
      .def(py::init<>())
      .def("add_segment", &PyChain::addSegment, R"doc(Append a segment (a joint followed by a rigid body).

Parameters
----------
name : str
    Segment (link) name.
joint : str or Joint
    'rot_x', 'rot_y', 'rot_z', 'trans_x', 'trans_y', 'trans_z' (about / along the axes of the
    segment's root frame, i.e. the previous segment's tip frame), 'fixed', or
    Joint.revolute(axis, origin) (rotation about the line through ``origin`` along ``axis``) /
    Joint.prismatic(axis) (translation along ``axis``), in the root frame.
tip : array_like, shape (4, 4), optional
    Pose of the segment's tip frame in its root frame when the joint is at 0 (KDL convention).
mass : float
    kg, >= 0.
com : array_like, shape (3,), optional
    Centre of mass in the tip frame, m.
inertia : array_like, shape (3, 3), optional
    Rotational inertia about the centre of mass, tip-frame axes, kg m^2 (symmetric PSD).
rotor_inertia : float
    Motor rotor inertia reflected to the joint (kg m^2 or kg), added to the joint's inertia.
joint_name : str, optional
    Defaults to ``name + '_joint'``.
)doc", py::arg("name"), py::arg("joint"), py::arg("tip") = py::none(),
           py::arg("mass") = 0.0, py::arg("com") = py::none(), py::arg("inertia") = py::none(),
           py::arg("rotor_inertia") = 0.0, py::arg("joint_name") = "")
      .def_property_readonly("n_joints", [](const PyChain& c) { return c.chain.getNrOfJoints(); })
      .def_property_readonly("n_segments", [](const PyChain& c) { return c.chain.getNrOfSegments(); })
      .def_property_readonly("segment_names", &PyChain::segmentNames)
      .def_property_readonly("joint_names", &PyChain::jointNames)
      .def("__repr__", [](const PyChain& c) {
        return "<vereshchagin.Chain with " + std::to_string(c.chain.getNrOfSegments()) + " segments, " +
               std::to_string(c.chain.getNrOfJoints()) + " joints>";
      });

  py::class_<SolveResult>(mod, "SolveResult")
      .def_readonly("qdd", &SolveResult::qdd)
      .def_readonly("tau_command", &SolveResult::tau_command)
      .def_readonly("nu", &SolveResult::nu)
      .def_readonly("link_acc", &SolveResult::link_acc)
      .def_readonly("constraint_rank", &SolveResult::constraint_rank)
      .def_readonly("smallest_singular_value", &SolveResult::smallest_singular_value)
      .def("__repr__", [](const SolveResult& r) {
        return "<vereshchagin.SolveResult n_joints=" + std::to_string(r.qdd.size()) +
               " m=" + std::to_string(r.nu.size()) + " rank=" + std::to_string(r.constraint_rank) + ">";
      });

  py::class_<PySolver>(mod, "Solver")
      .def(py::init<const PyChain&, const py::object&, double, py::object>(), py::arg("chain"),
           py::arg("gravity") = std::vector<double>{0.0, 0.0, -9.81}, py::arg("rcond") = 1e-12,
           py::arg("damping") = py::none())
      .def("solve", &PySolver::solve, py::arg("q"), py::arg("qd"), py::arg("alpha") = py::none(),
           py::arg("beta") = py::none(), py::arg("f_ext") = py::none(), py::arg("tau_ff") = py::none())
      .def("solve_batch", &PySolver::solveBatch, py::arg("q"), py::arg("qd"), py::arg("alpha") = py::none(),
           py::arg("beta") = py::none(), py::arg("f_ext") = py::none(), py::arg("tau_ff") = py::none())
      .def("response_columns", &PySolver::responseColumns, py::arg("joints"))
      .def_property("gravity", &PySolver::gravity, &PySolver::setGravity)
      .def_property_readonly("n_joints", [](const PySolver& s) { return s.nj_; })
      .def_property_readonly("n_segments", [](const PySolver& s) { return s.ns_; });
}
