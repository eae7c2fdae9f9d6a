#include "result_type.hpp"

#include <pybind11/numpy.h>

#include <cstddef>
#include <cstring>
#include <string>

#include "common.hpp"
#include "model_state.hpp"

namespace vsbind {

namespace {

enum View { kQdd, kTau, kNu, kLinkAcc, kFriction, kLimit, kStatus, kNumViews };

// Every numeric output lives in `data` (allocated with the object: one allocation per solve).
// Array fields are views of it whose base is the result; they are not cached (a cache would be a
// reference cycle), so each attribute access makes a new view of the same memory.
struct ResultObject {
  PyObject_VAR_HEAD PyObject* segment_keys;  // tuple or NULL: constraints= keys
  PyObject* segment_starts;                  // tuple of int: first entry of each key's part of nu
  PyObject* segment_counts;                  // tuple of int: its length
  ResultLayout layout;
  int rank;
  double smin;
  double gauss;
  int iterations;
  double data[1];  // bufferDoubles(layout) entries
};

PyTypeObject* g_type = nullptr;

Py_ssize_t bufferDoubles(const ResultLayout& l) {
  const Py_ssize_t nj = l.nj, ns = l.ns, m = l.m;  // no int arithmetic: sizes from a state are checked first
  Py_ssize_t n = 2 * nj + m + 6 * (ns + 1);
  if (l.friction) n += 2 * nj + (nj + 1) / 2;  // friction, limit torques; int32 status
  return n;
}

// Sizes a result can have: up to kMaxSize joints or segments, m <= 6 per segment.
constexpr long long kMaxSize = 1 << 24;

// A size entry of a SolveResult state, in [0, hi] (model_state.hpp's stateInt).
int stateSize(const py::handle& obj, long long hi, const char* what) {
  return static_cast<int>(stateInt(obj, 0, hi, std::string("SolveResult state: ") + what));
}

ResultObject* self(PyObject* o) {
  return reinterpret_cast<ResultObject*>(o);
}

double* base(PyObject* o) {
  return self(o)->data;
}

void dealloc(PyObject* o) {
  ResultObject* r = self(o);
  Py_CLEAR(r->segment_keys);
  Py_CLEAR(r->segment_starts);
  Py_CLEAR(r->segment_counts);
  PyTypeObject* tp = Py_TYPE(o);
  tp->tp_free(o);
  Py_DECREF(tp);
}

PyObject* allocate(const ResultLayout& layout) {
  ResultObject* r = PyObject_NewVar(ResultObject, g_type, bufferDoubles(layout));
  if (r == nullptr) throw py::error_already_set();
  r->segment_keys = r->segment_starts = r->segment_counts = nullptr;
  r->layout = layout;
  r->rank = 0;
  r->smin = r->gauss = 0.0;
  r->iterations = 0;
  return reinterpret_cast<PyObject*>(r);
}

// A view at `offset_doubles` into the result's data, shaped `dims`; its base is the result.
PyObject* makeView(ResultObject* r, Py_ssize_t offset_doubles, int nd, const Py_ssize_t* dims, int type_num) {
  const auto& api = py::detail::npy_api::get();
  constexpr int flags = py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_ALIGNED_ |
                        py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  void* data = r->data + offset_doubles;
  PyObject* v = api.PyArray_NewFromDescr_(api.PyArray_Type_, api.PyArray_DescrFromType_(type_num), nd, dims, nullptr,
                                          data, flags, nullptr);
  if (v == nullptr) return nullptr;
  Py_INCREF(r);
  if (api.PyArray_SetBaseObject_(v, reinterpret_cast<PyObject*>(r)) != 0) {
    Py_DECREF(v);
    return nullptr;
  }
  return v;
}

Py_ssize_t offsetOf(const ResultLayout& l, int which) {
  const Py_ssize_t nj = l.nj, link = 6 * (l.ns + 1);
  switch (which) {
    case kQdd:
      return 0;
    case kTau:
      return nj;
    case kNu:
      return 2 * nj;
    case kLinkAcc:
      return 2 * nj + l.m;
    case kFriction:
      return 2 * nj + l.m + link;
    case kLimit:
      return 3 * nj + l.m + link;
    default:
      return 4 * nj + l.m + link;  // kStatus
  }
}

PyObject* getView(PyObject* o, void* closure) {
  ResultObject* r = self(o);
  const int which = static_cast<int>(reinterpret_cast<intptr_t>(closure));
  if (which >= kFriction && !r->layout.friction) Py_RETURN_NONE;
  const ResultLayout& l = r->layout;
  Py_ssize_t dims[2] = {l.nj, 0};
  int nd = 1;
  if (which == kNu) dims[0] = l.m;
  if (which == kLinkAcc) {
    dims[0] = l.ns + 1;
    dims[1] = 6;
    nd = 2;
  }
  const int type = which == kStatus ? py::detail::npy_api::NPY_INT_ : py::detail::npy_api::NPY_DOUBLE_;
  return makeView(r, offsetOf(l, which), nd, dims, type);
}

PyObject* getRank(PyObject* o, void*) {
  return PyLong_FromLong(self(o)->rank);
}
PyObject* getSmin(PyObject* o, void*) {
  return PyFloat_FromDouble(self(o)->smin);
}
PyObject* getGauss(PyObject* o, void*) {
  if (!self(o)->layout.friction) Py_RETURN_NONE;
  return PyFloat_FromDouble(self(o)->gauss);
}
PyObject* getIterations(PyObject* o, void*) {
  if (!self(o)->layout.friction) Py_RETURN_NONE;
  return PyLong_FromLong(self(o)->iterations);
}

PyObject* getSegmentNu(PyObject* o, void*) {
  ResultObject* r = self(o);
  if (r->segment_keys == nullptr) Py_RETURN_NONE;
  {
    try {
      py::object nu = py::reinterpret_steal<py::object>(getView(o, reinterpret_cast<void*>(kNu)));
      if (!nu) throw py::error_already_set();
      py::dict d;
      const py::tuple keys = py::reinterpret_borrow<py::tuple>(r->segment_keys);
      const py::tuple starts = py::reinterpret_borrow<py::tuple>(r->segment_starts);
      const py::tuple counts = py::reinterpret_borrow<py::tuple>(r->segment_counts);
      for (std::size_t k = 0; k < keys.size(); ++k) {
        const Py_ssize_t a = starts[k].cast<Py_ssize_t>(), c = counts[k].cast<Py_ssize_t>();
        d[keys[k]] = nu[py::slice(a, a + c, 1)];
      }
      return d.release().ptr();
    } catch (py::error_already_set& e) {
      e.restore();
      return nullptr;
    }
  }
}

PyObject* repr(PyObject* o) {
  const ResultObject* r = self(o);
  const std::string s = "<vereshchagin.SolveResult n_joints=" + std::to_string(r->layout.nj) +
                        " m=" + std::to_string(r->layout.m) + " rank=" + std::to_string(r->rank) +
                        (r->layout.friction ? " friction" : "") + ">";
  return PyUnicode_FromString(s.c_str());
}

PyObject* stateTuple(PyObject* o) {
  const ResultObject* r = self(o);
  PyObject* buf = PyBytes_FromStringAndSize(reinterpret_cast<const char*>(r->data),
                                            static_cast<Py_ssize_t>(sizeof(double)) * bufferDoubles(r->layout));
  if (buf == nullptr) return nullptr;
  auto orNone = [](PyObject* x) {
    PyObject* v = x ? x : Py_None;
    Py_INCREF(v);
    return v;
  };
  return Py_BuildValue("(iiiiddiiNNNN)", r->layout.nj, r->layout.ns, r->layout.m, static_cast<int>(r->layout.friction),
                       r->smin, r->gauss, r->rank, r->iterations, buf, orNone(r->segment_keys),
                       orNone(r->segment_starts), orNone(r->segment_counts));
}

// A segment_nu layout: keys, starts and counts of equal length, each part inside nu (m entries).
void checkSegmentLayout(const py::handle& keys, const py::handle& starts, const py::handle& counts, int m) {
  if (starts.is_none() || counts.is_none() || py::len(keys) != py::len(starts) || py::len(keys) != py::len(counts))
    throw SolverError("SolveResult state: segment layout of inconsistent lengths");
  const py::tuple s = py::reinterpret_borrow<py::tuple>(starts), c = py::reinterpret_borrow<py::tuple>(counts);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const int a = stateSize(s[k], m, "segment layout start"), n = stateSize(c[k], m, "segment layout count");
    if (a + n > m) throw SolverError("SolveResult state: segment layout beyond nu");
  }
}

PyObject* fromState(PyObject*, PyObject* args) {
  try {
    const py::tuple t = py::reinterpret_borrow<py::tuple>(args);
    if (t.size() != 12) throw SolverError("SolveResult state must have 12 entries");
    ResultLayout l;
    l.nj = stateSize(t[0], kMaxSize, "n_joints");
    l.ns = stateSize(t[1], kMaxSize, "n_segments");
    l.m = stateSize(t[2], 6LL * l.ns, "m");
    l.friction = stateSize(t[3], 1, "the friction flag") != 0;
    if (!PyBytes_Check(t[8].ptr())) throw SolverError("SolveResult state: data must be bytes");
    const std::string buf = t[8].cast<std::string>();
    if (buf.size() != sizeof(double) * static_cast<std::size_t>(bufferDoubles(l)))
      throw SolverError("SolveResult state: data of the wrong size");
    for (int k = 9; k < 12; ++k)
      if (!t[k].is_none() && !py::isinstance<py::tuple>(t[k]))
        throw SolverError("SolveResult state: segment layout entries must be tuples or None");
    if (!t[9].is_none()) checkSegmentLayout(t[9], t[10], t[11], l.m);
    PyObject* o = allocate(l);
    ResultObject* r = self(o);
    std::memcpy(r->data, buf.data(), buf.size());
    r->smin = t[4].cast<double>();
    r->gauss = t[5].cast<double>();
    r->rank = t[6].cast<int>();
    r->iterations = t[7].cast<int>();
    if (!t[9].is_none()) {
      r->segment_keys = t[9].cast<py::tuple>().release().ptr();
      r->segment_starts = t[10].cast<py::tuple>().release().ptr();
      r->segment_counts = t[11].cast<py::tuple>().release().ptr();
    }
    return o;
  } catch (const SolverError& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
  } catch (py::error_already_set& e) {
    e.restore();
  } catch (const std::exception& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
  }
  return nullptr;
}

PyObject* g_from_state = nullptr;

PyObject* reduce(PyObject* o, PyObject*) {
  PyObject* state = stateTuple(o);
  if (state == nullptr) return nullptr;
  return Py_BuildValue("(ON)", g_from_state, state);
}

PyObject* copyResult(PyObject* o, PyObject*) {
  PyObject* state = stateTuple(o);
  if (state == nullptr) return nullptr;
  PyObject* r = fromState(nullptr, state);
  Py_DECREF(state);
  return r;
}

PyObject* deepcopyResult(PyObject* o, PyObject*) {
  return copyResult(o, nullptr);
}

PyGetSetDef g_getset[] = {{"qdd", getView, nullptr, nullptr, reinterpret_cast<void*>(kQdd)},
                          {"tau_command", getView, nullptr, nullptr, reinterpret_cast<void*>(kTau)},
                          {"nu", getView, nullptr, nullptr, reinterpret_cast<void*>(kNu)},
                          {"link_acc", getView, nullptr, nullptr, reinterpret_cast<void*>(kLinkAcc)},
                          {"constraint_rank", getRank, nullptr, nullptr, nullptr},
                          {"smallest_singular_value", getSmin, nullptr, nullptr, nullptr},
                          {"friction_torque", getView, nullptr, nullptr, reinterpret_cast<void*>(kFriction)},
                          {"limit_torque", getView, nullptr, nullptr, reinterpret_cast<void*>(kLimit)},
                          {"status", getView, nullptr, nullptr, reinterpret_cast<void*>(kStatus)},
                          {"gauss_value", getGauss, nullptr, nullptr, nullptr},
                          {"iterations", getIterations, nullptr, nullptr, nullptr},
                          {"segment_nu", getSegmentNu, nullptr, nullptr, nullptr},
                          {nullptr, nullptr, nullptr, nullptr, nullptr}};

// Docstrings (and those of g_getset, g_from_state_def) are set in bindResultType().
PyMethodDef g_methods[] = {{"__reduce__", reduce, METH_NOARGS, nullptr},
                           {"__copy__", copyResult, METH_NOARGS, nullptr},
                           {"__deepcopy__", deepcopyResult, METH_O, nullptr},
                           {nullptr, nullptr, 0, nullptr}};

PyMethodDef g_from_state_def = {"_result_from_state", fromState, METH_VARARGS, nullptr};

}  // namespace

void bindResultType(py::module_& mod) {
  for (PyGetSetDef* g = g_getset; g->name != nullptr; ++g) g->doc = doc(std::string("SolveResult.") + g->name);
  for (PyMethodDef* m = g_methods; m->ml_name != nullptr; ++m)
    m->ml_doc = doc(std::string("SolveResult.") + m->ml_name);
  g_from_state_def.ml_doc = doc("_core._result_from_state");
  static PyType_Slot slots[] = {{Py_tp_dealloc, reinterpret_cast<void*>(dealloc)},
                                {Py_tp_repr, reinterpret_cast<void*>(repr)},
                                {Py_tp_getset, g_getset},
                                {Py_tp_methods, g_methods},
                                {Py_tp_doc, const_cast<char*>(doc("SolveResult"))},
                                {0, nullptr}};
  static PyType_Spec spec = {"vereshchagin._core.SolveResult", static_cast<int>(offsetof(ResultObject, data)),
                             static_cast<int>(sizeof(double)), Py_TPFLAGS_DEFAULT, slots};
  PyObject* type = PyType_FromSpec(&spec);
  if (type == nullptr) throw py::error_already_set();
  g_type = reinterpret_cast<PyTypeObject*>(type);
  mod.add_object("SolveResult", py::reinterpret_borrow<py::object>(type));
  g_from_state = PyCFunction_NewEx(&g_from_state_def, nullptr, mod.attr("__name__").ptr());
  if (g_from_state == nullptr) throw py::error_already_set();
  mod.add_object("_result_from_state", py::reinterpret_borrow<py::object>(g_from_state));
}

namespace {

std::string layoutString(const ResultLayout& l) {
  return "n_joints = " + std::to_string(l.nj) + ", n_segments = " + std::to_string(l.ns) +
         ", m = " + std::to_string(l.m) + (l.friction ? " with" : " without") + " friction";
}

}  // namespace

py::object newResult(const ResultLayout& layout, PyObject* out) {
  if (out == nullptr) return py::reinterpret_steal<py::object>(allocate(layout));
  if (Py_TYPE(out) != g_type)
    throw SolverError("out must be a SolveResult returned by an earlier solve(), got " +
                      std::string(Py_TYPE(out)->tp_name));
  ResultObject* r = self(out);
  const ResultLayout& l = r->layout;
  if (l.nj != layout.nj || l.ns != layout.ns || l.m != layout.m || l.friction != layout.friction)
    throw SolverError("out does not fit this solve: it holds " + layoutString(l) + ", this solve has " +
                      layoutString(layout));
  Py_CLEAR(r->segment_keys);
  Py_CLEAR(r->segment_starts);
  Py_CLEAR(r->segment_counts);
  return py::reinterpret_borrow<py::object>(out);
}

ResultPointers resultPointers(PyObject* o) {
  const ResultLayout& l = self(o)->layout;
  double* b = base(o);
  ResultPointers p;
  p.qdd = b + offsetOf(l, kQdd);
  p.tau_command = b + offsetOf(l, kTau);
  p.nu = b + offsetOf(l, kNu);
  p.link_acc = b + offsetOf(l, kLinkAcc);
  p.friction_torque = l.friction ? b + offsetOf(l, kFriction) : nullptr;
  p.limit_torque = l.friction ? b + offsetOf(l, kLimit) : nullptr;
  p.status = l.friction ? reinterpret_cast<int*>(b + offsetOf(l, kStatus)) : nullptr;
  return p;
}

void setResultScalars(PyObject* o, int rank, double smin, double gauss, int iterations) {
  ResultObject* r = self(o);
  r->rank = rank;
  r->smin = smin;
  r->gauss = gauss;
  r->iterations = iterations;
}

void setSegmentLayout(PyObject* o, py::tuple keys, py::tuple starts, py::tuple counts) {
  ResultObject* r = self(o);
  r->segment_keys = keys.release().ptr();
  r->segment_starts = starts.release().ptr();
  r->segment_counts = counts.release().ptr();
}

}  // namespace vsbind
