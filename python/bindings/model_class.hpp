// The Python Chain and Tree as one template over the C++ robot (RobotChain / RobotTree) and the
// inertia check it was built with. Names and frames are resolved by addressing.hpp, the
// companions' C++ model is built on demand (companions.hpp); the domain logic is the C++
// library's (robot_access.hpp, robot_edit.hpp, robot_state.hpp).
#pragma once

#include <string>
#include <type_traits>
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
  py::array_t<double> rotorInertia() const {
    const std::vector<double> values = vereshchagin::rotorInertia(robot);
    return copyVector(values.data(), static_cast<py::ssize_t>(values.size()));
  }
  void setRotorInertia(const py::object& values) {
    const Array a = vectorArg(values, "rotor_inertia", static_cast<py::ssize_t>(robot.joints.size()));
    std::string message;
    if (!vereshchagin::setRotorInertia(robot, std::vector<double>(a.data(), a.data() + a.size()), message))
      raise(message);
    invalidateCompanions();
  }

 protected:
  bool frameByName(const std::string& name, vereshchagin::FrameRef& out) const override {
    return vereshchagin::findFrame(robot, name, out);
  }
  int jointByName(const std::string& name) const override { return vereshchagin::findJoint(robot, name); }
  // A tree's Model must order its segments as the PyTree does (the preorder of the KDL::Tree).
  vereshchagin::Model buildModel() const override {
    vereshchagin::Model model(robot, vereshchagin::ModelOptions{inertia_check});
    if constexpr (std::is_same_v<Robot, vereshchagin::RobotTree>)
      if (model.segmentNames() != robot.segment_names)
        raise("internal error: the tree's C++ model orders its segments differently");
    return model;
  }
};

using PyChain = PyModel<vereshchagin::RobotChain>;
using PyTree = PyModel<vereshchagin::RobotTree>;

// The Python classes (model_bindings.cpp): bindModel binds what Chain and Tree share.
template <class M>
py::class_<M> bindModel(py::module_& mod, const char* name);
void bindChain(py::module_& mod);  // model_chain.cpp: Joint and Chain
void bindTree(py::module_& mod);

}  // namespace vsbind
