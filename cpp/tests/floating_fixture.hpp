// A random tree on a floating base (base_kind.hpp) and a configuration for it, shared by the
// floating-base tests (test_floating_base.cpp, test_floating_step.cpp, test_floating_contacts.cpp,
// test_no_alloc.cpp, test_pinocchio_oracle.cpp).
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "random_tree.hpp"
#include "vereshchagin/model.hpp"

namespace testutil {

/// A random tree drawn from `g` by `spec` on a base of kind `kind` whose body has mass
/// `base_mass` (its centre of mass and rotational inertia fixed).
inline vereshchagin::Model floatingTreeModel(vereshchagin::BaseKind kind, RandomGen& g, const TreeSpec& spec,
                                             double base_mass) {
  vereshchagin::ModelOptions options;
  options.base = kind;
  options.base_inertia = KDL::RigidBodyInertia(base_mass, KDL::Vector(0.05, -0.02, 0.01),
                                               KDL::RotationalInertia(0.2, 0.3, 0.25, 0.01, 0.0, -0.02));
  return vereshchagin::Model(randomTree(g, spec), "", options);
}

/// A random tree of `n_joints` joints (seed `seed`, no rotor inertia: a rotor's inertia is not the
/// body's, free fall would feel it) on a base of kind `kind` with a 3 kg base body.
inline vereshchagin::Model floatingTreeModel(vereshchagin::BaseKind kind, unsigned seed, int n_joints) {
  RandomGen g(seed);
  TreeSpec spec;
  spec.n_joints = n_joints;
  spec.rotor_inertia = false;
  return floatingTreeModel(kind, g, spec, 3.0);
}

/// q (nq entries) spaced evenly from `lo` to `hi`, its base orientation replaced by a fixed unit
/// quaternion (free-flyer) or (cos 0.7, sin 0.7) (planar).
inline Eigen::VectorXd floatingConfiguration(const vereshchagin::Model& model, double lo, double hi) {
  Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(model.nq(), lo, hi);
  if (model.baseKind() == vereshchagin::BaseKind::FreeFlyer) {
    q.segment<4>(3) << 0.3, -0.5, 0.2, 0.8;
    q.segment<4>(3).normalize();
  } else {
    q.segment<2>(2) << std::cos(0.7), std::sin(0.7);
  }
  return q;
}

}  // namespace testutil
