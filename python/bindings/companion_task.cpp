// task.py's fast path: _core._beta_for (beta_for's arithmetic, task.hpp, also for (N, 6) twists).
// It returns None for inputs that are not plainly valid: task.py then checks them and raises its
// own messages.
#include <optional>

#include "model_class.hpp"
#include "numpy_fast.hpp"
#include "vereshchagin/task.hpp"

namespace vsbind {

namespace {

// A finite float64 view of a real array, or nullopt (what asF64 refuses, NaN or Inf).
std::optional<F64View> realView(const py::handle& obj) {
  try {
    F64View v = asF64(obj.ptr(), "");
    if (Eigen::Map<const Eigen::ArrayXd>(v.data, v.size()).allFinite()) return v;
  } catch (const SolverError&) {
  }
  return std::nullopt;
}

// alpha (6,) or (6, m), a_desired (6,) or one row per twist, twist (6,) or (N, 6), gravity (3,):
// beta (m,) or (N, m) rows.
py::object betaFor(const py::handle& alpha, const py::handle& a_desired, const py::handle& twist,
                   const py::handle& gravity) {
  const auto A = realView(alpha), a = realView(a_desired), t = realView(twist), g = realView(gravity);
  if (!A || !a || !t || !g || g->size() != 3 || A->shape[0] != 6 || (A->ndim != 1 && A->ndim != 2)) return py::none();
  const py::ssize_t m = A->ndim == 1 ? 1 : A->shape[1];
  const bool batched = t->ndim == 2 && t->shape[1] == 6 && t->size() != 6;
  const py::ssize_t rows = batched ? t->shape[0] : 1;
  const bool a_rows = a->size() != 6;
  if ((!batched && t->size() != 6) || (a_rows && !(batched && a->ndim == 2 && a->shape[0] == rows && a->shape[1] == 6)))
    return py::none();
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> alfa(A->data, 6, m);
  const KDL::Vector grav(g->data[0], g->data[1], g->data[2]);
  py::array out = batched ? newDoubles({rows, m}) : newDoubles({m});
  for (py::ssize_t r = 0; r < rows; ++r) {
    const vereshchagin::Vector6 acc = Eigen::Map<const vereshchagin::Vector6>(a->data + (a_rows ? 6 * r : 0));
    const vereshchagin::Vector6 tw = Eigen::Map<const vereshchagin::Vector6>(t->data + 6 * r);
    Eigen::Map<Eigen::VectorXd>(doubles(out) + m * r, m).noalias() =
        alfa.transpose() * vereshchagin::spatialFromClassical(acc, tw, grav);
  }
  if (!Eigen::Map<const Eigen::ArrayXd>(doubles(out), out.size()).allFinite())
    raise("beta_for: the result overflows the double range (inputs too large)");
  return std::move(out);
}

}  // namespace

void bindTaskHelpers(py::module_& mod) {
  mod.def("_beta_for", &betaFor, py::arg("alpha"), py::arg("a_desired"), py::arg("twist"), py::arg("gravity"),
          doc("_core._beta_for"));
}

}  // namespace vsbind
