/// @file
/// A RobotTree's floating base (robot_tree.hpp: RobotTree::base, RobotTree::base_inertia) as plain
/// values, for the Python pickle state of a Tree (vereshchagin/_models.py): the base kind's name
/// (base_kind.hpp: "fixed", "free", "planar") and the 13 doubles KDL::RigidBodyInertia stores
/// (mass in kg, first moment m c in kg m and the rotational inertia about the base origin in
/// kg m^2, base axes), copied so that a restored tree solves bit for bit like the original.
#pragma once

#include <array>
#include <string>

#include "vereshchagin/robot_tree.hpp"

namespace vereshchagin {

/// The base inertia's 13 stored doubles (see the top of this file).
std::array<double, 13> baseInertiaDoubles(const RobotTree& robot);

/// Sets robot.base from its name and robot.base_inertia from its 13 stored doubles; false (robot
/// unchanged) with a message for an unknown name or a non-finite or negative-mass inertia.
bool setBaseState(RobotTree& robot, const std::string& kind, const std::array<double, 13>& inertia,
                  std::string& message);

}  // namespace vereshchagin
