// Validation of a parsed friction model against the Python argument names (friction.static,
// friction.kinetic, friction.velocity_tolerance, friction.lower / upper, friction.limit_tolerance),
// before any computation. The C++ FrictionSolver checks the same again (C++ field names).
#pragma once

#include <cmath>
#include <string>

#include "common.hpp"
#include "vereshchagin/friction_solver.hpp"

namespace vsbind {

inline void checkFriction(const vereshchagin::FrictionModel& fm) {
  const Eigen::Index n = fm.static_friction.size();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double fs = fm.static_friction(j);
    if (!std::isfinite(fs) || fs < 0.0)
      raise("friction.static[" + std::to_string(j) + "] must be finite and >= 0, got " + fmtDouble(fs));
    if (fm.kinetic_friction.size() == n) {
      const double fk = fm.kinetic_friction(j);
      if (!std::isfinite(fk) || fk < 0.0 || fk > fs)
        raise("friction.kinetic[" + std::to_string(j) + "] must be in [0, friction.static[" + std::to_string(j) +
              "] = " + fmtDouble(fs) + "] (kinetic <= static), got " + fmtDouble(fk));
    }
  }
  if (!std::isfinite(fm.velocity_tolerance) || fm.velocity_tolerance < 0.0)
    raise("friction.velocity_tolerance must be finite and >= 0, got " + fmtDouble(fm.velocity_tolerance));
  if (fm.lower.size() || fm.upper.size()) {
    if (!std::isfinite(fm.limit_tolerance) || fm.limit_tolerance < 0.0)
      raise("friction.limit_tolerance must be finite and >= 0, got " + fmtDouble(fm.limit_tolerance));
    for (Eigen::Index j = 0; j < fm.lower.size() && j < fm.upper.size(); ++j)
      if (!(fm.lower(j) <= fm.upper(j)))
        raise("friction.lower[" + std::to_string(j) + "] and friction.upper[" + std::to_string(j) +
              "] must satisfy lower <= upper, got " + fmtDouble(fm.lower(j)) + " > " + fmtDouble(fm.upper(j)));
  }
}

}  // namespace vsbind
