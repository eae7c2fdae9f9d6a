// wholeBodyArrays() (whole_body.hpp): the Python face's call, one list of arrays unpacked into a
// SolveInput and a WholeBodySolver's call, its results or its status returned as a tuple.
#include <cmath>

#include "vereshchagin/whole_body.hpp"

namespace vereshchagin {

namespace {

using Tuple = std::tuple<int, std::string, Eigen::VectorXd, Eigen::MatrixXd, Eigen::VectorXd, double, double>;

Tuple failure(Error code, const std::string& message) {
  return Tuple(static_cast<int>(code), message, Eigen::VectorXd(), Eigen::MatrixXd(), Eigen::VectorXd(), 0.0, 0.0);
}

bool shaped(const Eigen::MatrixXd& a, long rows, long cols) {
  return a.rows() == rows && a.cols() == cols && a.allFinite();
}

}  // namespace

Tuple wholeBodyArrays(const Model& model, const std::vector<Eigen::MatrixXd>& a) {
  const long nq = model.nq(), nv = model.nv(), nj = model.nrOfJoints(), ns = model.nrOfSegments();
  if (a.size() < 8 || !shaped(a[0], nq, 1) || !shaped(a[1], nv, 1) || !shaped(a[2], 6, ns) || !shaped(a[3], nv, 1) ||
      !shaped(a[4], 3, 1) || a[5].cols() != 1 || a[6].cols() != 9 || a[7].cols() != 4 ||
      static_cast<long>(a.size()) != 8 + 2 * a[7].rows())
    return failure(Error::SizeMismatch, "whole body: arrays of the wrong shape or not finite");
  SolveInput in(model, static_cast<int>(a[7].rows()), 0);
  in.setState(JointPositions(a[0].col(0)), JointVelocities(a[1].col(0)));
  in.f_ext = a[2];
  in.ff_torques = a[3].col(0);
  in.gravity = KDL::Vector(a[4](0), a[4](1), a[4](2));
  for (long c = 0; c < a[6].rows(); ++c) {
    PointContact pc;
    pc.segment = static_cast<int>(a[6](c, 0));
    pc.point = a[6].block<1, 3>(c, 1).transpose();
    pc.normal = a[6].block<1, 3>(c, 4).transpose();
    pc.mu = a[6](c, 7);
    pc.facets = static_cast<int>(a[6](c, 8));
    in.contacts.push_back(pc);
  }
  int rows = 0;
  for (long b = 0; b < a[7].rows(); ++b) {
    const Eigen::MatrixXd &alfa = a[8 + 2 * b], &beta = a[9 + 2 * b];
    if (alfa.rows() != 6 || alfa.cols() > 6 || !shaped(beta, alfa.cols(), 1) || !alfa.allFinite())
      return failure(Error::SizeMismatch,
                     "whole body: task block " + std::to_string(b) + ": alpha not 6 x m or beta not m");
    ConstraintBlock blk;
    blk.segment = static_cast<int>(a[7](b, 0));
    blk.point = a[7].block<1, 3>(b, 1).transpose();
    blk.columns = static_cast<int>(alfa.cols());
    blk.alfa.leftCols(blk.columns) = alfa;
    blk.beta.head(blk.columns) = beta.col(0);
    in.constraints.push_back(blk);
    rows += blk.columns;
  }
  WholeBodyOptions options;
  options.max_contacts = static_cast<int>(a[6].rows());
  options.max_task_rows = rows;
  WholeBodySolver solver(model, options);
  Eigen::VectorXi actuated(a[5].rows());
  for (long j = 0; j < actuated.size(); ++j) actuated(j) = a[5](j, 0) != 0.0 ? 1 : 0;
  (void)nj;
  WholeBodyResult r;
  const Status st = solver.solve(in, actuated, r);
  if (!st) return failure(st.code(), st.message());
  return Tuple(0, std::string(), r.tau, Eigen::MatrixXd(r.forces), r.qdd, r.effort, r.residual);
}

}  // namespace vereshchagin
