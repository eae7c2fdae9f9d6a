// A RobotTree's floating base as plain values and back (base_state.hpp), for the pickle state.
#include "vereshchagin/base_state.hpp"

#include <cmath>
#include <cstring>

namespace vereshchagin {

static_assert(sizeof(KDL::RigidBodyInertia) == 13 * sizeof(double), "unexpected KDL::RigidBodyInertia layout");

std::array<double, 13> baseInertiaDoubles(const RobotTree& robot) {
  std::array<double, 13> out;
  std::memcpy(out.data(), static_cast<const void*>(&robot.base_inertia), sizeof out);
  return out;
}

bool setBaseState(RobotTree& robot, const std::string& kind, const std::array<double, 13>& inertia,
                  std::string& message) {
  BaseKind base;
  if (!baseKindFromName(kind, base)) {
    message = "the base must be 'fixed', 'free' or 'planar', got '" + kind + "'";
    return false;
  }
  for (const double x : inertia)
    if (!std::isfinite(x)) {
      message = "the base inertia is not finite";
      return false;
    }
  if (inertia[0] < 0.0) {
    message = "the base inertia has a negative mass";
    return false;
  }
  robot.base = base;
  std::memcpy(static_cast<void*>(&robot.base_inertia), inertia.data(), sizeof inertia);
  return true;
}

}  // namespace vereshchagin
