/// @file
/// A serial KDL::Chain together with what a robot description says about its joints and links.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/joint.hpp>

namespace vereshchagin {

/// A copy of `joint` with rotor inertia `rotor` reflected to it (kg m^2 or kg); origin, axis, type,
/// damping and stiffness kept. (A fixed joint's rotor inertia is never read.)
inline KDL::Joint withRotorInertia(const KDL::Joint& joint, double rotor) {
  if (joint.getType() == KDL::Joint::RotAxis || joint.getType() == KDL::Joint::TransAxis)
    return KDL::Joint(joint.getName(), joint.JointOrigin(), joint.JointAxis(), joint.getType(), 1.0, 0.0, rotor,
                      joint.getDamping(), joint.getStiffness());
  return KDL::Joint(joint.getName(), joint.getType(), 1.0, 0.0, rotor, joint.getDamping(), joint.getStiffness());
}

/// One moving joint of the chain. Units: rad or m, rad/s or m/s, N m or N.
struct JointInfo {
  std::string name;                                                 ///< the joint's name
  std::string type;                                                 ///< "revolute", "continuous" or "prismatic"
  double lower = -std::numeric_limits<double>::infinity();          ///< lower position limit
  double upper = std::numeric_limits<double>::infinity();           ///< upper position limit
  double velocity_limit = std::numeric_limits<double>::infinity();  ///< the URDF velocity limit
  double effort_limit = std::numeric_limits<double>::infinity();    ///< the URDF effort limit
  double friction = 0.0;     ///< static (breakaway) friction, the URDF `<dynamics friction>` value
  double damping = 0.0;      ///< viscous damping, N m s/rad or N s/m
  unsigned int segment = 0;  ///< index of the chain segment this joint moves
};

/// Where a link of the description ended up: links merged through fixed joints share a segment.
struct LinkPlacement {
  std::string link;           ///< the link's name
  int segment = -1;           ///< segment whose rigid body holds the link (-1: the base)
  KDL::Frame in_segment_tip;  ///< pose of the link frame in that segment's tip frame (base: root)
};

/// The result of loading a chain: the KDL::Chain and what the description says about it.
struct RobotChain {
  KDL::Chain chain;                  ///< the chain from the base frame (root_link) to the tip
  std::vector<JointInfo> joints;     ///< one per moving joint, in chain order
  std::vector<LinkPlacement> links;  ///< every link folded into the chain's segments
  std::string root_link;             ///< the base frame
  std::vector<std::string> notes;    ///< approximations made while building (e.g. lumped branches)
};

}  // namespace vereshchagin
