// pybind11 module vereshchagin._core: the C++ library's Python face. Shapes and values are checked
// in the bindings (messages name the argument); the C++ solver checks again and its error codes
// become vereshchagin.SolverError (a ValueError). Docstrings: vereshchagin/_docstrings.py (doc()).
#include "common.hpp"

namespace vsbind {
void bindChain(py::module_& mod);       // model_chain.cpp: Joint and Chain
void bindTree(py::module_& mod);        // model_bindings.cpp
void bindSolver(py::module_& mod);      // solver_bindings.cpp
void bindResultType(py::module_& mod);  // result_type.cpp: SolveResult and _result_from_parts (pickling)
void bindDynamics(py::module_& mod);    // companions.cpp: the companions of Chain and Tree, _beta_for
}  // namespace vsbind

PYBIND11_MODULE(_core, mod) {
  mod.doc() = vsbind::doc("_core");
  pybind11::register_exception<vsbind::SolverError>(mod, "SolverError", PyExc_ValueError);
  vsbind::bindChain(mod);
  vsbind::bindTree(mod);
  vsbind::bindResultType(mod);
  vsbind::bindDynamics(mod);
  vsbind::bindSolver(mod);
}
