// vereshchagin.SolveResult: a small CPython type holding every numeric output of one solve in
// float64 storage allocated with the object. Its array fields are views of that storage made on
// access, so a solve allocates one object whatever the number of outputs, and `out=` reuses it.
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

// Registers the type on `mod` (as SolveResult) and _result_state / _result_from_parts, the
// storage side of pickling (vereshchagin/_results.py).
void bindResultType(py::module_& mod);

// A new result for `layout` (data uninitialised), or `out` after checking that it is a
// SolveResult of the same layout (raises SolverError otherwise). Returns a new reference.
py::object newResult(const ResultLayout& layout, PyObject* out);
ResultPointers resultPointers(PyObject* result);
// Scalars and the segment_nu layout: keys[k] owns nu[start_k:start_k + count_k].
void setResultScalars(PyObject* result, int rank, double smin, double gauss, int iterations);
void setSegmentLayout(PyObject* result, py::tuple keys, py::tuple starts, py::tuple counts);

}  // namespace vsbind
