// The Python Chain and Tree as one template over the C++ robot (RobotChain / RobotTree) and the
// inertia check it was built with. Names and frames are resolved by addressing.hpp, the
// companions' C++ model is built on demand (companions.hpp); the domain logic is the C++
// library's (robot_access.hpp, robot_edit.hpp, robot_state.hpp).
#pragma once

#include <string>
#include <vector>

#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/robot_access.hpp"

#include "addressing.hpp"
#include "common.hpp"
#include "companions.hpp"

namespace vsbind {

template <class Robot>
struct PyModel : CompanionModel {
  Robot robot;
  // The inertia check the model was built with: JointSpace once any part of it was accepted only
  // by that check (from_urdf or add_segment with inertia_check='joint_space'). A Solver uses it
  // unless told otherwise.
  vereshchagin::InertiaCheck inertia_check = vereshchagin::InertiaCheck::Physical;

  int segmentCount() const override { return vereshchagin::segmentCount(robot); }
  const std::string& segmentName(int index) const override { return vereshchagin::segmentName(robot, index); }
  const std::vector<vereshchagin::LinkPlacement>& linkPlacements() const override { return robot.links; }
  const std::vector<vereshchagin::JointInfo>& jointInfos() const override { return robot.joints; }
  const std::string& rootLink() const override { return robot.root_link; }

  // Rotor inertia of each joint in q order; the setter (shape (n_joints,), >= 0) rebuilds the robot.
  py::array_t<double> rotorInertia() const;
  void setRotorInertia(const py::object& values);

 protected:
  bool frameByName(const std::string& name, vereshchagin::FrameRef& out) const override {
    return vereshchagin::findFrame(robot, name, out);
  }
  int jointByName(const std::string& name) const override { return vereshchagin::findJoint(robot, name); }
  vereshchagin::Model buildModel() const override;
};

using PyChain = PyModel<vereshchagin::RobotChain>;
using PyTree = PyModel<vereshchagin::RobotTree>;

// The Python class of M (Chain or Tree) with every member the two share (model_bindings.cpp).
template <class M>
py::class_<M> bindModel(py::module_& mod, const char* name);
void bindChain(py::module_& mod);  // model_chain.cpp
void bindTree(py::module_& mod);   // model_bindings.cpp

// An inertia_check argument: 'physical' or 'joint_space', else raises (message after `where`).
vereshchagin::InertiaCheck modelCheckArg(const std::string& value, const std::string& where);

}  // namespace vsbind
