// The same robot in Pinocchio's C++ model, built from a vereshchagin::Model (chains and trees,
// fixed joints merged into their parent's body, prismatic joints, rotor inertia as armature), with
// the maps between the two: each segment's Pinocchio joint and its tip frame in that joint's
// frame, and each of our joints' index in Pinocchio's v. Header-only use of Pinocchio (no library
// linked), for the oracle tests and benchmarks.
#pragma once

#include <pinocchio/multibody.hpp>

#include <vector>

#include <Eigen/Core>
#include <kdl/frames.hpp>
#include <kdl/segment.hpp>

#include "random_tree.hpp"
#include "vereshchagin/model.hpp"

namespace testutil {

// Random robots of the Pinocchio oracle tests: chains (even trials) and trees, 1 to 12 moving joints.
inline vereshchagin::Model randomOracleModel(RandomGen& g, int trial) {
  if (trial % 2 == 0) return vereshchagin::Model(g.chain(g.integer(1, 12)));
  TreeSpec spec;
  spec.n_joints = g.integer(2, 12);
  return vereshchagin::Model(randomTree(g, spec));
}

inline pinocchio::SE3 toSE3(const KDL::Frame& f) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = f.M(i, j);
  return pinocchio::SE3(r, Eigen::Vector3d(f.p.x(), f.p.y(), f.p.z()));
}

// KDL keeps the rotational inertia about the tip origin; Pinocchio's Inertia takes it about the
// centre of mass (parallel-axis theorem).
inline pinocchio::Inertia toInertia(const KDL::RigidBodyInertia& in) {
  const double m = in.getMass();
  const Eigen::Vector3d c(in.getCOG().x(), in.getCOG().y(), in.getCOG().z());
  const KDL::RotationalInertia ro = in.getRotationalInertia();
  const Eigen::Matrix3d io = Eigen::Map<const Eigen::Matrix3d>(ro.data);
  const Eigen::Matrix3d ic = io - m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  return pinocchio::Inertia(m, c, ic);
}

inline bool isPrismatic(KDL::Joint::JointType t) {
  return t == KDL::Joint::TransAxis || t == KDL::Joint::TransX || t == KDL::Joint::TransY || t == KDL::Joint::TransZ;
}

// A revolute or prismatic joint about (along) `axis` (unit, joint frame); with `aligned`, the
// axis-aligned types for +x, +y, +z (as Pinocchio's URDF parser picks them: faster sweeps).
inline pinocchio::JointModel jointModel(const Eigen::Vector3d& axis, bool prismatic, bool aligned) {
  for (int k = 0; aligned && k < 3; ++k) {
    if (axis != Eigen::Vector3d::Unit(k)) continue;
    if (k == 0) return prismatic ? pinocchio::JointModel(pinocchio::JointModelPX()) : pinocchio::JointModelRX();
    if (k == 1) return prismatic ? pinocchio::JointModel(pinocchio::JointModelPY()) : pinocchio::JointModelRY();
    return prismatic ? pinocchio::JointModel(pinocchio::JointModelPZ()) : pinocchio::JointModelRZ();
  }
  if (prismatic) return pinocchio::JointModelPrismaticUnaligned(axis);
  return pinocchio::JointModelRevoluteUnaligned(axis);
}

struct PinRobot {
  // `gravity`: physical, base axes; `aligned_axes`: see jointModel().
  PinRobot(const vereshchagin::Model& ours, const KDL::Vector& gravity, bool aligned_axes = false) {
    const int ns = static_cast<int>(ours.nrOfSegments());
    joint_of.assign(ns, 0);
    tip.assign(ns, pinocchio::SE3::Identity());
    v_index.assign(ours.nrOfJoints(), -1);
    std::vector<double> rotor(ours.nrOfJoints(), 0.0);
    pinocchio::JointIndex root = 0;  // a floating base: Pinocchio's free-flyer or planar joint
    nb = static_cast<int>(ours.nv() - ours.nrOfJoints());
    nbq = static_cast<int>(ours.nq() - ours.nrOfJoints());
    if (nb != 0) {
      const auto kind = ours.baseKind();
      root = kind == vereshchagin::BaseKind::FreeFlyer
                 ? model.addJoint(0, pinocchio::JointModelFreeFlyer(), pinocchio::SE3::Identity(), "base")
                 : model.addJoint(0, pinocchio::JointModelPlanar(), pinocchio::SE3::Identity(), "base");
      model.appendBodyToJoint(root, toInertia(ours.options().base_inertia), pinocchio::SE3::Identity());
    }
    for (int i = 0; i < ns; ++i) {
      const KDL::Segment& seg = ours.segment(i);
      const int p = ours.parents()[i];
      const pinocchio::JointIndex pj = p < 0 ? root : joint_of[p];
      const pinocchio::SE3 parent_tip = p < 0 ? pinocchio::SE3::Identity() : tip[p];
      const KDL::Joint& kj = seg.getJoint();
      const int j = ours.jointOfSegment()[i];
      if (j < 0) {  // rigid: the body joins the parent's joint
        joint_of[i] = pj;
        tip[i] = parent_tip * toSE3(seg.getFrameToTip());
      } else {  // motion about (along) the axis through the joint origin, parent tip axes
        const Eigen::Vector3d o(kj.JointOrigin().x(), kj.JointOrigin().y(), kj.JointOrigin().z());
        const Eigen::Vector3d axis(kj.JointAxis().x(), kj.JointAxis().y(), kj.JointAxis().z());
        const pinocchio::SE3 placement = parent_tip * pinocchio::SE3(Eigen::Matrix3d::Identity(), o);
        joint_of[i] =
            model.addJoint(pj, jointModel(axis, isPrismatic(kj.getType()), aligned_axes), placement, kj.getName());
        tip[i] = pinocchio::SE3(Eigen::Matrix3d::Identity(), -o) * toSE3(seg.getFrameToTip());
        rotor[j] = kj.getInertia();
      }
      model.appendBodyToJoint(joint_of[i], toInertia(seg.getInertia()), tip[i]);
    }
    model.gravity.linear(Eigen::Vector3d(gravity.x(), gravity.y(), gravity.z()));
    for (std::size_t j = 0; j < v_index.size(); ++j) {
      v_index[j] = model.idx_vs[joint_of[ours.segmentOfJoint()[j]]];
      model.armature(v_index[j]) = rotor[j];
    }
  }
  // A joint vector in our order -> Pinocchio's, and back. On a floating base a velocity-sized
  // vector (nv) keeps its base rows first; toPinQ maps a configuration (nq).
  Eigen::VectorXd toPin(const Eigen::VectorXd& x) const {
    Eigen::VectorXd out(x.size());
    out.head(nb) = x.head(nb);
    for (std::size_t j = 0; j < v_index.size(); ++j) out(v_index[j]) = x(nb + j);
    return out;
  }
  Eigen::VectorXd fromPin(const Eigen::VectorXd& x) const {
    Eigen::VectorXd out(x.size());
    out.head(nb) = x.head(nb);
    for (std::size_t j = 0; j < v_index.size(); ++j) out(nb + j) = x(v_index[j]);
    return out;
  }
  Eigen::VectorXd toPinQ(const Eigen::VectorXd& q) const {
    Eigen::VectorXd out(q.size());
    out.head(nbq) = q.head(nbq);
    for (std::size_t j = 0; j < v_index.size(); ++j) out(v_index[j] - nb + nbq) = q(nbq + j);
    return out;
  }
  int nb = 0, nbq = 0;  // the base's entries of v and q (0 on a fixed base)
  pinocchio::Model model;
  std::vector<pinocchio::JointIndex> joint_of;  // per segment
  std::vector<pinocchio::SE3> tip;              // per segment: its tip in its joint's frame
  std::vector<int> v_index;                     // per joint of ours: its index in Pinocchio's v
};

}  // namespace testutil
