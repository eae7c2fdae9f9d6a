// The one parser of Solver.solve's and Solver.solve_batch's arguments (SolveArgs, py_solver.hpp):
// Python objects are viewed as float64 arrays and handed to vereshchagin::BatchArgs, which checks
// their shapes into rows with a stride of a BatchInput (0: shared by every row; solve() is the
// one-row case that accepts no batch axis); keys and friction= are resolved here.
#include "py_solver.hpp"

namespace vsbind {

namespace {

// Raised for alpha/beta (the end segment's constraint) on a tree solver.
constexpr const char* kTreeAlpha =
    "alpha and beta constrain a chain's last segment; a Tree has no last segment: pass constraints={segment or "
    "link name: (alpha, beta)}";

bool given(PyObject* obj) {
  return obj != nullptr && obj != Py_None;
}

void check(const std::string& why) {
  if (!why.empty()) raise(why);
}

std::string keyLabel(const char* what, PyObject* key) {
  return std::string(what) + "[" + py::repr(key).cast<std::string>() + "]";
}

vereshchagin::Vector3 point(const KDL::Vector& p) {
  return vereshchagin::Vector3(p.x(), p.y(), p.z());
}

}  // namespace

const double* SolveArgs::keep(F64View& v) {
  if (v.keep) keep_.push_back(std::move(v.keep));
  return v.data;
}

Rows SolveArgs::vector(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok) {
  F64View v = asF64(obj, name);
  Rows r;
  check(BatchArgs::vector(r, name, v, n, scalar_ok));
  keep(v);
  return r;
}

// A block of alpha and its set-point, beta or (classical) a_desired (label: "" for solve's alpha,
// else "constraints[key]").
void SolveArgs::addBlock(int segment, PyObject* alpha, PyObject* set_point, const std::string& label, bool classical) {
  F64View a = asF64(alpha, label.empty() ? "alpha" : (label + " alpha").c_str());
  check(block(segment, a, label));
  keep(a);
  F64View sp;
  if (set_point != nullptr)
    sp = asF64(set_point, classical ? "a_desired" : label.empty() ? "beta" : (label + " beta").c_str());
  check(setPoint(set_point ? &sp : nullptr, classical, label));
  keep(sp);
}

// f_ext: (n_segments, 6) rows [force, moment] (base axes, moment about each tip origin), or a
// dict {segment or link: (6,) wrench}, the moment about that frame's origin.
void SolveArgs::parseFExt(PyObject* obj) {
  if (!PyDict_Check(obj)) {
    const long shape[2] = {ns_, 6};
    F64View v = asF64(obj, "f_ext");
    check(rows(input.f_ext, "f_ext", v, 2, shape, vereshchagin::ShapeHint::FExt));
    keep(v);
    return;
  }
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = keyLabel("f_ext", key);
    const FrameTarget t = addressing_->resolveMoving(key, label);
    vereshchagin::WrenchRows& w = input.wrenches.emplace_back();
    w.segment = t.segment;
    w.on_frame = t.merged;
    w.point = point(t.link_in_tip.p);
    w.wrench = vector(value, label.c_str(), 6);
  }
}

// constraints: {segment or link: (alpha (6, m_i), beta (m_i,))}, one entry per frame.
void SolveArgs::parseConstraints(PyObject* obj) {
  if (!PyDict_Check(obj)) raise("constraints must be a dict {segment name or index: (alpha (6, m_i), beta (m_i,))}");
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(obj, &pos, &key, &value)) {
    const std::string label = keyLabel("constraints", key);
    const FrameTarget t = addressing_->resolveMoving(key, label);
    check(frame(t.segment, point(t.link_in_tip.p), label));
    if ((!PyTuple_Check(value) && !PyList_Check(value)) || PySequence_Fast_GET_SIZE(value) != 2)
      raise(label + " must be a pair (alpha " +
            (batched() ? "(6, m_i) or (B, 6, m_i), beta (m_i,) or (B, m_i))" : "(6, m_i), beta (m_i,))"));
    keys.push_back(py::reinterpret_borrow<py::object>(key));
    starts.push_back(columns);
    addBlock(t.segment, PySequence_Fast_GET_ITEM(value, 0), PySequence_Fast_GET_ITEM(value, 1), label);
    if (t.merged) input.blocks.back().point = point(t.link_in_tip.p);
  }
}

// friction: one for every row, or in a batch a list or tuple of one per row.
void SolveArgs::parseFriction(FrictionArg& parser, PyObject* obj) {
  input.friction.clear();
  any_friction = false;
  if (!batched() || !(PyList_Check(obj) || PyTuple_Check(obj))) {
    if (const vereshchagin::FrictionModel* fm = parser.parse(obj, nj_, friction_scratch_)) input.friction.push_back(fm);
    any_friction = !input.friction.empty();
    return;
  }
  const Py_ssize_t n = PySequence_Fast_GET_SIZE(obj);
  check(batchAxis(n, "friction", "(a sequence of " + std::to_string(n) + ")"));
  friction_models_.resize(static_cast<std::size_t>(n));
  for (Py_ssize_t b = 0; b < n; ++b) {
    vereshchagin::FrictionModel& fm = friction_models_[b];
    const vereshchagin::FrictionModel* p = nullptr;
    try {
      p = parser.parse(PySequence_Fast_GET_ITEM(obj, b), nj_, fm);
    } catch (const SolverError& e) {
      raise("friction[" + std::to_string(b) + "]: " + e.what());
    }
    if (p != nullptr && p != &fm) fm = *p;  // the cache or the model's values: the next row may change them
    input.friction.push_back(p ? &fm : nullptr);
    any_friction |= p != nullptr;
  }
}

void SolveArgs::parse(PySolver& s, PyObject* const* a, bool batch) {
  start(batch, s.cppModel());
  nj_ = s.nj;
  ns_ = s.ns;
  addressing_ = s.addressing;
  keys.clear();
  starts.clear();
  keep_.clear();
  if (a[0] == nullptr || a[1] == nullptr) raise("solve() needs q and qd");
  input.q = vector(a[0], "q", nj_);
  input.q_dot = vector(a[1], "qd", nj_);
  PyObject* a_desired = given(a[kADesiredArg]) ? a[kADesiredArg] : nullptr;
  if (given(a[2])) {
    if (s.isTree()) raise(kTreeAlpha);
    if (a_desired && given(a[3]))
      raise("beta and a_desired given: a_desired (the tip's classical acceleration) replaces beta");
    addBlock(static_cast<int>(ns_) - 1, a[2],
             a_desired     ? a_desired
             : given(a[3]) ? a[3]
                           : nullptr,
             "", a_desired != nullptr);
    if (input.blocks.back().columns == 0) input.blocks.pop_back();  // no columns: nothing to constrain
  } else if (given(a[3]) || a_desired) {
    raise(std::string(a_desired ? "a_desired" : "beta") + " given without alpha");
  }
  if (given(a[4])) parseFExt(a[4]);
  if (given(a[5])) input.ff_torques = vector(a[5], "tau_ff", nj_);
  if (given(a[7])) parseConstraints(a[7]);
  parseFriction(s.friction, a[6]);
  // Pass-through weights: one per constraint column (their range: checked by vereshchagin::solve).
  if (given(a[8])) input.f_ext_pass_through = vector(a[8], "f_ext_pass_through", columns, /*scalar_ok=*/true);
  if (given(a[9])) input.ff_pass_through = vector(a[9], "tau_ff_pass_through", columns, /*scalar_ok=*/true);
}

}  // namespace vsbind
