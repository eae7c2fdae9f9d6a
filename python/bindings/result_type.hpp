// vereshchagin.SolveResult: a small CPython type holding every numeric output of one solve in one
// float64 buffer. Its array fields are views of that buffer, made on first access and cached, so
// a solve allocates two objects (result and buffer) whatever the number of outputs, and
// `out=` reuses both.
#pragma once

#include <pybind11/pybind11.h>

namespace vsbind {

namespace py = pybind11;

struct ResultLayout {
  int nj = 0, ns = 0, m = 0;
  bool friction = false;
};

// Where each output lives in the buffer (offsets in doubles).
struct ResultPointers {
  double *qdd, *tau_command, *nu, *link_acc, *friction_torque, *limit_torque;
  int* status;
};

// Registers the type on `mod` (as SolveResult) and _result_from_state for unpickling.
void bindResultType(py::module_& mod);

// A new result for `layout` (buffer uninitialised), or `out` after checking that it is a
// SolveResult of the same layout (raises SolverError otherwise). Returns a new reference.
py::object newResult(const ResultLayout& layout, PyObject* out);
ResultPointers resultPointers(PyObject* result);
// Scalars and the segment_nu layout: keys[k] owns nu[start_k:start_k + count_k].
void setResultScalars(PyObject* result, int rank, double smin, double gauss, int iterations);
void setSegmentLayout(PyObject* result, py::tuple keys, py::tuple starts, py::tuple counts);

}  // namespace vsbind
