// The conversion vocabulary of the bindings: the exception type, the docstrings, and checked numpy
// conversions whose messages (array_arg.hpp's) name the offending argument. Float64 C-contiguous
// inputs are viewed in place (a type check and a few field reads through numpy's C API table that
// pybind11 already loads), anything else is converted once; outputs come from PyArray_NewFromDescr.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <stdexcept>
#include <string>

#include "vereshchagin/array_arg.hpp"
#include "vereshchagin/kinematics.hpp"  // poseFromArray
#include "vereshchagin/status.hpp"

namespace vsbind {

namespace py = pybind11;

struct SolverError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The docstring `key` ("Chain.fk", "_core.Solver.solve": the Python-visible dotted name) of
// vereshchagin/_docstrings.py, which documents the Python API once; only from the bind functions.
inline const char* doc(const std::string& key) {
  static PyObject* const docs =
      py::object(py::module_::import("vereshchagin._docstrings").attr("DOCS")).release().ptr();
  PyObject* text = PyDict_GetItemString(docs, key.c_str());  // borrowed
  if (text == nullptr) throw std::runtime_error("vereshchagin._docstrings has no entry '" + key + "'");
  const char* utf8 = PyUnicode_AsUTF8(text);
  if (utf8 == nullptr) throw py::error_already_set();
  return utf8;
}

[[noreturn]] inline void raise(const std::string& msg) {
  throw SolverError(msg);
}
// Raises the message of a library check ("" or a Status that is ok(): nothing to raise).
inline void check(const std::string& why) {
  if (!why.empty()) raise(why);
}
inline void check(const vereshchagin::Status& s) {
  if (!s) raise(s.message());
}
// An optional argument that was passed (not missing, not None).
inline bool given(PyObject* obj) {
  return obj != nullptr && obj != Py_None;
}

// The value of an integer argument (an int or anything with __index__; each caller refuses bool
// and other types with its own message) when it lies in [lo, hi], else std::nullopt: a value
// beyond the C range is out of range like any other. Raises the error of a failing __index__.
inline std::optional<long long> intWithin(PyObject* obj, long long lo, long long hi) {
  const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(obj));
  if (!index) throw py::error_already_set();
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow != 0 || v < lo || v > hi) return std::nullopt;
  return v;
}

inline std::string typeName(PyObject* obj) {
  return py::str(py::type::of(py::handle(obj)).attr("__name__"));
}

// A real scalar (Python int or float, numpy scalar, 0-d array); bool, str, bytes, None and
// anything without __float__ raise.
inline double scalarArg(const py::handle& obj, const char* name) {
  PyObject* o = obj.ptr();
  const bool refused = PyBool_Check(o) || PyUnicode_Check(o) || PyBytes_Check(o) || o == Py_None;
  const py::object f = py::reinterpret_steal<py::object>(refused ? nullptr : PyNumber_Float(o));
  if (!f) {
    PyErr_Clear();
    raise(std::string(name) + " must be a real number, got " + typeName(o));
  }
  return PyFloat_AsDouble(f.ptr());
}

// A read-only view of a real array argument (data, ndim, shape, size(), shapeString()). `data`
// points into numpy memory owned by the caller's object or by `keep` (a converted copy).
struct F64View : vereshchagin::ArrayArg {
  py::object keep;
};

// `obj` as numpy float64 with at most 3 dimensions. Native C-contiguous aligned float64 arrays are
// viewed in place; integer and floating arrays (and nested sequences of numbers) are converted;
// None, bool, complex, string, object and other dtypes raise naming `name` (a failed conversion
// with its Python error). Values are not checked here.
inline F64View asF64(PyObject* obj, const char* name) {
  namespace d = py::detail;
  const auto& api = d::npy_api::get();
  constexpr int need = d::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | d::npy_api::NPY_ARRAY_ALIGNED_;
  F64View v;
  const auto* arr = api.PyArray_Check_(obj) ? d::array_proxy(obj) : nullptr;
  const auto* descr = arr ? d::array_descriptor_proxy(arr->descr) : nullptr;
  if (!arr || arr->nd > 3 || (arr->flags & need) != need || descr->type_num != d::npy_api::NPY_DOUBLE_ ||
      descr->byteorder == '>') {
    if (obj == Py_None || PyBool_Check(obj)) raise(vereshchagin::notArrayMessage(name, obj == Py_None));
    // PyArray_FromAny keeps the error of a failed conversion (py::array::ensure clears it).
    const py::array any = py::reinterpret_steal<py::array>(api.PyArray_FromAny_(obj, nullptr, 0, 0, 0, nullptr));
    if (!any) {
      const py::error_already_set e;  // the conversion's own error (a NULL return sets one), cleared
      raise(vereshchagin::unconvertedMessage(name, typeName(obj),
                                             typeName(e.value().ptr()) + ": " + std::string(py::str(e.value()))));
    }
    // The dtype's text only for the message (str(dtype) costs about a microsecond).
    if (!vereshchagin::realDtype(any.dtype().kind(), any.ndim()))
      raise(vereshchagin::dtypeMessage(name, any.dtype().kind(), py::str(any.dtype()), any.ndim()));
    v.keep = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(any);  // a float64 copy
    if (!v.keep) {
      PyErr_Clear();
      raise(std::string(name) + " could not be converted to float64");
    }
    arr = d::array_proxy(v.keep.ptr());
  }
  v.data = reinterpret_cast<const double*>(arr->data);
  v.ndim = arr->nd;
  for (int k = 0; k < v.ndim; ++k) v.shape[k] = arr->dimensions[k];
  return v;
}

// A checked (n,) vector argument (a scalar is accepted for n == 1 when scalar_ok).
inline F64View vectorView(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok = false) {
  F64View v = asF64(obj, name);
  if (v.ndim == 0 && scalar_ok && n == 1) {
    v.ndim = 1;
    v.shape[0] = 1;
  }
  if (const std::string why = vereshchagin::vectorMessage(v, name, n); !why.empty()) raise(why);
  return v;
}

inline KDL::Vector vec3(const py::handle& obj, const char* name) {
  const F64View a = vectorView(obj.ptr(), name, 3);
  return KDL::Vector(a.data[0], a.data[1], a.data[2]);
}

// A finite 4x4 homogeneous transform with a proper rotation (vereshchagin::poseFromArray).
inline KDL::Frame frameFrom4x4(const py::handle& obj, const char* name) {
  KDL::Frame pose;
  if (const std::string why = vereshchagin::poseFromArray(asF64(obj.ptr(), name), name, pose); !why.empty()) raise(why);
  return pose;
}

// New arrays, uninitialised (int arrays hold numpy int32): C-contiguous, or with fortran = true
// column-major, so that an Eigen column-major matrix can be written in place.
inline py::array newArray(int type_num, int nd, const py::ssize_t* dims, bool fortran = false) {
  const auto& api = py::detail::npy_api::get();
  PyObject* descr = api.PyArray_DescrFromType_(type_num);
  PyObject* a = api.PyArray_NewFromDescr_(api.PyArray_Type_, descr, nd, dims, nullptr, nullptr, fortran, nullptr);
  if (a == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::array>(a);
}
inline py::array newDoubles(std::initializer_list<py::ssize_t> shape) {
  return newArray(py::detail::npy_api::NPY_DOUBLE_, static_cast<int>(shape.size()), shape.begin());
}
inline py::array newInts(std::initializer_list<py::ssize_t> shape) {
  return newArray(py::detail::npy_api::NPY_INT_, static_cast<int>(shape.size()), shape.begin());
}
inline double* doubles(const py::array& a) {
  return reinterpret_cast<double*>(py::detail::array_proxy(a.ptr())->data);
}
inline int* ints(const py::array& a) {
  return reinterpret_cast<int*>(py::detail::array_proxy(a.ptr())->data);
}

}  // namespace vsbind
