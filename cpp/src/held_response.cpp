// Data::responseColumnsHoldingSticking (data.hpp): the affine response with the sticking joints of
// the last friction solve held, from the response columns of the requested and the held joints.
#include <algorithm>

#include <Eigen/QR>  // CompleteOrthogonalDecomposition

#include "vereshchagin/data.hpp"

#include "contact_stage.hpp"
#include "data_impl.hpp"

namespace vereshchagin {

Status Data::responseColumnsHoldingSticking(const Eigen::Ref<const Eigen::VectorXi>& joints,
                                            Eigen::Ref<Eigen::MatrixXd> dqdd, Eigen::Ref<Eigen::MatrixXd> dtau_cmd) {
  const std::vector<JointStatus>& status = impl_->status_per_joint;
  const auto held_count = std::count(status.begin(), status.end(), JointStatus::Stick);
  // On a floating base joint friction without contacts runs in the contact stage (solve.cpp).
  const bool floating_friction = impl_->core.model.floating && impl_->stage_joints && impl_->contact_stage->count == 0;
  if (!(impl_->friction_last || floating_friction) || held_count == 0) return responseColumns(joints, dqdd, dtau_cmd);
  // Rows: nv (a floating base's nb first), joint j's row nb + j.
  const Eigen::Index n = model().nrOfJoints(), nv = model().nv(), nb = nv - n, k = joints.size(), s = held_count;
  if (dqdd.rows() != nv || dqdd.cols() != k || dtau_cmd.rows() != nv || dtau_cmd.cols() != k)
    return Status(Error::SizeMismatch, "dqdd and dtau_cmd must be n_joints (nv) x joints.size()");
  Eigen::VectorXi all(k + s);
  all.head(k) = joints;
  for (Eigen::Index j = 0, a = k; j < n; ++j)
    if (status[static_cast<std::size_t>(j)] == JointStatus::Stick) all(a++) = static_cast<int>(j);
  Eigen::MatrixXd dq(nv, k + s), dt(nv, k + s);
  if (const Status st = responseColumns(all, dq, dt); !st) return st;
  // The held joints' extra friction per unit torque X = -G[S, S]^+ G[S, J]; then G[:, J] + G[:, S] X.
  Eigen::MatrixXd g_ss(s, s), g_sj(s, k);
  for (Eigen::Index a = 0; a < s; ++a) {
    for (Eigen::Index b = 0; b < s; ++b) g_ss(a, b) = dq(nb + all(k + a), k + b);
    for (Eigen::Index c = 0; c < k; ++c) g_sj(a, c) = dq(nb + all(k + a), c);
  }
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(g_ss);
  cod.setThreshold(1e-12);
  const Eigen::MatrixXd x = -cod.solve(g_sj);
  dqdd = dq.leftCols(k) + dq.rightCols(s) * x;
  dtau_cmd = dt.leftCols(k) + dt.rightCols(s) * x;
  return Status();
}

}  // namespace vereshchagin
