// Deterministic random KDL chains and solver inputs for the tests.
//
// Everything is drawn from a seeded std::mt19937_64, so a failing sample is reproduced from its
// seed alone. Distributions:
//  * joints: RotX/RotY/RotZ, RotAxis (random unit axis, random origin in [-0.3,0.3]^3), and (unless
//    disabled) TransX/TransY/TransZ, TransAxis (random unit axis and origin); rotor inertia 0 (half
//    of the time) or uniform in [0, 0.5];
//  * segment tip frames: random RPY in [-pi, pi]^3, translation in [-0.5, 0.5]^3;
//  * segment inertias: mass in [0.1, 5], centre of mass in [-0.3, 0.3]^3, rotational inertia about
//    the centre of mass R diag(a, b, c) R^T with a, b, c in [0.01, 0.5] obeying the triangle
//    inequality (a physically realisable body).
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/chainidsolver.hpp>  // KDL::Wrenches
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>
#include <kdl/segment.hpp>

namespace testutil {

struct ChainSpec {
  int n_joints = 7;             // moving joints, 1..30 in the tests
  bool allow_prismatic = true;  // TransX/Y/Z and TransAxis joints
  bool rotor_inertia = true;    // random rotor inertias (else 0)
  // A fixed segment (KDL::Joint::Fixed, random tip frame and inertia) is inserted before moving
  // joint k for every k listed here (k = n_joints appends it after the last moving segment).
  // Repeated entries insert several consecutive fixed segments.
  std::vector<int> fixed_before;
};

class RandomGen {
 public:
  explicit RandomGen(unsigned long long seed) : rng_(seed) {}

  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }  // inclusive
  bool coin(double p_true = 0.5) { return uniform(0.0, 1.0) < p_true; }

  // Every draw is its own statement: the order of a call's arguments is unspecified in C++ (g++
  // evaluates them last to first, clang++ first to last), so draws inside one argument list gave
  // each compiler other samples. The statements keep the order g++ drew in before, so the tests'
  // samples stayed what they were.
  KDL::Vector vector(double lo, double hi) {
    const double z = uniform(lo, hi), y = uniform(lo, hi), x = uniform(lo, hi);
    return KDL::Vector(x, y, z);
  }

  KDL::Vector unitVector() {
    for (;;) {
      const KDL::Vector v = vector(-1.0, 1.0);
      const double nrm = v.Norm();
      if (nrm > 0.1 && nrm <= 1.0) return v / nrm;
    }
  }

  KDL::Rotation rotation() {
    const double yaw = uniform(-M_PI, M_PI), pitch = uniform(-M_PI, M_PI), roll = uniform(-M_PI, M_PI);
    return KDL::Rotation::RPY(roll, pitch, yaw);
  }

  KDL::Frame frame(double half_width = 0.5) {
    const KDL::Vector p = vector(-half_width, half_width);
    const KDL::Rotation R = rotation();
    return KDL::Frame(R, p);
  }

  // A segment's frame and inertia, drawn inertia first.
  KDL::Segment segment(const std::string& name, const KDL::Joint& joint) {
    const KDL::RigidBodyInertia I = inertia();
    const KDL::Frame f = frame();
    return KDL::Segment(name, joint, f, I);
  }

  // Rotational inertia about the centre of mass: R diag(a, b, c) R^T, triangle inequality holds.
  KDL::RotationalInertia rotationalInertia() {
    double a, b, c;
    do {
      a = uniform(0.01, 0.5);
      b = uniform(0.01, 0.5);
      c = uniform(0.01, 0.5);
    } while (a + b < c || b + c < a || a + c < b);
    const KDL::Rotation R = rotation();
    double I[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) I[i][j] = a * R(i, 0) * R(j, 0) + b * R(i, 1) * R(j, 1) + c * R(i, 2) * R(j, 2);
    return KDL::RotationalInertia(I[0][0], I[1][1], I[2][2], I[0][1], I[0][2], I[1][2]);
  }

  KDL::RigidBodyInertia inertia() {
    const double m = uniform(0.1, 5.0);
    const KDL::Vector com = vector(-0.3, 0.3);
    return KDL::RigidBodyInertia(m, com, rotationalInertia());
  }

  double rotorInertia(bool enabled) {
    if (!enabled || coin(0.5)) return 0.0;
    return uniform(0.0, 0.5);
  }

  KDL::Joint movingJoint(const std::string& name, bool allow_prismatic, bool rotor) {
    const int kinds = allow_prismatic ? 8 : 4;
    const int kind = integer(0, kinds - 1);
    const double r = rotorInertia(rotor);
    switch (kind) {
      case 0:
        return KDL::Joint(name, KDL::Joint::RotX, 1.0, 0.0, r);
      case 1:
        return KDL::Joint(name, KDL::Joint::RotY, 1.0, 0.0, r);
      case 2:
        return KDL::Joint(name, KDL::Joint::RotZ, 1.0, 0.0, r);
      case 3: {
        const KDL::Vector origin = vector(-0.3, 0.3);
        return KDL::Joint(name, origin, unitVector(), KDL::Joint::RotAxis, 1.0, 0.0, r);
      }
      case 4:
        return KDL::Joint(name, KDL::Joint::TransX, 1.0, 0.0, r);
      case 5:
        return KDL::Joint(name, KDL::Joint::TransY, 1.0, 0.0, r);
      case 6:
        return KDL::Joint(name, KDL::Joint::TransZ, 1.0, 0.0, r);
      default: {
        const KDL::Vector origin = vector(-0.3, 0.3);
        return KDL::Joint(name, origin, unitVector(), KDL::Joint::TransAxis, 1.0, 0.0, r);
      }
    }
  }

  KDL::Segment fixedSegment() { return segment("NoName", KDL::Joint(KDL::Joint::Fixed)); }

  KDL::Chain chain(const ChainSpec& spec) {
    KDL::Chain ch;
    for (int k = 0; k <= spec.n_joints; ++k) {
      const int fixed_here = static_cast<int>(std::count(spec.fixed_before.begin(), spec.fixed_before.end(), k));
      for (int f = 0; f < fixed_here; ++f) ch.addSegment(fixedSegment());
      if (k == spec.n_joints) break;
      const KDL::Joint j = movingJoint("j" + std::to_string(k), spec.allow_prismatic, spec.rotor_inertia);
      ch.addSegment(segment("s" + std::to_string(k), j));
    }
    return ch;
  }

  KDL::Chain chain(int n_joints, bool allow_prismatic = true, bool rotor_inertia = true) {
    ChainSpec spec;
    spec.n_joints = n_joints;
    spec.allow_prismatic = allow_prismatic;
    spec.rotor_inertia = rotor_inertia;
    return chain(spec);
  }

  KDL::JntArray jntArray(unsigned int n, double lo, double hi) {
    KDL::JntArray a(n);
    for (unsigned int i = 0; i < n; ++i) a(i) = uniform(lo, hi);
    return a;
  }
  KDL::JntArray q(unsigned int n) { return jntArray(n, -M_PI, M_PI); }
  KDL::JntArray qdot(unsigned int n) { return jntArray(n, -2.0, 2.0); }
  KDL::JntArray torques(unsigned int n) { return jntArray(n, -5.0, 5.0); }

  KDL::Wrenches fext(unsigned int n_segments, double scale = 2.0) {
    KDL::Wrenches w(n_segments);
    for (auto& x : w) {
      const KDL::Vector torque = vector(-scale, scale), force = vector(-scale, scale);
      x = KDL::Wrench(force, torque);
    }
    return w;
  }

  // 6 x nc, columns of unit Euclidean norm.
  KDL::Jacobian alfa(unsigned int nc) {
    KDL::Jacobian a(nc);
    for (unsigned int c = 0; c < nc; ++c) {
      Eigen::Matrix<double, 6, 1> col;
      do {
        for (int r = 0; r < 6; ++r) col(r) = uniform(-1.0, 1.0);
      } while (col.norm() < 0.1);
      a.data.col(c) = col.normalized();
    }
    return a;
  }
  KDL::JntArray beta(unsigned int nc) { return jntArray(nc, -5.0, 5.0); }

  std::mt19937_64& engine() { return rng_; }

 private:
  std::mt19937_64 rng_;
};

// ---- conversions between KDL containers and the Eigen entry point ----

inline Eigen::Matrix<double, 6, Eigen::Dynamic> toMatrix(const KDL::Wrenches& w) {
  Eigen::Matrix<double, 6, Eigen::Dynamic> m(6, static_cast<Eigen::Index>(w.size()));
  for (std::size_t i = 0; i < w.size(); ++i)
    for (int r = 0; r < 6; ++r) m(r, static_cast<Eigen::Index>(i)) = w[i](r);
  return m;
}

inline Eigen::Matrix<double, 6, Eigen::Dynamic> toMatrix(const std::vector<KDL::Twist>& t) {
  Eigen::Matrix<double, 6, Eigen::Dynamic> m(6, static_cast<Eigen::Index>(t.size()));
  for (std::size_t i = 0; i < t.size(); ++i)
    for (int r = 0; r < 6; ++r) m(r, static_cast<Eigen::Index>(i)) = t[i](r);
  return m;
}

inline Eigen::Matrix<double, 6, 1> toVector(const KDL::Twist& t) {
  Eigen::Matrix<double, 6, 1> v;
  for (int r = 0; r < 6; ++r) v(r) = t(r);
  return v;
}

inline Eigen::Matrix<double, 6, 1> toVector(const KDL::Wrench& w) {
  Eigen::Matrix<double, 6, 1> v;
  for (int r = 0; r < 6; ++r) v(r) = w(r);
  return v;
}

inline KDL::Wrench toWrench(const Eigen::Matrix<double, 6, 1>& v) {
  return KDL::Wrench(KDL::Vector(v(0), v(1), v(2)), KDL::Vector(v(3), v(4), v(5)));
}

inline Eigen::Matrix3d toMatrix(const KDL::Rotation& R) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = R(i, j);
  return m;
}

// The arguments of one solve drawn at random: state, feed-forward torques, a wrench on every
// segment, nc constraint columns and their set-points (segments of the columns are the caller's).
struct SolveInputs {
  Eigen::VectorXd q, qd, beta, ff;
  Eigen::Matrix<double, 6, Eigen::Dynamic> alfa, fext;
  Eigen::VectorXi segments;
};

inline SolveInputs randomInputs(RandomGen& g, unsigned int n, unsigned int ns, int nc) {
  SolveInputs in;
  in.q = g.q(n).data;
  in.qd = g.qdot(n).data;
  in.ff = g.torques(n).data;
  in.fext = toMatrix(g.fext(ns));
  in.alfa = g.alfa(nc).data;
  in.beta = g.beta(nc).data;
  return in;
}

}  // namespace testutil
