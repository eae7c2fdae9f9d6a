// vereshchagin.SolveResult: storage, views and the solve path's fast access (declared in py_solver.hpp).
// Pickling, copies, segment_nu and repr are Python code over this storage (vereshchagin/_results.py).
#include <cstring>
#include <string>
#include <string_view>
#include <tuple>

#include "py_solver.hpp"

namespace vsbind {

namespace {

using Row = vereshchagin::PackedRow;

// Every numeric output lives in `data` (allocated with the object: one allocation per solve), laid
// out as a PackedRow. Array fields are views of it whose base is the result; they are not cached (a
// cache would be a reference cycle), so each attribute access makes a new view of the same memory.
struct ResultObject {
  PyObject_VAR_HEAD PyObject* segments;  // segment_nu's layout: a (key, start, count) tuple per key, or NULL
  Row layout;
  int rank, iterations, contact_outcome;
  double smin, gauss;
  double data[1];  // layout.offset(Row::End) entries
};

PyTypeObject* g_type = nullptr;

ResultObject* self(PyObject* o) {
  return reinterpret_cast<ResultObject*>(o);
}

void dealloc(PyObject* o) {
  Py_CLEAR(self(o)->segments);
  PyTypeObject* tp = Py_TYPE(o);
  tp->tp_free(o);
  Py_DECREF(tp);
}

PyObject* allocate(const Row& layout) {
  ResultObject* r = PyObject_NewVar(ResultObject, g_type, layout.offset(Row::End));
  if (r == nullptr) throw py::error_already_set();
  r->segments = nullptr;
  r->layout = layout;
  r->rank = r->iterations = r->contact_outcome = 0;
  r->smin = r->gauss = 0.0;
  return reinterpret_cast<PyObject*>(r);
}

// Field `which` (closure) as a view into the result's data whose base is the result (Row::End: all
// of it as doubles, read-only: the pickle state's bytes, vereshchagin/_results.py).
PyObject* getView(PyObject* o, void* closure) {
  ResultObject* r = self(o);
  const auto which = static_cast<Row::Field>(reinterpret_cast<intptr_t>(closure));
  const Row& l = r->layout;
  if (which >= Row::FrictionTorque && which <= Row::Status && !l.friction) Py_RETURN_NONE;
  const bool contact = which == Row::ContactForce || which == Row::ContactStatus;
  const Py_ssize_t n = which == Row::Nu    ? l.m
                       : which == Row::End ? l.offset(Row::End)
                       : contact           ? l.contacts
                                           : l.n_joints;
  const bool matrix = which == Row::LinkAcc || which == Row::ContactForce;  // (rows, 6) and (contacts, 3)
  const Py_ssize_t dims[2] = {which == Row::LinkAcc ? l.n_segments + 1 : n, which == Row::LinkAcc ? 6 : 3};
  const auto& api = py::detail::npy_api::get();
  constexpr int flags = py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_ALIGNED_;
  const int writeable = which == Row::End ? 0 : py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  const bool ints = which == Row::Status || which == Row::ContactStatus;
  const int type = ints ? py::detail::npy_api::NPY_INT_ : py::detail::npy_api::NPY_DOUBLE_;
  PyObject* v =
      api.PyArray_NewFromDescr_(api.PyArray_Type_, api.PyArray_DescrFromType_(type), matrix ? 2 : 1, dims, nullptr,
                                r->data + (which == Row::End ? 0 : l.offset(which)), flags | writeable, nullptr);
  if (v == nullptr) return nullptr;
  Py_INCREF(o);
  if (api.PyArray_SetBaseObject_(v, o) != 0) Py_CLEAR(v);
  return v;
}

// Scalar `which` (closure): 0 rank, 1 smin, 2 gauss, 3 iterations (2 and 3: None without friction),
// 4 the (key, start, count) triples of segment_nu or None (vereshchagin/_results.py makes the dict),
// 5 the ContactOutcome code.
PyObject* getScalar(PyObject* o, void* closure) {
  const ResultObject* r = self(o);
  const intptr_t which = reinterpret_cast<intptr_t>(closure);
  if (which == 4) return py::handle(r->segments ? r->segments : Py_None).inc_ref().ptr();
  if (which == 5) return PyLong_FromLong(r->contact_outcome);
  if (which >= 2 && !r->layout.friction) Py_RETURN_NONE;
  if (which == 0 || which == 3) return PyLong_FromLong(which == 0 ? r->rank : r->iterations);
  return PyFloat_FromDouble(which == 1 ? r->smin : r->gauss);
}

void* closure(intptr_t which) {
  return reinterpret_cast<void*>(which);
}

// Docstrings are set in bindResultType(); segment_nu and __repr__ are vereshchagin/_results.py's.
PyGetSetDef g_getset[] = {{"qdd", getView, nullptr, nullptr, closure(Row::Qdd)},
                          {"tau_command", getView, nullptr, nullptr, closure(Row::TauCommand)},
                          {"nu", getView, nullptr, nullptr, closure(Row::Nu)},
                          {"link_acc", getView, nullptr, nullptr, closure(Row::LinkAcc)},
                          {"constraint_rank", getScalar, nullptr, nullptr, closure(0)},
                          {"smallest_singular_value", getScalar, nullptr, nullptr, closure(1)},
                          {"friction_torque", getView, nullptr, nullptr, closure(Row::FrictionTorque)},
                          {"limit_torque", getView, nullptr, nullptr, closure(Row::LimitTorque)},
                          {"status", getView, nullptr, nullptr, closure(Row::Status)},
                          {"gauss_value", getScalar, nullptr, nullptr, closure(2)},
                          {"iterations", getScalar, nullptr, nullptr, closure(3)},
                          {"contact_force", getView, nullptr, nullptr, closure(Row::ContactForce)},
                          {"contact_status", getView, nullptr, nullptr, closure(Row::ContactStatus)},
                          {"_segment_layout", getScalar, nullptr, nullptr, closure(4)},
                          {"_contact_outcome", getScalar, nullptr, nullptr, closure(5)},
                          {"_data", getView, nullptr, nullptr, closure(Row::End)},
                          {nullptr, nullptr, nullptr, nullptr, nullptr}};

// A result from the entries of a state that vereshchagin/_results.py checked; the sizes and the
// data length are checked again here, before anything is allocated.
py::object resultFromParts(std::tuple<long, long, long, bool, long> sizes,
                           std::tuple<int, double, double, int, int> scalars, const py::bytes& data,
                           const py::object& layout) {
  const Row l = std::apply([](auto... size) { return Row{size...}; }, sizes);
  if (!l.plausible()) raise("SolveResult state: sizes out of range");
  const std::string_view buf = data;
  if (buf.size() != sizeof(double) * static_cast<std::size_t>(l.offset(Row::End)))
    raise("SolveResult state: data of the wrong size");
  py::object o = py::reinterpret_steal<py::object>(allocate(l));
  ResultObject* r = self(o.ptr());
  std::memcpy(r->data, buf.data(), buf.size());
  std::tie(r->rank, r->smin, r->gauss, r->iterations, r->contact_outcome) = scalars;
  if (!layout.is_none()) setSegmentLayout(o.ptr(), layout.cast<py::tuple>());
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

py::object newResult(const vereshchagin::PackedRow& layout, PyObject* out) {
  if (out == nullptr) return py::reinterpret_steal<py::object>(allocate(layout));
  if (Py_TYPE(out) != g_type)
    throw SolverError("out must be a SolveResult returned by an earlier solve(), got " +
                      std::string(Py_TYPE(out)->tp_name));
  ResultObject* r = self(out);
  if (!(r->layout == layout))
    throw SolverError("out does not fit this solve: it holds " + r->layout.describe() + ", this solve has " +
                      layout.describe());
  Py_CLEAR(r->segments);
  return py::reinterpret_borrow<py::object>(out);
}

vereshchagin::BatchOutput resultOutput(PyObject* o) {
  ResultObject* r = self(o);
  r->contact_outcome = 0;  // written by a solve with contacts
  return r->layout.output(r->data, &r->smin, &r->rank, &r->gauss, &r->iterations, &r->contact_outcome);
}

void setSegmentLayout(PyObject* o, py::tuple layout) {
  self(o)->segments = layout.release().ptr();
}

}  // namespace vsbind
