// A small branched robot for the robot_* tests: base -rev- arm -rev- hand -fixed- finger (one
// segment named 'finger', 'hand' merged into it 0.05 m below its tip) and base -prismatic- slider.
#pragma once

#include <doctest/doctest.h>

#include "vereshchagin/urdf_loader.hpp"

namespace robotfixture {

inline const char* kUrdf = R"(<robot name="fixture">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0 0 0.1"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <link name="hand"><inertial><origin xyz="0 0.01 0.05"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.005"/></inertial></link>
  <link name="finger"><inertial><mass value="0.1"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <link name="slider"><inertial><mass value="3"/>
    <inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.03"/></inertial></link>
  <joint name="j_arm" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="2"/><dynamics friction="0.5"/></joint>
  <joint name="j_hand" type="continuous"><parent link="arm"/><child link="hand"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/></joint>
  <joint name="j_finger" type="fixed"><parent link="hand"/><child link="finger"/><origin xyz="0 0 0.05"/></joint>
  <joint name="j_slider" type="prismatic"><parent link="base"/><child link="slider"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.5" effort="10" velocity="1"/></joint>
</robot>)";

inline vereshchagin::RobotTree tree() {
  const vereshchagin::UrdfTreeResult r = vereshchagin::treeFromUrdfString(kUrdf);
  REQUIRE_MESSAGE(r.ok, r.message);
  return r.robot;
}

inline vereshchagin::RobotChain chain() {
  const vereshchagin::UrdfResult r = vereshchagin::chainFromUrdfString(kUrdf, "base", "finger");
  REQUIRE_MESSAGE(r.ok, r.message);
  return r.robot;
}

}  // namespace robotfixture
