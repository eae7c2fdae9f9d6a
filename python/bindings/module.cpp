// pybind11 module vereshchagin._core: the C++ library's Python face. Shapes and values are checked
// in the bindings (messages name the argument); the C++ solver checks again and its error codes
// become vereshchagin.SolverError (a ValueError).
#include <pybind11/pybind11.h>

#include "common.hpp"

namespace vsbind {
void bindChain(py::module_& mod);
void bindTree(py::module_& mod);
void bindSolver(py::module_& mod);
void bindResultType(py::module_& mod);
void bindDynamics(py::module_& mod);
void bindSegmentSpec(py::module_& mod);
}  // namespace vsbind

PYBIND11_MODULE(_core, mod) {
  mod.doc() = "C++ core of vereshchagin (Popov-Vereshchagin hybrid dynamics on KDL chains).";
  pybind11::register_exception<vsbind::SolverError>(mod, "SolverError", PyExc_ValueError);
  vsbind::bindChain(mod);
  vsbind::bindTree(mod);
  vsbind::bindResultType(mod);
  vsbind::bindDynamics(mod);     // adds methods to Chain
  vsbind::bindSegmentSpec(mod);  // adds Chain.segment_spec
  vsbind::bindSolver(mod);
}
