// The workspace of WholeBodySolver (whole_body.hpp), shared by its translation units:
// whole_body.cpp (checks and the call's order), whole_body_rows.cpp (the affine map from the
// unknowns to the conditions), whole_body_qp.cpp (the equalities eliminated, the least-effort
// programme, the certificate).
#pragma once

#include <cstdio>

#include <Eigen/Core>
#include <Eigen/QR>

#include "lemke.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/whole_body.hpp"

namespace vereshchagin {

struct WholeBodySolver::Impl {
  Impl(const Model& model, const WholeBodyOptions& options);

  // whole_body_rows.cpp: R (nv x p) from the free solve, then E (m x p) and e (m).
  Status columns(const SolveInput& input);
  void rows(const SolveInput& input);
  void comRows(const SolveInput& input, const ConstraintBlock& block, int& row);
  // whole_body_qp.cpp: x (p) from E x = e, the cones and the objective; false with message_ set.
  bool eliminate();
  bool program(const SolveInput& input);
  void coneRows(const SolveInput& input);
  Status fail(Error code, const char* format, ...);

  const Model* model;
  WholeBodyOptions options;
  Data data;
  SolveInput free;  // the input without task and supports: qdd0 and the response columns
  int nv = 0, nj = 0, nb = 0;
  double mass = 0.0;  // the robot's total mass (a free-flyer's: centre-of-mass tasks), kg
  int na = 0, k = 0, mt = 0, p = 0, m = 0, rank = 0, cone_rows = 0;
  Eigen::VectorXi joints;   // the actuated joints (na)
  Eigen::MatrixXd R, dtau;  // nv x p: qdd per unknown; scratch for responseColumns
  Eigen::VectorXi segs;     // 3 k: each force column's segment
  Matrix6X W;               // 6 x 3 k: each force column's wrench about its segment's tip
  Eigen::MatrixXd J6, JR;   // 6 x nv frame Jacobian, 6 x p its product with R
  Eigen::MatrixXd E;        // m x p
  Eigen::VectorXd e, qdd0;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr;
  Eigen::MatrixXd Q, D, C, G;  // Q: p x p; D: cone rows x 3 k; C, G: the programme's in w
  Eigen::VectorXd xp, x, w, t, pv, g, work, y;
  Eigen::MatrixXd P;
  detail::LexicographicQp lqp;
  int lqp_p = 0, lqp_k = 0;  // the programme's reserved sizes
  double residual = 0.0;
  char message[256] = "";
};

}  // namespace vereshchagin
