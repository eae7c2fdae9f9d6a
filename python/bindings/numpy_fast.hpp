// Cheap numpy conversions for the solve path: float64 inputs viewed in place (one type check and
// a few field reads through numpy's C API table that pybind11 already loads), everything else
// converted once with a dtype check, and outputs allocated directly by PyArray_NewFromDescr.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "common.hpp"

namespace vsbind {

// Clears the pending Python error and returns " (its conversion raised Type: message)", so that a
// message about a failed conversion keeps the reason (e.g. an __array__ that raised).
inline std::string pendingErrorNote() {
  if (!PyErr_Occurred()) return "";
  py::error_already_set e;  // fetches and clears it
  const std::string type = py::str(e.type().attr("__name__"));
  return " (its conversion raised " + type + ": " + std::string(py::str(e.value())) + ")";
}

// A read-only view of a real array argument. `data` points into numpy memory owned by the
// caller's object or by `keep` (a converted copy); valid while both live.
struct F64View {
  const double* data = nullptr;
  int ndim = 0;
  py::ssize_t shape[3] = {0, 0, 0};
  py::object keep;
  bool given() const { return data != nullptr || ndim > 0 || shape[0] > 0; }
  py::ssize_t size() const {
    py::ssize_t s = 1;
    for (int k = 0; k < ndim; ++k) s *= shape[k];
    return s;
  }
  std::string shapeString() const {
    std::string s = "(";
    for (int k = 0; k < ndim; ++k) s += (k ? ", " : "") + std::to_string(shape[k]);
    return s + (ndim == 1 ? ",)" : ")");
  }
};

namespace detail_np {

inline bool nativeContiguousF64(PyObject* obj) {
  const auto& api = py::detail::npy_api::get();
  if (!api.PyArray_Check_(obj)) return false;
  const auto* arr = py::detail::array_proxy(obj);
  const auto* descr = py::detail::array_descriptor_proxy(arr->descr);
  constexpr int need = py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_ALIGNED_;
  return descr->type_num == py::detail::npy_api::NPY_DOUBLE_ && descr->byteorder != '>' &&
         (arr->flags & need) == need && arr->nd <= 3;
}

inline void fill(PyObject* obj, F64View& v) {
  const auto* arr = py::detail::array_proxy(obj);
  v.data = reinterpret_cast<const double*>(arr->data);
  v.ndim = arr->nd;
  for (int k = 0; k < arr->nd; ++k) v.shape[k] = arr->dimensions[k];
}

}  // namespace detail_np

// Views `obj` as float64. Integer and floating arrays (and nested sequences of numbers) are
// accepted; bool, complex, string, object and other dtypes raise naming `name`. Values are not
// checked here (see requireFiniteView).
inline F64View asF64(PyObject* obj, const char* name) {
  F64View v;
  if (detail_np::nativeContiguousF64(obj)) {
    detail_np::fill(obj, v);
    return v;
  }
  if (obj == Py_None) raise(std::string(name) + " must be a real array, got None");
  if (PyBool_Check(obj)) raise(std::string(name) + " must be a real number or array, got bool");
  // PyArray_FromAny keeps the error of a failed conversion (py::array::ensure clears it).
  py::array any =
      py::reinterpret_steal<py::array>(py::detail::npy_api::get().PyArray_FromAny_(obj, nullptr, 0, 0, 0, nullptr));
  if (!any)
    raise(std::string(name) + " must be a real array (numbers of equal-length rows), got " +
          std::string(py::str(py::type::of(py::handle(obj)).attr("__name__"))) + pendingErrorNote());
  const char kind = any.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    raise(std::string(name) + " must hold real numbers (int or float), got dtype " + std::string(py::str(any.dtype())));
  if (any.ndim() > 3)
    raise(std::string(name) + " has " + std::to_string(any.ndim()) + " dimensions; at most 3 are meaningful");
  v.keep = Array::ensure(any);  // float64, C-contiguous copy
  if (!v.keep) {
    PyErr_Clear();
    raise(std::string(name) + " could not be converted to float64");
  }
  detail_np::fill(v.keep.ptr(), v);
  return v;
}

inline void requireFiniteView(const F64View& v, const char* name) {
  const py::ssize_t n = v.size();
  for (py::ssize_t k = 0; k < n; ++k)
    if (!std::isfinite(v.data[k]))
      raise(std::string(name) + " contains NaN or Inf (flat index " + std::to_string(k) + ")");
}

// A checked (n,) vector argument (a scalar is accepted for n == 1 when scalar_ok).
inline F64View vectorView(PyObject* obj, const char* name, py::ssize_t n, bool scalar_ok = false) {
  F64View v = asF64(obj, name);
  if (v.ndim == 0 && scalar_ok && n == 1) {
    v.ndim = 1;
    v.shape[0] = 1;
  }
  if (v.ndim != 1 || v.shape[0] != n)
    raise(std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + v.shapeString());
  requireFiniteView(v, name);
  return v;
}

// New C-contiguous arrays, uninitialised (int arrays hold numpy int32).
// (fortran: column-major, so that an Eigen column-major matrix can be written in place).
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
