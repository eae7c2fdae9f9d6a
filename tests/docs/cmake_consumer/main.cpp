// Downstream use of the installed library: a 2-joint pendulum held by one constraint.
#include <cmath>
#include <cstdio>

#include <kdl/chain.hpp>
#include <vereshchagin/chain_hd_solver.hpp>

int main() {
  KDL::Chain chain;
  for (int i = 0; i < 2; ++i) {
    chain.addSegment(KDL::Segment(
        KDL::Joint(KDL::Joint::RotY), KDL::Frame(KDL::Vector(0.5, 0.0, 0.0)),
        KDL::RigidBodyInertia(1.0, KDL::Vector(0.25, 0.0, 0.0), KDL::RotationalInertia(0.01, 0.02, 0.02))));
  }
  vereshchagin::ChainHdSolver solver(chain, KDL::Twist(KDL::Vector(0, 0, 9.81), KDL::Vector::Zero()));
  KDL::JntArray q(2), qd(2), qdd(2), tau(2), cmd(2), beta(1);
  KDL::Jacobian alfa(1);
  alfa.data.setZero();
  alfa.data(2, 0) = 1.0;  // hold the tip still along z
  beta(0) = 9.81;         // = root acceleration: zero classical acceleration
  KDL::Wrenches f_ext(2, KDL::Wrench::Zero());
  const int rc = solver.CartToJnt(q, qd, qdd, alfa, beta, f_ext, tau, cmd);
  if (rc != 0) {
    std::printf("consumer: solve failed: %s\n", solver.errorMessage());
    return 1;
  }
  // The tip's vertical acceleration must equal the set-point.
  const double az = solver.linkAccelerations()(2, 2);
  if (!(std::abs(az - 9.81) < 1e-9) || !std::isfinite(cmd(0))) {
    std::printf("consumer: unexpected result az=%g\n", az);
    return 1;
  }
  std::printf("consumer: find_package(vereshchagin) works; tau_cmd = [%g, %g]\n", cmd(0), cmd(1));
  return 0;
}
