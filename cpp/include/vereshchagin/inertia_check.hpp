/// @file
/// Which inertial parameters a model may have: the choice shared by ChainHdSolver (SolverOptions)
/// and the URDF loader (UrdfOptions).
#pragma once

#include <string>

#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// Which inertial parameters a model may have (see the top of this file).
enum class InertiaCheck {
  /// Every body must be a rigid body: mass >= 0 and a rotational inertia about its centre of mass
  /// that is symmetric, positive semi-definite and whose principal moments obey the triangle
  /// inequality I1 + I2 >= I3 (a PSD tensor such as diag(0.1, 0.01, 0.01) belongs to no mass
  /// distribution). Checked once, when the model is built. The default of this library's own
  /// classes. Tolerances, relative to the body's own inertia scale
  ///     s = max(max |I_ij|, m x (1 m)^2, the size of the terms I was computed from),  t = 1e-12 s:
  /// symmetric to t, every principal moment >= -t, and I1 + I2 >= I3 - max(1e-6 I3, t) (1e-6 for
  /// rounded model files). So a tensor of round-off (iCub's l_ankle_2 in example-robot-data:
  /// moments -1.4e-20, 0, 1.4e-20 kg m^2 for 0.27 kg) passes, while a real violation (the Allegro
  /// hand's link_3.0: moments 2.3e-6, 3.5e-6, 7.3e-6 kg m^2) is refused, naming JointSpace.
  Physical,
  /// Identified models (parameters fitted on the real arm, e.g. the KUKA LWR 4 of Jubien, Gautier
  /// and Janot, IFAC 2014) often have link inertias that are not positive semi-definite; only the
  /// joint-space inertia matrix H(q) is positive definite. Accepted: mass >= 0 and any symmetric
  /// rotational inertia. At each solve every joint's articulated inertia D_j must be > 0 (which
  /// holds exactly when H(q) is positive definite), else the solve fails with
  /// ChainHdSolver::E_DEGENERATE_INERTIA and a message naming the joint. KDL's behaviour, minus
  /// its NaNs.
  JointSpace,
};

/// "physical" / "joint_space" (the Python spelling), for messages.
inline const char* inertiaCheckName(InertiaCheck check) {
  return check == InertiaCheck::Physical ? "physical" : "joint_space";
}

/// Sets `out` from its Python spelling, "physical" or "joint_space". Any other `name` leaves `out`
/// as it is and returns Error::InvalidOptions with the message "inertia_check must be 'physical'
/// (...) or 'joint_space' (...)" (the caller appends the value it got).
inline Status parseInertiaCheck(const std::string& name, InertiaCheck& out) {
  if (name == "physical" || name == "joint_space") {
    out = name == "physical" ? InertiaCheck::Physical : InertiaCheck::JointSpace;
    return {};
  }
  return {Error::InvalidOptions,
          "inertia_check must be 'physical' (every body a rigid body) or 'joint_space' (identified models: any "
          "symmetric inertia, H(q) positive definite at each solve)"};
}

}  // namespace vereshchagin
