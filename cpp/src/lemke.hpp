// Lemke's complementary pivoting for a small dense linear complementarity problem
//     w = M z + q,  w >= 0,  z >= 0,  w^T z = 0,
// with the covering vector of ones. Finitely many pivots: the lexicographic ratio test never
// revisits a basis (ties go to the artificial variable first); max_pivots bounds them anyway. For M copositive-plus
// (positive semi-definite, e.g. frictionless contacts) a secondary ray proves that the problem has no solution;
// otherwise it only says none was found. Workspace sized by reserve(); solve() allocates nothing within it.
#pragma once

#include <Eigen/Core>

#include "dual_qp.hpp"

namespace vereshchagin {
namespace detail {

class Lemke {
 public:
  enum Result { kSolved = 0, kRay = 1, kPivotLimit = 2 };

  // Room for problems of up to n variables (allocates).
  void reserve(int n);
  int capacity() const { return static_cast<int>(basis_.size()); }
  // Solves the LCP of M (n x n) and q (n), n <= capacity(); z and w (n) receive the answer.
  // tolerance: entries of a pivot column at or below it do not bound the ratio test (scaled by
  // the problem's magnitude inside). pivots: the pivots made.
  Result solve(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
               Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w, int max_pivots, int& pivots);

  // After solve() returned kSolved: the complementary basis it ended on, evaluated at another q
  // (n, the same size): the basic variables B^-1 q (clipped at 0), the others 0, into z and
  // w = M z + q. For a q perturbed to break ties, this is the original problem's basic solution.
  void basicSolution(const Eigen::Ref<const Eigen::MatrixXd>& M, const Eigen::Ref<const Eigen::VectorXd>& q,
                     Eigen::Ref<Eigen::VectorXd> z, Eigen::Ref<Eigen::VectorXd> w) const;

 private:
  int ratioTest(int entering, int n, double tol) const;
  void pivot(int row, int col, int n);
  // Tableau [I | -M | -e | q] over the variables w (0..n-1), z (n..2n-1), z0 (2n), rhs (2n+1).
  Eigen::MatrixXd tableau_;
  Eigen::VectorXi basis_;   // variable in the basis of each row
  Eigen::VectorXd factor_;  // pivot(): the pivot column's multipliers
};

// A small convex quadratic programme on Lemke's pivoting:
//     min 1/2 x^T Q x + c^T x   subject to   R x >= r   (x free; equalities as two rows),
// Q positive semi-definite (p x p), R (k x p). Its optimality conditions are the LCP of the
// bisymmetric, positive semi-definite matrix [[Q, -Q, -R^T], [-Q, Q, R^T], [R, -R, 0]] in
// (x+, x-, multipliers), x = x+ - x-, which Lemke's pivoting solves whenever the programme is
// feasible and bounded. Workspace by reserve(p, k); solve() allocates nothing within it.
class ConvexQp {
 public:
  void reserve(int p, int k);
  Lemke::Result solve(const Eigen::Ref<const Eigen::MatrixXd>& Q, const Eigen::Ref<const Eigen::VectorXd>& c,
                      const Eigen::Ref<const Eigen::MatrixXd>& R, const Eigen::Ref<const Eigen::VectorXd>& r,
                      Eigen::Ref<Eigen::VectorXd> x, int max_pivots);

 private:
  Lemke lemke_;
  Eigen::MatrixXd m_;
  Eigen::VectorXd q_, z_, w_;
};

// Two convex programmes in turn over the same feasible set R x >= r: first
//     min 1/2 ||t + C x||^2,
// then, among its minimisers (x = x1 + Z w, Z spanning C's null space, from a pivoted Cholesky
// factor of C^T C: C x is unique), the one
// with the least 1/2 x^T P x + p^T x (P positive definite on Z's span, so the answer is unique).
// Skips the first when C has no rows (x1 = 0: the caller's point must be feasible), the second when
// C has independent columns; the second runs as the LCP of its dual (k
// multipliers) when its Hessian is certainly positive definite. When R's first 2 eq rows are an
// equality E x = 0 written as two inequalities (E, then -E, each >= a round-off slack), and the
// second programme does not finish (P only positive semi-definite on Z's span, and the doubled
// primal's pivoting stalls on the degenerate pairs), it runs once more on the null space of
// [C; E] with the other rows only (secondOnEqualities); when C has no rows that form runs first
// (the doubled primal over all p unknowns only if it fails: the same minimiser in exact
// arithmetic, E x = 0 kept exactly instead of within the pairs' slack). When C has rows, all of that
// is the fallback: both programmes are first tried by the dual active-set method with a certificate
// (lexicographic_active.cpp; E x = 0 as an equality there), which returns kRay itself when it proves
// the rows admit no point (without E: with it the pairs' slack might). Workspace by reserve(p, k)
// (p unknowns, k rows); solve() allocates nothing within it.
class LexicographicQp {
 public:
  void reserve(int p, int k);
  Lemke::Result solve(const Eigen::Ref<const Eigen::MatrixXd>& C, const Eigen::Ref<const Eigen::VectorXd>& t,
                      const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& pv,
                      const Eigen::Ref<const Eigen::MatrixXd>& R, const Eigen::Ref<const Eigen::VectorXd>& r,
                      Eigen::Ref<Eigen::VectorXd> x, int eq = 0);
  // The last solve was answered by the dual active-set method (lexicographic_active.cpp), not the
  // pivoting (tests, benchmarks).
  bool byActiveSet() const { return by_active_set_; }

 private:
  bool secondOnEqualities(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& pv,
                          const Eigen::Ref<const Eigen::MatrixXd>& R, const Eigen::Ref<const Eigen::VectorXd>& r,
                          Eigen::Ref<Eigen::VectorXd> x, int eq);
  bool secondOnNull(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& pv,
                    const Eigen::Ref<const Eigen::MatrixXd>& Rs, const Eigen::Ref<const Eigen::VectorXd>& rs,
                    const Eigen::Ref<const Eigen::VectorXd>& x, int d);
  // secondOnNull's two halves: the programme in w into q2_, c2_, rz_, r2_ (activeSetSolve builds
  // the same with coefficient-wise products); then its pivoting, which reads them.
  void secondData(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& pv,
                  const Eigen::Ref<const Eigen::MatrixXd>& Rs, const Eigen::Ref<const Eigen::VectorXd>& rs,
                  const Eigen::Ref<const Eigen::VectorXd>& x, int d);
  bool secondPivoting(int d, int k);
  bool strictSecond(const Eigen::Ref<const Eigen::MatrixXd>& Q2, const Eigen::Ref<const Eigen::VectorXd>& c2,
                    const Eigen::Ref<const Eigen::MatrixXd>& RZ, const Eigen::Ref<const Eigen::VectorXd>& r2,
                    Eigen::Ref<Eigen::VectorXd> w);
  int nullBasis(const Eigen::Ref<const Eigen::MatrixXd>& Q);
  int nullBasisWithEqualities(const Eigen::Ref<const Eigen::MatrixXd>& E);
  // The first try by the dual active-set method, certified (lexicographic_active.cpp): kAnswered
  // when x holds the answer, kInfeasible when the rows admit no point, else kUnknown (the pivoting
  // then finds it).
  enum class ActiveSet { kAnswered, kInfeasible, kUnknown };
  ActiveSet activeSetSolve(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& pv,
                           const Eigen::Ref<const Eigen::MatrixXd>& R, const Eigen::Ref<const Eigen::VectorXd>& r,
                           Eigen::Ref<Eigen::VectorXd> x, int eq);
  bool firstOnActive(int p);
  bool certified(const Eigen::Ref<const Eigen::VectorXd>& x, int eq, int rows);
  void reserveActiveSet(int p, int k);
  DualActiveSetQp gi_, gi2_;  // the first programme's active rows; the second programme
  bool by_active_set_ = false;
  Eigen::MatrixXd as_h_, as_pw_, as_s_, as_v_, as_rw_, as_gw_, as_lw_, as_a_;
  Eigen::VectorXd as_g_, as_x_, as_y_, as_t_, as_diag_, as_l_, as_b_;
  Eigen::VectorXi as_idx_, as_piv_;
  ConvexQp qp_;
  Lemke lemke2_;  // the second programme's dual
  Eigen::VectorXi idx_, piv_;
  Eigen::VectorXd diag_;
  Eigen::MatrixXd q_, v_, z_, rz_, q2_, l2_, g2_, m2_;
  Eigen::VectorXd c_, r2_, w_, c2_, q2v_, l_, s_;
};

}  // namespace detail
}  // namespace vereshchagin
