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

using O = const py::object&;  // a Python argument

template <class Robot>
struct PyModel : CompanionModel {
  Robot robot;
  // The inertia check the model was built with: JointSpace once any part of it was accepted only
  // by that check (from_urdf or add_segment with inertia_check='joint_space'). A Solver uses it
  // unless told otherwise.
  vereshchagin::InertiaCheck inertia_check = vereshchagin::InertiaCheck::Physical;

  int segmentCount() const override { return vereshchagin::segmentCount(robot); }
  const std::string& segmentName(int index) const override { return vereshchagin::segmentName(robot, index); }
  const std::vector<vereshchagin::JointInfo>& jointInfos() const override { return robot.joints; }

 protected:
  Status frameByName(const std::string& name, vereshchagin::FrameRef& out, std::string& message) const override {
    return vereshchagin::findFrame(robot, name, out, message);
  }
  Status jointByName(const std::string& name, int& index, std::string& message) const override {
    return vereshchagin::findJoint(robot, name, index, message);
  }
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

// Pickle states (model_state.cpp; their layout: vereshchagin/_models.py's module docstring).
// Crafted states raise SolverError naming the record ("Chain state: ...", "Tree state: ...").
template <class Model>
py::tuple modelState(const Model& model);
template <class Model>
Model modelFromState(const py::tuple& state);

// Chain.from_urdf / Tree.from_urdf: `source` is URDF XML text (str holding '<') or a readable file
// path (str or os.PathLike); `tip` is unused for a Tree. Raises SolverError otherwise.
template <class Model>
Model modelFromUrdf(const py::object& source, const std::string& root, const std::string& tip,
                    const std::string& inertia_check);

}  // namespace vsbind
