// task.py's fast path: _core._beta_for (beta_for's arithmetic and shapes, task.hpp's betaShape and
// betaFromArrays, also for (N, 6) twists). It returns None for inputs that are not plainly valid:
// task.py then checks them and raises its own messages.
#include <optional>

#include "common.hpp"
#include "vereshchagin/task.hpp"

namespace vsbind {

namespace {

// A float64 view of a real array, or nullopt (what asF64 refuses).
std::optional<F64View> realView(const py::handle& obj) {
  try {
    return asF64(obj.ptr(), "");
  } catch (const SolverError&) {
    return std::nullopt;
  }
}

// alpha (6,) or (6, m), a_desired (6,) or one row per twist, twist (6,) or (N, 6), gravity (3,):
// beta (m,) or (N, m) rows.
py::object betaFor(const py::handle& alpha, const py::handle& a_desired, const py::handle& twist,
                   const py::handle& gravity) {
  const auto A = realView(alpha), a = realView(a_desired), t = realView(twist), g = realView(gravity);
  int ndim = 0;
  py::ssize_t shape[2];
  if (!A || !a || !t || !g || !vereshchagin::betaShape(*A, *a, *t, *g, ndim, shape)) return py::none();
  py::array out = newArray(py::detail::npy_api::NPY_DOUBLE_, ndim, shape);
  if (!vereshchagin::betaFromArrays(*A, *a, *t, *g, doubles(out)))
    raise("beta_for: the result overflows the double range (inputs too large)");
  return std::move(out);
}

}  // namespace

void bindTaskHelpers(py::module_& mod) {
  mod.def("_beta_for", &betaFor, py::arg("alpha"), py::arg("a_desired"), py::arg("twist"), py::arg("gravity"),
          doc("_core._beta_for"));
}

}  // namespace vsbind
