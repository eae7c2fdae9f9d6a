// Python Solver and SolveResult: checked inputs, GIL released during solves, one lock per solver.
#include <pybind11/stl.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <mutex>

#include "chain_bindings.hpp"
#include "common.hpp"
#include "friction_args.hpp"
#include "vereshchagin/chain_hd_solver.hpp"
#include "vereshchagin/friction_solver.hpp"

namespace vsbind {

using vereshchagin::ChainHdSolver;

namespace {

struct SolveResult {
  py::array_t<double> qdd, tau_command, nu, link_acc;
  int constraint_rank = 0;
  double smallest_singular_value = 0.0;
  // Friction-aware solves only (None otherwise).
  py::object friction_torque = py::none(), limit_torque = py::none(), status = py::none(), gauss_value = py::none(),
             iterations = py::none();
  // constraints= solves only: {key: nu_i} per entry of the dict (views of nu's entries).
  py::object segment_nu = py::none();
};

class PySolver {
 public:
  PySolver(const PyChain& chain, const py::object& gravity, const py::object& rcond, py::object damping)
      : chain_(chain), solver_(chain.robot.chain, KDL::Twist::Zero()), friction_solver_(chain.robot.chain, KDL::Twist::Zero()) {
    const auto nj = static_cast<Eigen::Index>(chain.robot.joints.size());
    chain_friction_ = chain_lower_ = chain_upper_ = Eigen::VectorXd::Zero(nj);
    for (Eigen::Index k = 0; k < nj; ++k) {
      chain_friction_(k) = chain.robot.joints[k].friction;
      chain_lower_(k) = chain.robot.joints[k].lower;
      chain_upper_(k) = chain.robot.joints[k].upper;
    }
    if (solver_.modelError() != ChainHdSolver::E_NOERROR) raise(std::string("invalid chain: ") + solver_.errorMessage());
    setGravity(gravity);
    vereshchagin::SolverOptions opt;
    opt.rcond = scalarArg(rcond, "rcond");
    if (!damping.is_none()) {
      opt.policy = vereshchagin::SingularityPolicy::DampedLeastSquares;
      opt.damping = scalarArg(damping, "damping");
    }
    if (solver_.setOptions(opt) != ChainHdSolver::E_NOERROR) raise(solver_.errorMessage());
    friction_solver_.setOptions(opt);
    nj_ = solver_.nrOfJoints();
    ns_ = solver_.nrOfSegments();
    alfa_ = ChainHdSolver::Matrix6X::Zero(6, solver_.maxConstraints());
    beta_ = Eigen::VectorXd::Zero(solver_.maxConstraints());
    segs_ = Eigen::VectorXi::Zero(solver_.maxConstraints());
  }

  void setGravity(const py::object& gravity) {
    const KDL::Vector g = vec3(gravity, "gravity");
    gravity_ = g;
    solver_.setRootAcceleration(KDL::Twist(-g, KDL::Vector::Zero()));  // base accelerates up
    friction_solver_.setRootAcceleration(KDL::Twist(-g, KDL::Vector::Zero()));
  }
  py::array_t<double> gravity() const { return copyVector(gravity_.data, 3); }

  // Checked, converted inputs of one solve (views into numpy memory, kept alive by the arrays).
  struct Inputs {
    Array q, qd, alpha, beta, f_ext, tau;
    bool has_f_ext = false, has_tau = false;
    py::ssize_t m = 0;
    // constraints={segment: (alpha_i, beta_i)}: one entry per segment, in the dict's order.
    bool has_segments = false;
    std::vector<int> seg;
    std::vector<Array> seg_alpha, seg_beta;
    py::ssize_t m_total = 0;  // m plus the segment columns
  };

  // alpha (6, m) or (6,) -> (6, m), checked; `name` for messages.
  static Array alphaArg(const py::object& alpha, const std::string& name) {
    Array a = toArray(alpha, name.c_str());
    if (a.ndim() == 1 && a.shape(0) == 6) a = a.reshape({6, 1});
    if (a.ndim() != 2 || a.shape(0) != 6)
      raise(name + " must have shape (6, m) with rows [force; moment], got " + shapeStr(a));
    if (a.shape(1) > 6) raise(name + " has " + std::to_string(a.shape(1)) + " columns; at most 6 constraints per segment");
    requireFinite(a, name.c_str());
    return a;
  }

  void parseConstraints(const py::object& constraints, Inputs& in) const {
    if (constraints.is_none()) return;
    if (!py::isinstance<py::dict>(constraints))
      raise("constraints must be a dict {segment name or index: (alpha (6, m_i), beta (m_i,))}");
    in.has_segments = true;
    in.m_total = in.m;
    std::vector<int> seen;
    for (auto item : constraints.cast<py::dict>()) {
      const py::object key = py::reinterpret_borrow<py::object>(item.first);
      const std::string label = "constraints[" + std::string(py::repr(key)) + "]";
      if (!py::isinstance<py::str>(key) && !py::isinstance<py::int_>(key))
        raise(label + ": keys must be segment names (str) or indices (int)");
      int seg;
      if (py::isinstance<py::int_>(key)) {
        const long long v = key.cast<long long>();
        const long long ns = static_cast<long long>(ns_);
        if (v < -ns || v >= ns) raise(label + ": segment index out of range [" + std::to_string(-ns) + ", " + std::to_string(ns) + ")");
        seg = static_cast<int>(v < 0 ? v + ns : v);
      } else {
        KDL::Frame offset;
        seg = chain_.resolveSegment(key, offset);  // raises for unknown names
        if (!KDL::Equal(offset, KDL::Frame::Identity(), 1e-12))
          raise(label + ": '" + key.cast<std::string>() + "' is a link merged into segment '" +
                chain_.robot.chain.getSegment(seg).getName() + "' (constraints are about segment tip origins: use that name)");
      }
      if (std::find(seen.begin(), seen.end(), seg) != seen.end())
        raise(label + ": segment " + std::to_string(seg) + " appears twice");
      seen.push_back(seg);
      py::object value = py::reinterpret_borrow<py::object>(item.second);
      if (!py::isinstance<py::tuple>(value) && !py::isinstance<py::list>(value))
        raise(label + " must be a pair (alpha (6, m_i), beta (m_i,))");
      py::sequence pair = value.cast<py::sequence>();
      if (pair.size() != 2) raise(label + " must be a pair (alpha (6, m_i), beta (m_i,))");
      Array a = alphaArg(pair[0], label + " alpha");
      Array b = vectorArg(pair[1], (label + " beta").c_str(), a.shape(1));
      if (seg == static_cast<int>(ns_) - 1 && in.m > 0 && in.m + a.shape(1) > 6)
        raise(label + ": together with alpha (last segment) more than 6 constraints on the last segment");
      in.seg.push_back(seg);
      in.seg_alpha.push_back(a);
      in.seg_beta.push_back(b);
      in.m_total += a.shape(1);
    }
  }

  Inputs parse(const py::object& q, const py::object& qd, const py::object& alpha, const py::object& beta,
               const py::object& f_ext, const py::object& tau_ff) const {
    Inputs in;
    in.q = vectorArg(q, "q", nj_);
    in.qd = vectorArg(qd, "qd", nj_);
    if (!alpha.is_none()) {
      in.alpha = alphaArg(alpha, "alpha");
      in.m = in.alpha.shape(1);
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

  // friction: None/False (frictionless), True (the chain's friction values, static = kinetic), or
  // an object with attributes static, kinetic (or None) and velocity_tolerance.
  bool parseFriction(const py::object& friction, vereshchagin::FrictionModel& fm) const {
    if (friction.is_none()) return false;
    if (py::isinstance<py::bool_>(friction)) {
      if (!friction.cast<bool>()) return false;
      fm.static_friction = chain_friction_;
      fm.kinetic_friction.resize(0);
      fm.lower = chain_lower_;
      fm.upper = chain_upper_;
      return true;
    }
    if (!py::hasattr(friction, "static"))
      raise("friction must be None, True or a vereshchagin.Friction(static=..., kinetic=..., velocity_tolerance=...)");
    Array fs = vectorArg(friction.attr("static"), "friction.static", nj_);
    fm.static_friction = Eigen::Map<const Eigen::VectorXd>(fs.data(), nj_);
    const py::object kin = py::getattr(friction, "kinetic", py::none());
    if (kin.is_none()) {
      fm.kinetic_friction.resize(0);
    } else {
      Array fk = vectorArg(kin, "friction.kinetic", nj_);
      fm.kinetic_friction = Eigen::Map<const Eigen::VectorXd>(fk.data(), nj_);
    }
    const py::object tol = py::getattr(friction, "velocity_tolerance", py::none());
    if (!tol.is_none()) fm.velocity_tolerance = scalarArg(tol, "friction.velocity_tolerance");
    const py::object lower = py::getattr(friction, "lower", py::none()), upper = py::getattr(friction, "upper", py::none());
    if (!lower.is_none() || !upper.is_none()) {
      fm.lower = Eigen::VectorXd::Constant(nj_, -std::numeric_limits<double>::infinity());
      fm.upper = Eigen::VectorXd::Constant(nj_, std::numeric_limits<double>::infinity());
      auto limitArg = [&](const py::object& obj, const char* name, Eigen::VectorXd& out) {
        if (obj.is_none()) return;
        Array a = toArray(obj, name);
        if (a.ndim() != 1 || a.shape(0) != static_cast<py::ssize_t>(nj_))
          raise(std::string(name) + " must have shape (" + std::to_string(nj_) + ",), got " + shapeStr(a));
        for (py::ssize_t j = 0; j < a.shape(0); ++j) {
          if (std::isnan(a.at(j))) raise(std::string(name) + " contains NaN");
          out(j) = a.at(j);
        }
      };
      limitArg(lower, "friction.lower", fm.lower);
      limitArg(upper, "friction.upper", fm.upper);
      const py::object ltol = py::getattr(friction, "limit_tolerance", py::none());
      if (!ltol.is_none()) fm.limit_tolerance = scalarArg(ltol, "friction.limit_tolerance");
    }
    checkFriction(fm);
    return true;
  }

  // Runs the C++ solve without the GIL. Caller holds mutex_.
  void run(const Inputs& in, const vereshchagin::FrictionModel* fm = nullptr) {
    using Map6X = Eigen::Map<const ChainHdSolver::Matrix6X>;
    using MapV = Eigen::Map<const Eigen::VectorXd>;
    const auto m = in.m;
    for (py::ssize_t r = 0; r < 6; ++r)
      for (py::ssize_t c = 0; c < m; ++c) alfa_(r, c) = in.alpha.data()[r * m + c];
    for (py::ssize_t c = 0; c < m; ++c) {
      beta_(c) = in.beta.data()[c];
      segs_(c) = static_cast<int>(ns_) - 1;
    }
    py::ssize_t col = m;
    for (std::size_t k = 0; k < in.seg.size(); ++k) {
      const py::ssize_t mk = in.seg_alpha[k].shape(1);
      for (py::ssize_t c = 0; c < mk; ++c, ++col) {
        for (py::ssize_t r = 0; r < 6; ++r) alfa_(r, col) = in.seg_alpha[k].data()[r * mk + c];
        beta_(col) = in.seg_beta[k].data()[c];
        segs_(col) = in.seg[k];
      }
    }
    const MapV q(in.q.data(), nj_), qd(in.qd.data(), nj_);
    const MapV beta(m ? in.beta.data() : nullptr, m);
    const Map6X f(in.has_f_ext ? in.f_ext.data() : nullptr, 6, in.has_f_ext ? ns_ : 0);
    const MapV tau(in.has_tau ? in.tau.data() : nullptr, in.has_tau ? nj_ : 0);
    int rc;
    last_friction_ = fm != nullptr;
    {
      py::gil_scoped_release release;
      if (in.has_segments) {
        const auto A = alfa_.leftCols(col);
        const auto b = beta_.head(col);
        const auto sg = segs_.head(col);
        rc = fm ? friction_solver_.solve(q, qd, A, b, sg, f, tau, *fm) : solver_.solve(q, qd, A, b, sg, f, tau);
      } else {
        rc = fm ? friction_solver_.solve(q, qd, alfa_.leftCols(m), beta, f, tau, *fm)
                : solver_.solve(q, qd, alfa_.leftCols(m), beta, f, tau);
      }
    }
    if (rc != ChainHdSolver::E_NOERROR) raise(fm ? friction_solver_.errorMessage() : solver_.errorMessage());
  }

  // The solver that answered the last run().
  ChainHdSolver& answered() { return last_friction_ ? friction_solver_.hdSolver() : solver_; }

  SolveResult result() {
    const ChainHdSolver& s = answered();
    SolveResult r;
    if (last_friction_) {  // outputs at the friction optimum
      r.qdd = copyVector(friction_solver_.qdd().data(), nj_);
      r.tau_command = copyVector(friction_solver_.commandTorques().data(), nj_);
      r.nu = copyVector(friction_solver_.nu().data(), friction_solver_.nu().size());
    } else {
      r.qdd = copyVector(s.qdd().data(), nj_);
      r.tau_command = copyVector(s.commandTorques().data(), nj_);
      r.nu = copyVector(s.nu().data(), s.constraintCount());
    }
    const ChainHdSolver::Matrix6X& acc = last_friction_ ? friction_solver_.linkAccelerations() : s.linkAccelerations();
    r.link_acc = py::array_t<double>({static_cast<py::ssize_t>(ns_ + 1), static_cast<py::ssize_t>(6)});
    std::copy(acc.data(), acc.data() + 6 * (ns_ + 1), r.link_acc.mutable_data());
    r.constraint_rank = s.constraintRank();
    r.smallest_singular_value = s.smallestSingularValue();
    if (last_friction_) {
      r.friction_torque = copyVector(friction_solver_.frictionTorques().data(), nj_);
      r.limit_torque = copyVector(friction_solver_.limitTorques().data(), nj_);
      py::array_t<int> st(static_cast<py::ssize_t>(nj_));
      for (unsigned int j = 0; j < nj_; ++j) st.mutable_data()[j] = friction_solver_.status()[j];
      r.status = st;
      const double gauss = friction_solver_.gaussValue();  // not finite only for overflowing inputs
      if (!std::isfinite(gauss)) raise("the results overflow: gauss_value is beyond the double range");
      r.gauss_value = py::float_(gauss);
      r.iterations = py::int_(friction_solver_.iterations());
    }
    return r;
  }

  SolveResult solve(const py::object& q, const py::object& qd, const py::object& alpha, const py::object& beta,
                    const py::object& f_ext, const py::object& tau_ff, const py::object& friction,
                    const py::object& constraints) {
    Inputs in = parse(q, qd, alpha, beta, f_ext, tau_ff);
    parseConstraints(constraints, in);
    vereshchagin::FrictionModel fm;
    const bool with_friction = parseFriction(friction, fm);
    std::lock_guard<std::mutex> lock(mutex_);
    run(in, with_friction ? &fm : nullptr);
    SolveResult r = result();
    if (in.has_segments) {
      py::dict per_segment;
      py::ssize_t offset = in.m;
      const double* nu = r.nu.data();
      std::size_t k = 0;
      for (auto item : constraints.cast<py::dict>()) {
        const py::ssize_t mk = in.seg_alpha[k++].shape(1);
        per_segment[item.first] = copyVector(nu + offset, static_cast<unsigned int>(mk));
        offset += mk;
      }
      r.segment_nu = per_segment;
    }
    return r;
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
        run(rows[b]);  // frictionless
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
      rc = answered().responseColumns(j, dq, dt);
    }
    if (rc != ChainHdSolver::E_NOERROR) raise(answered().errorMessage());
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
  PyChain chain_;  // for segment names
  ChainHdSolver solver_;
  vereshchagin::FrictionSolver friction_solver_;
  Eigen::VectorXd chain_friction_, chain_lower_, chain_upper_;
  bool last_friction_ = false;
  KDL::Vector gravity_;
  ChainHdSolver::Matrix6X alfa_;  // all constraint columns of a solve (6 x maxConstraints())
  Eigen::VectorXd beta_;
  Eigen::VectorXi segs_;
  std::mutex mutex_;
};

}  // namespace

void bindSolver(py::module_& mod) {
  py::class_<SolveResult>(mod, "SolveResult")
      .def_readonly("qdd", &SolveResult::qdd)
      .def_readonly("tau_command", &SolveResult::tau_command)
      .def_readonly("nu", &SolveResult::nu)
      .def_readonly("link_acc", &SolveResult::link_acc)
      .def_readonly("constraint_rank", &SolveResult::constraint_rank)
      .def_readonly("smallest_singular_value", &SolveResult::smallest_singular_value)
      .def_readonly("friction_torque", &SolveResult::friction_torque)
      .def_readonly("limit_torque", &SolveResult::limit_torque)
      .def_readonly("status", &SolveResult::status)
      .def_readonly("gauss_value", &SolveResult::gauss_value)
      .def_readonly("iterations", &SolveResult::iterations)
      .def_readonly("segment_nu", &SolveResult::segment_nu)
      .def("__repr__", [](const SolveResult& r) {
        return "<vereshchagin.SolveResult n_joints=" + std::to_string(r.qdd.size()) +
               " m=" + std::to_string(r.nu.size()) + " rank=" + std::to_string(r.constraint_rank) + ">";
      });

  py::class_<PySolver>(mod, "Solver")
      .def(py::init<const PyChain&, const py::object&, const py::object&, py::object>(), py::arg("chain"),
           py::arg("gravity") = std::vector<double>{0.0, 0.0, -9.81}, py::arg("rcond") = 1e-12,
           py::arg("damping") = py::none())
      .def("solve", &PySolver::solve, py::arg("q"), py::arg("qd"), py::arg("alpha") = py::none(),
           py::arg("beta") = py::none(), py::arg("f_ext") = py::none(), py::arg("tau_ff") = py::none(),
           py::arg("friction") = py::none(), py::arg("constraints") = py::none())
      .def("solve_batch", &PySolver::solveBatch, py::arg("q"), py::arg("qd"), py::arg("alpha") = py::none(),
           py::arg("beta") = py::none(), py::arg("f_ext") = py::none(), py::arg("tau_ff") = py::none())
      .def("response_columns", &PySolver::responseColumns, py::arg("joints"))
      .def_property("gravity", &PySolver::gravity, &PySolver::setGravity)
      .def_property_readonly("n_joints", [](const PySolver& s) { return s.nj_; })
      .def_property_readonly("n_segments", [](const PySolver& s) { return s.ns_; });
}

}  // namespace vsbind
