// vereshchagin.SolveResult: a small CPython type holding every numeric output of one solve in
// float64 storage allocated with the object. Its array fields are views of that storage made on
// access, so a solve allocates one object whatever the number of outputs, and `out=` reuses it.
#pragma once

#include <pybind11/pybind11.h>

#include "vereshchagin/batch.hpp"

namespace vsbind {

namespace py = pybind11;

// A new result for `layout` (data uninitialised), or `out` after checking that it is a
// SolveResult of the same layout (raises SolverError otherwise). Returns a new reference.
py::object newResult(const vereshchagin::PackedRow& layout, PyObject* out);
// Where solve() writes its outputs into `result` (row 0; the friction ones nullptr without friction).
vereshchagin::BatchOutput resultOutput(PyObject* result);
// Sets segment_nu's layout, a (key, start, count) tuple per key (keys[k] owns nu[start:start + count]).
void setSegmentLayout(PyObject* result, py::tuple layout);

}  // namespace vsbind
