// The members of PyModel (model_class.hpp) for Chain and Tree: rotor inertia, the companions'
// C++ model, and the inertia_check argument.
#include "model_class.hpp"

#include <type_traits>

namespace vsbind {

template <class Robot>
py::array_t<double> PyModel<Robot>::rotorInertia() const {
  const std::vector<double> values = vereshchagin::rotorInertia(robot);
  return copyVector(values.data(), static_cast<py::ssize_t>(values.size()));
}

template <class Robot>
void PyModel<Robot>::setRotorInertia(const py::object& values) {
  const Array a = vectorArg(values, "rotor_inertia", static_cast<py::ssize_t>(robot.joints.size()));
  std::string message;
  if (!vereshchagin::setRotorInertia(robot, std::vector<double>(a.data(), a.data() + a.size()), message))
    raise(message);
  invalidateCompanions();
}

// A tree's Model orders its segments as the PyTree does (the preorder of the KDL::Tree).
template <class Robot>
vereshchagin::Model PyModel<Robot>::buildModel() const {
  vereshchagin::ModelOptions options;
  options.inertia_check = inertia_check;
  vereshchagin::Model model(robot, options);
  if constexpr (std::is_same_v<Robot, vereshchagin::RobotTree>)
    if (model.segmentNames() != robot.segment_names)
      raise("internal error: the tree's C++ model orders its segments differently");
  return model;
}

template struct PyModel<vereshchagin::RobotChain>;
template struct PyModel<vereshchagin::RobotTree>;

vereshchagin::InertiaCheck modelCheckArg(const std::string& value, const std::string& where) {
  if (value == "physical") return vereshchagin::InertiaCheck::Physical;
  if (value == "joint_space") return vereshchagin::InertiaCheck::JointSpace;
  raise(where +
        "inertia_check must be 'physical' (every body a rigid body) or 'joint_space' (identified models: "
        "any symmetric inertia, H(q) positive definite at each solve), got '" +
        value + "'");
}

}  // namespace vsbind
