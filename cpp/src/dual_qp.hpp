// A dual active-set method for a small dense strictly convex quadratic programme
//     min 1/2 x^T H x + g^T x   subject to   A_i x = b_i (i < eq),   A_i x >= b_i (i >= eq),
// H positive definite (p x p), A (k x p): the method of Goldfarb and Idnani (Math. Programming 27,
// 1983, 1-33). It starts at the unconstrained minimiser -H^-1 g (no feasible point needed) and
// adds one violated row at a time, each step keeping the active rows' multipliers non-negative
// (dropping a row whose multiplier reaches zero), so that every iterate is optimal for the rows
// active in it; the objective grows strictly, hence no active set repeats and the method ends
// after finitely many steps: at the optimum, or with a proof that the rows admit no point (a
// violated row that the active ones imply, with no multiplier to release). The active rows stay
// linearly independent. The active normals in H^-1's metric, B = L^-1 N (H = L L^T), are kept as
// B = J T (orthonormal J, upper triangular T), extended by one Gram-Schmidt column when a row
// enters and refactored from the dropped column on when one leaves: meant for p and k of a few
// dozen. Workspace by reserve(p, k); solve() allocates nothing within it.
#pragma once

#include <Eigen/Core>

namespace vereshchagin {
namespace detail {

class DualActiveSetQp {
 public:
  enum Result { kSolved = 0, kInfeasible = 1, kNotDefinite = 2, kStepLimit = 3 };

  void reserve(int p, int k);
  // max_steps bounds the added and dropped rows together. On kSolved, x is the minimiser and
  // active() / multipliers() name the active rows (independent) and their multipliers (>= 0 for
  // inequalities).
  Result solve(const Eigen::Ref<const Eigen::MatrixXd>& H, const Eigen::Ref<const Eigen::VectorXd>& g,
               const Eigen::Ref<const Eigen::MatrixXd>& A, const Eigen::Ref<const Eigen::VectorXd>& b, int eq,
               Eigen::Ref<Eigen::VectorXd> x, int max_steps);
  int activeCount() const { return na_; }
  int active(int j) const { return act_(j); }
  double multiplier(int j) const { return u_(j); }

 private:
  // The step for the row `row` (its normal n = A_row^T) with the active rows: primal direction
  // z = H^-1 n projected off the active normals in H^-1's metric, dual direction r (the active
  // multipliers' change per unit of the new one). zn: z^T n (0 when n depends on the active
  // normals).
  void direction(const Eigen::Ref<const Eigen::MatrixXd>& A, int row, double& zn);
  void orthogonalize(int j);
  void addActive(int row, double u);
  void dropActive(int j);

  int p_ = 0, na_ = 0;
  Eigen::MatrixXd l_;      // p x p: H = L L^T
  Eigen::MatrixXd b_;      // p x p: B, L^-1 n_j per active row j
  Eigen::MatrixXd j_, t_;  // B = J T: J orthonormal columns, T upper triangular
  Eigen::VectorXd d_, z_, r_, u_, w_, norm_, s_;
  Eigen::VectorXi act_;
  Eigen::Matrix<bool, Eigen::Dynamic, 1> is_active_;
};

}  // namespace detail
}  // namespace vereshchagin
