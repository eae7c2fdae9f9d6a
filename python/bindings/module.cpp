// pybind11 module vereshchagin._core: the C++ library's Python face. Shapes and values are checked
// in the bindings (messages name the argument); the C++ solver checks again and its error codes
// become vereshchagin.SolverError (a ValueError).
#include <pybind11/pybind11.h>

#include "common.hpp"

namespace vsbind {
void bindChain(py::module_& mod);  // model_chain.cpp: Joint and Chain
void bindTree(py::module_& mod);   // model_bindings.cpp
void bindSolver(py::module_& mod);
void bindResultType(py::module_& mod);
void bindDynamics(py::module_& mod);

namespace {
PyObject* g_docs = nullptr;  // vereshchagin._docstrings.DOCS, referenced for the interpreter's lifetime
}  // namespace

const char* doc(const char* key) {
  PyObject* text = PyDict_GetItemString(g_docs, key);  // borrowed
  if (text == nullptr) throw std::runtime_error(std::string("vereshchagin._docstrings has no entry '") + key + "'");
  const char* utf8 = PyUnicode_AsUTF8(text);
  if (utf8 == nullptr) throw py::error_already_set();
  return utf8;
}

}  // namespace vsbind

PYBIND11_MODULE(_core, mod) {
  vsbind::g_docs = pybind11::object(pybind11::module_::import("vereshchagin._docstrings").attr("DOCS")).release().ptr();
  mod.doc() = vsbind::doc("_core");
  pybind11::register_exception<vsbind::SolverError>(mod, "SolverError", PyExc_ValueError);
  vsbind::bindChain(mod);
  vsbind::bindTree(mod);
  vsbind::bindResultType(mod);
  vsbind::bindDynamics(mod);  // adds the companions to Chain and Tree
  vsbind::bindSolver(mod);
}
