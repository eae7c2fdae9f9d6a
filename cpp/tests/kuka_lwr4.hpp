// KUKA LWR 4 with identified dynamic parameters, as published by A. Jubien, M. Gautier and
// A. Janot, "Dynamic identification of the Kuka LWR robot using motor torques and joint torque
// sensors data", IFAC Proceedings Volumes 47(3), 2014, pp. 8391-8396, in the form Orocos KDL's own
// solver tests use them (orocos_kdl/tests/solvertest.cpp, KDL 1.5.1): modified (Craig 1989)
// Denavit-Hartenberg frames, 2 kg per link, link centres of mass and rotational inertias in each
// link's DH frame, and effective joint (rotor) inertias. Several link inertias are not positive
// semi-definite (identified parameters); the joint-space inertia matrix is positive definite.
#pragma once

#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>

namespace testutil {

inline KDL::Chain kukaLwr4() {
  struct Link {
    double alpha, d;            // Craig DH: link twist (rad) and offset (m); a = theta = 0
    double rotor;               // joint's effective rotor inertia, kg m^2
    double cx, cy, cz;          // centre of mass in the DH frame, m
    double ixx, iyy, izz, iyz;  // rotational inertia in the DH frame, kg m^2 (ixy = ixz = 0)
  };
  const double h = 1.5707963;  // the published model's pi / 2
  const Link links[7] = {
      {h, 0.0, 3.19, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0115343, 0.0},
      {-h, 0.4, 3.05, 0.0, -0.3120511, -0.0038871, -0.5471572, -0.0000302, -0.5423253, 0.0018828},
      {-h, 0.0, 1.98, 0.0, -0.0015515, 0.0, 0.0063507, 0.0, 0.0107804, -0.0005147},
      {h, 0.39, 2.05, 0.0, 0.5216809, 0.0, -1.0436952, 0.0, -1.0392780, 0.0005324},
      {h, 0.0, 0.787, 0.0, 0.0119891, 0.0, 0.0036654, 0.0, 0.0060429, 0.0004226},
      {-h, 0.0, 0.391, 0.0, 0.0080787, 0.0, 0.0010431, 0.0, 0.0036376, 0.0000101},
      {0.0, 0.0, 0.394, 0.0, 0.0, 0.0, 0.000001, 0.0, 0.0001203, 0.0},
  };
  KDL::Chain chain;
  for (int k = 0; k < 7; ++k) {
    const Link& l = links[k];
    // The last link's frame is the joint frame itself (no DH step), as in the published model.
    const KDL::Frame F = k < 6 ? KDL::Frame::DH_Craig1989(0.0, l.alpha, l.d, 0.0) : KDL::Frame::Identity();
    const KDL::RigidBodyInertia in_dh(2.0, KDL::Vector(l.cx, l.cy, l.cz),
                                      KDL::RotationalInertia(l.ixx, l.iyy, l.izz, 0.0, 0.0, l.iyz));
    const KDL::Joint joint("lwr_j" + std::to_string(k + 1), KDL::Joint::RotZ, 1.0, 0.0, l.rotor, 0.0, 0.0);
    chain.addSegment(KDL::Segment("lwr_link" + std::to_string(k + 1), joint, F, F.Inverse() * in_dh));
  }
  return chain;
}

}  // namespace testutil
