// Shared helpers of the Python bindings: the exception type and checked numpy conversions that
// name the offending argument in their messages.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

namespace vsbind {

namespace py = pybind11;

struct SolverError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The docstring `key` of vereshchagin/_docstrings.py, where the Python API is documented once
// (module.cpp); `key` is the Python-visible dotted name ("Chain.fk", "_core.Solver.solve"). Only
// from the bind functions (DOCS is imported when module initialisation starts), never from a
// namespace-scope initialiser. The text stays alive for the interpreter's lifetime.
const char* doc(const char* key);
inline const char* doc(const std::string& key) {
  return doc(key.c_str());
}

[[noreturn]] inline void raise(const std::string& msg) {
  throw SolverError(msg);
}

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

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

inline std::string shapeStr(const py::array& a) {
  std::ostringstream s;
  s << "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s << (k ? ", " : "") << a.shape(k);
  if (a.ndim() == 1) s << ",";
  s << ")";
  return s.str();
}

// A float64 C-contiguous array of a real argument: int and float dtypes (and nested sequences of
// numbers) are converted; bool, complex, string and object values raise naming `name`.
inline Array toArray(const py::handle& obj, const char* name) {
  if (PyBool_Check(obj.ptr())) raise(std::string(name) + " must be a real number or array, got bool");
  if (obj.is_none()) raise(std::string(name) + " must be a real array, got None");
  py::array any = py::array::ensure(obj);
  if (!any) {
    PyErr_Clear();
    raise(std::string(name) + " must be a numeric array-like of floats");
  }
  const char kind = any.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    raise(std::string(name) + " must hold real numbers (int or float), got dtype " + std::string(py::str(any.dtype())));
  Array a = Array::ensure(any);
  if (!a) {
    PyErr_Clear();
    raise(std::string(name) + " could not be converted to float64");
  }
  return a;
}

inline std::string fmtDouble(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// A real scalar (Python int or float, numpy scalar, 0-d array); bool and everything else raise.
inline double scalarArg(const py::handle& obj, const char* name) {
  if (py::isinstance<py::bool_>(obj) || py::isinstance<py::str>(obj) || py::isinstance<py::bytes>(obj) || obj.is_none())
    raise(std::string(name) + " must be a real number, got " +
          std::string(py::str(py::type::of(obj).attr("__name__"))));
  PyObject* f = PyNumber_Float(obj.ptr());
  if (f == nullptr) {
    PyErr_Clear();
    raise(std::string(name) + " must be a real number, got " +
          std::string(py::str(py::type::of(obj).attr("__name__"))));
  }
  const double v = PyFloat_AsDouble(f);
  Py_DECREF(f);
  return v;
}

inline void requireFinite(const Array& a, const char* name) {
  const double* p = a.data();
  for (py::ssize_t k = 0; k < a.size(); ++k) {
    if (!std::isfinite(p[k])) {
      raise(std::string(name) + " contains NaN or Inf (flat index " + std::to_string(k) + ")");
    }
  }
}

inline Array vectorArg(const py::handle& obj, const char* name, py::ssize_t n) {
  Array a = toArray(obj, name);
  if (a.ndim() != 1 || a.shape(0) != n) {
    raise(std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + shapeStr(a));
  }
  requireFinite(a, name);
  return a;
}

// A finite vector of shape (n,) as joint values.
inline KDL::JntArray jntArrayArg(const py::handle& obj, const char* name, unsigned int n) {
  const Array a = vectorArg(obj, name, n);
  KDL::JntArray out(n);
  for (unsigned int k = 0; k < n; ++k) out(k) = a.at(k);
  return out;
}

inline KDL::Frame frameFrom4x4(const py::handle& obj, const char* name) {
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
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-9 || R.determinant() < 0.0) {
    raise(std::string(name) + ": the upper-left 3x3 block must be a rotation matrix (orthonormal, det +1)");
  }
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
                    KDL::Vector(t(0, 3), t(1, 3), t(2, 3)));
}

inline KDL::Vector vec3(const py::handle& obj, const char* name) {
  Array a = vectorArg(obj, name, 3);
  return KDL::Vector(a.at(0), a.at(1), a.at(2));
}

inline py::array_t<double> copyVector(const double* p, py::ssize_t n) {
  py::array_t<double> a(n);
  std::copy(p, p + n, a.mutable_data());
  return a;
}

// A KDL frame as a row-major 4x4 homogeneous transform written to out[0..15].
inline void writeHomogeneous(const KDL::Frame& f, double* out) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = r < 3 ? (c < 3 ? f.M(r, c) : f.p(r)) : (c == 3 ? 1.0 : 0.0);
}

inline py::array_t<double> homogeneous(const KDL::Frame& f) {
  py::array_t<double> T({4, 4});
  writeHomogeneous(f, T.mutable_data());
  return T;
}

}  // namespace vsbind
