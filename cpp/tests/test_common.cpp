// test_common.hpp's helpers (declared and documented there).
#include "test_common.hpp"

namespace testutil {

double relErr(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return INFINITY;
  if (a.size() == 0) return 0.0;
  if (!a.allFinite() || !b.allFinite()) return INFINITY;
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

double relErrCols(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return INFINITY;
  double e = 0.0;
  for (Eigen::Index c = 0; c < a.cols(); ++c) e = std::max(e, relErr(a.col(c), b.col(c)));
  return e;
}

bool nearFrame(const KDL::Frame& a, const KDL::Frame& b, double tol) {
  for (int r = 0; r < 3; ++r) {
    if (!near(a.p(r), b.p(r), tol)) return false;
    for (int c = 0; c < 3; ++c)
      if (!near(a.M(r, c), b.M(r, c), tol)) return false;
  }
  return true;
}

std::string mat(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  std::ostringstream os;
  os.precision(10);
  os << m.transpose();
  return os.str();
}

KDL::Chain withoutRotorInertia(const KDL::Chain& chain) {
  KDL::Chain out;
  for (const KDL::Segment& s : chain.segments) {
    const KDL::Joint& j = s.getJoint();
    KDL::Joint j0;
    switch (j.getType()) {
      case KDL::Joint::RotAxis:
      case KDL::Joint::TransAxis:
        j0 = KDL::Joint(j.getName(), j.JointOrigin(), j.JointAxis(), j.getType(), 1.0, 0.0, 0.0);
        break;
      default:
        j0 = KDL::Joint(j.getName(), j.getType(), 1.0, 0.0, 0.0);
        break;
    }
    out.addSegment(KDL::Segment(s.getName(), j0, s.getFrameToTip(), s.getInertia()));
  }
  return out;
}

DenseModel denseModel(const KDL::Chain& chain, const KDL::JntArray& q) {
  const unsigned int n = chain.getNrOfJoints();
  DenseModel d;
  KDL::Chain bare = withoutRotorInertia(chain);
  KDL::ChainDynParam dyn(bare, KDL::Vector::Zero());
  KDL::JntSpaceInertiaMatrix H(n);
  dyn.JntToMass(q, H);
  d.H = H.data;
  unsigned int j = 0;
  for (const KDL::Segment& s : chain.segments) {
    if (s.getJoint().getType() == KDL::Joint::Fixed) continue;
    d.H(j, j) += s.getJoint().getInertia();
    ++j;
  }
  KDL::ChainJntToJacSolver jac(chain);
  KDL::Jacobian J(n);
  jac.JntToJac(q, J);
  d.J = J.data;
  return d;
}

KDL::Wrenches toTipAxes(const KDL::Chain& chain, const KDL::JntArray& q, const KDL::Wrenches& f_ext) {
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::Wrenches out(f_ext.size());
  for (std::size_t i = 0; i < f_ext.size(); ++i) {
    KDL::Frame F;
    fk.JntToCart(q, F, static_cast<int>(i) + 1);
    out[i] = F.M.Inverse() * f_ext[i];
  }
  return out;
}

Eigen::VectorXd couplingEigenvalues(const DenseModel& d, const Eigen::MatrixXd& alfa) {
  if (alfa.cols() == 0) return Eigen::VectorXd();
  const Eigen::MatrixXd A = alfa.transpose() * d.J;
  const Eigen::MatrixXd K = A * d.H.lu().solve(A.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (K + K.transpose()), Eigen::EigenvaluesOnly);
  return es.eigenvalues();
}

bool wellConditioned(const Eigen::VectorXd& eig, double ratio) {
  if (eig.size() == 0) return true;
  return eig(0) > ratio * eig(eig.size() - 1) && eig(eig.size() - 1) > 0.0;
}

}  // namespace testutil
