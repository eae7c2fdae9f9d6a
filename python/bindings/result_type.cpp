// vereshchagin.SolveResult: storage, views and the solve path's fast access (result_type.hpp).
// Pickling, copies, segment_nu and repr are Python code over this storage (vereshchagin/_results.py).
#include "result_type.hpp"

#include <cstring>
#include <string>

#include "common.hpp"

namespace vsbind {

namespace {

enum View { kQdd, kTau, kNu, kLinkAcc, kFriction, kLimit, kStatus, kData };  // kData: the whole buffer

// Every numeric output lives in `data` (allocated with the object: one allocation per solve).
// Array fields are views of it whose base is the result; they are not cached (a cache would be a
// reference cycle), so each attribute access makes a new view of the same memory.
struct ResultObject {
  PyObject_VAR_HEAD PyObject* segments[3];  // constraints= keys, starts and counts in nu (tuples), or NULL
  ResultLayout layout;
  int rank, iterations;
  double smin, gauss;
  double data[1];  // bufferDoubles(layout) entries
};

PyTypeObject* g_type = nullptr;

Py_ssize_t bufferDoubles(const ResultLayout& l) {
  const Py_ssize_t nj = l.nj, ns = l.ns, m = l.m;  // no int arithmetic: sizes from a state are checked first
  return 2 * nj + m + 6 * (ns + 1) + (l.friction ? 2 * nj + (nj + 1) / 2 : 0);  // friction, limit, int32 status
}

ResultObject* self(PyObject* o) {
  return reinterpret_cast<ResultObject*>(o);
}

void clearSegments(ResultObject* r) {
  for (PyObject*& p : r->segments) Py_CLEAR(p);
}

void dealloc(PyObject* o) {
  clearSegments(self(o));
  PyTypeObject* tp = Py_TYPE(o);
  tp->tp_free(o);
  Py_DECREF(tp);
}

PyObject* allocate(const ResultLayout& layout) {
  ResultObject* r = PyObject_NewVar(ResultObject, g_type, bufferDoubles(layout));
  if (r == nullptr) throw py::error_already_set();
  r->segments[0] = r->segments[1] = r->segments[2] = nullptr;
  r->layout = layout;
  r->rank = r->iterations = 0;
  r->smin = r->gauss = 0.0;
  return reinterpret_cast<PyObject*>(r);
}

Py_ssize_t offsetOf(const ResultLayout& l, int which) {
  const Py_ssize_t nj = l.nj, link = 6 * (l.ns + 1);
  const Py_ssize_t offsets[] = {0, nj, 2 * nj, 2 * nj + l.m, 2 * nj + l.m + link, 3 * nj + l.m + link};
  return which == kData ? 0 : which < kStatus ? offsets[which] : 4 * nj + l.m + link;
}

// Field `which` (closure) as a view into the result's data whose base is the result (kData: all of
// it as doubles, read-only: the pickle state's bytes, vereshchagin/_results.py).
PyObject* getView(PyObject* o, void* closure) {
  ResultObject* r = self(o);
  const int which = static_cast<int>(reinterpret_cast<intptr_t>(closure));
  const ResultLayout& l = r->layout;
  if (which >= kFriction && which <= kStatus && !l.friction) Py_RETURN_NONE;
  const Py_ssize_t n = which == kNu ? l.m : which == kData ? bufferDoubles(l) : l.nj;
  const Py_ssize_t dims[2] = {which == kLinkAcc ? l.ns + 1 : n, 6};
  const auto& api = py::detail::npy_api::get();
  constexpr int flags = py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_ALIGNED_;
  const int writeable = which == kData ? 0 : py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  const int type = which == kStatus ? py::detail::npy_api::NPY_INT_ : py::detail::npy_api::NPY_DOUBLE_;
  PyObject* v =
      api.PyArray_NewFromDescr_(api.PyArray_Type_, api.PyArray_DescrFromType_(type), which == kLinkAcc ? 2 : 1, dims,
                                nullptr, r->data + offsetOf(l, which), flags | writeable, nullptr);
  if (v == nullptr) return nullptr;
  Py_INCREF(o);
  if (api.PyArray_SetBaseObject_(v, o) != 0) Py_CLEAR(v);
  return v;
}

// Scalar `which` (closure): 0 rank, 1 smin, 2 gauss, 3 iterations (2 and 3: None without friction).
PyObject* getScalar(PyObject* o, void* closure) {
  const ResultObject* r = self(o);
  const intptr_t which = reinterpret_cast<intptr_t>(closure);
  if (which >= 2 && !r->layout.friction) Py_RETURN_NONE;
  if (which == 0 || which == 3) return PyLong_FromLong(which == 0 ? r->rank : r->iterations);
  return PyFloat_FromDouble(which == 1 ? r->smin : r->gauss);
}

// (keys, starts, counts) of segment_nu, or None (vereshchagin/_results.py assembles the dict).
PyObject* getSegments(PyObject* o, void*) {
  PyObject* const* s = self(o)->segments;
  if (s[0] == nullptr) Py_RETURN_NONE;
  return PyTuple_Pack(3, s[0], s[1], s[2]);
}

void* closure(intptr_t which) {
  return reinterpret_cast<void*>(which);
}

// Docstrings are set in bindResultType(); segment_nu and __repr__ are vereshchagin/_results.py's.
PyGetSetDef g_getset[] = {{"qdd", getView, nullptr, nullptr, closure(kQdd)},
                          {"tau_command", getView, nullptr, nullptr, closure(kTau)},
                          {"nu", getView, nullptr, nullptr, closure(kNu)},
                          {"link_acc", getView, nullptr, nullptr, closure(kLinkAcc)},
                          {"constraint_rank", getScalar, nullptr, nullptr, closure(0)},
                          {"smallest_singular_value", getScalar, nullptr, nullptr, closure(1)},
                          {"friction_torque", getView, nullptr, nullptr, closure(kFriction)},
                          {"limit_torque", getView, nullptr, nullptr, closure(kLimit)},
                          {"status", getView, nullptr, nullptr, closure(kStatus)},
                          {"gauss_value", getScalar, nullptr, nullptr, closure(2)},
                          {"iterations", getScalar, nullptr, nullptr, closure(3)},
                          {"_segment_layout", getSegments, nullptr, nullptr, nullptr},
                          {"_data", getView, nullptr, nullptr, closure(kData)},
                          {nullptr, nullptr, nullptr, nullptr, nullptr}};

// A result from the entries of a state that vereshchagin/_results.py checked; the sizes and the
// data length are checked again here, before anything is allocated.
py::object resultFromParts(const py::tuple& sizes, const py::tuple& scalars, const py::bytes& data,
                           const py::tuple& seg) {
  const ResultLayout l{sizes[0].cast<int>(), sizes[1].cast<int>(), sizes[2].cast<int>(), sizes[3].cast<bool>()};
  if (l.nj < 0 || l.ns < 0 || l.m < 0 || l.nj > (1 << 24) || l.ns > (1 << 24) || l.m > 6 * l.ns)
    raise("SolveResult state: sizes out of range");
  const std::string buf = data;
  if (buf.size() != sizeof(double) * static_cast<std::size_t>(bufferDoubles(l)))
    raise("SolveResult state: data of the wrong size");
  py::object o = py::reinterpret_steal<py::object>(allocate(l));
  ResultObject* r = self(o.ptr());
  std::memcpy(r->data, buf.data(), buf.size());
  setResultScalars(o.ptr(), scalars[0].cast<int>(), scalars[1].cast<double>(), scalars[2].cast<double>(),
                   scalars[3].cast<int>());
  if (!seg[0].is_none())
    setSegmentLayout(o.ptr(), seg[0].cast<py::tuple>(), seg[1].cast<py::tuple>(), seg[2].cast<py::tuple>());
  return o;
}

}  // namespace

void bindResultType(py::module_& mod) {
  for (PyGetSetDef* g = g_getset; g->name[0] != '_'; ++g) g->doc = doc(std::string("SolveResult.") + g->name);
  static PyType_Slot slots[] = {{Py_tp_dealloc, reinterpret_cast<void*>(dealloc)},
                                {Py_tp_getset, g_getset},
                                {Py_tp_doc, const_cast<char*>(doc("SolveResult"))},
                                {0, nullptr}};
  static PyType_Spec spec = {"vereshchagin._core.SolveResult", static_cast<int>(offsetof(ResultObject, data)),
                             static_cast<int>(sizeof(double)), Py_TPFLAGS_DEFAULT, slots};
  PyObject* type = PyType_FromSpec(&spec);
  if (type == nullptr) throw py::error_already_set();
  g_type = reinterpret_cast<PyTypeObject*>(type);
  mod.add_object("SolveResult", py::reinterpret_borrow<py::object>(type));
  mod.def("_result_from_parts", &resultFromParts, doc("_core._result_from_parts"));
}

py::object newResult(const ResultLayout& layout, PyObject* out) {
  if (out == nullptr) return py::reinterpret_steal<py::object>(allocate(layout));
  if (Py_TYPE(out) != g_type)
    throw SolverError("out must be a SolveResult returned by an earlier solve(), got " +
                      std::string(Py_TYPE(out)->tp_name));
  ResultObject* r = self(out);
  const ResultLayout& l = r->layout;
  const auto str = [](const ResultLayout& x) {
    return "n_joints = " + std::to_string(x.nj) + ", n_segments = " + std::to_string(x.ns) +
           ", m = " + std::to_string(x.m) + (x.friction ? " with" : " without") + " friction";
  };
  if (l.nj != layout.nj || l.ns != layout.ns || l.m != layout.m || l.friction != layout.friction)
    throw SolverError("out does not fit this solve: it holds " + str(l) + ", this solve has " + str(layout));
  clearSegments(r);
  return py::reinterpret_borrow<py::object>(out);
}

ResultPointers resultPointers(PyObject* o) {
  const ResultLayout& l = self(o)->layout;
  double* b = self(o)->data;
  const auto at = [&](int which) { return l.friction || which < kFriction ? b + offsetOf(l, which) : nullptr; };
  return {at(kQdd), at(kTau), at(kNu), at(kLinkAcc), at(kFriction), at(kLimit), reinterpret_cast<int*>(at(kStatus))};
}

void setResultScalars(PyObject* o, int rank, double smin, double gauss, int iterations) {
  ResultObject* r = self(o);
  r->rank = rank;
  r->smin = smin;
  r->gauss = gauss;
  r->iterations = iterations;
}

void setSegmentLayout(PyObject* o, py::tuple keys, py::tuple starts, py::tuple counts) {
  PyObject** s = self(o)->segments;
  s[0] = keys.release().ptr();
  s[1] = starts.release().ptr();
  s[2] = counts.release().ptr();
}

}  // namespace vsbind
