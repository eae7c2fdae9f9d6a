// The kinematics and dynamics companions of Chain and Tree (fk, jacobian, twist, Jdot qd, fk_all,
// inverse_dynamics, mass_matrix, gravity_torques, coriolis_torques): argument parsing and
// messages here, the algorithms in the C++ library (kinematics.hpp, dynamics.hpp) on a
// vereshchagin::Model built from the Python model at its first companion call and kept until the
// model changes (add_segment, rotor_inertia). Callers hold the GIL: one workspace per model.
#pragma once

#include <memory>

#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/kinematics.hpp"
#include "vereshchagin/model.hpp"

#include "addressing.hpp"
#include "common.hpp"

namespace vsbind {

struct CompanionCache {
  explicit CompanionCache(const vereshchagin::Model& m);
  vereshchagin::Model model;
  vereshchagin::DynamicsData dyn;
  vereshchagin::Matrix6X f_ext;  // 6 x n_segments scratch
  vereshchagin::KinematicsData& kin() { return dyn.kinematics(); }
};

// What the companions need of a Python model: its names (Addressable) and its cached C++ model.
class CompanionModel : public Addressable {
 public:
  // The cache, built at first use from buildModel().
  CompanionCache& companions() const;
  // Drop the cache (the robot changed).
  void invalidateCompanions() { cache_.reset(); }

 protected:
  virtual vereshchagin::Model buildModel() const = 0;

 private:
  mutable std::shared_ptr<CompanionCache> cache_;
};

// Companion bodies shared by Chain and Tree. `target` is a resolved frame; q-like arguments are
// parsed with the messages of common.hpp's vectorArg.
py::array fkOf(const CompanionModel& m, const py::handle& q, const FrameTarget& target);
py::array jacobianOf(const CompanionModel& m, const py::handle& q, const FrameTarget& target);
py::array twistOf(const CompanionModel& m, const py::handle& q, const py::handle& qd, const FrameTarget& target);
py::array jacobianDotTimesQdOf(const CompanionModel& m, const py::handle& q, const py::handle& qd,
                               const FrameTarget& target);
py::array fkAllOf(const CompanionModel& m, const py::handle& q);
py::array inverseDynamicsOf(const CompanionModel& m, const py::handle& q, const py::handle& qd, const py::handle& qdd,
                            const py::object& f_ext, const py::handle& gravity);
py::array massMatrixOf(const CompanionModel& m, const py::handle& q);
py::array gravityTorquesOf(const CompanionModel& m, const py::handle& q, const py::handle& gravity);
py::array coriolisTorquesOf(const CompanionModel& m, const py::handle& q, const py::handle& qd);

// _core._beta_for: task.py's beta_for arithmetic (task.hpp), also for (N, 6) twists.
void bindTaskHelpers(py::module_& mod);
// Task.solve's beta: beta_for of the twist of `tip` at (q, qd); None for inputs task.py checks.
py::object taskBeta(const CompanionModel& m, const FrameTarget& tip, const py::handle& q, const py::handle& qd,
                    const py::handle& alpha, const py::handle& a_desired, const py::handle& gravity);

}  // namespace vsbind
