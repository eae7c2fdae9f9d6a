// The kinematics and dynamics companions of Chain and Tree (fk, jacobian, twist, fk_all,
// inverse_dynamics, mass_matrix, ...): the C++ library's kinematics.hpp and dynamics.hpp on a
// vereshchagin::Model built from the Python model at its first companion call and kept until the
// model changes (add_segment, rotor_inertia). Callers hold the GIL: one workspace per model.
#pragma once

#include <memory>

#include "vereshchagin/dynamics.hpp"

#include "addressing.hpp"
#include "common.hpp"

namespace vsbind {

struct CompanionCache {
  explicit CompanionCache(const vereshchagin::Model& m);
  vereshchagin::KinematicsData& kin() { return dyn.kinematics(); }
  vereshchagin::Model model;
  vereshchagin::DynamicsData dyn;
  vereshchagin::Matrix6X f_ext;  // scratch: 6 x n_segments
  py::ssize_t n;                 // joints
};

// What the companions need of a Python model: its names (Addressable) and its cached C++ model.
class CompanionModel : public Addressable {
 public:
  CompanionCache& companions() const;              // built at first use from buildModel()
  void invalidateCompanions() { cache_.reset(); }  // the robot changed

 protected:
  virtual vereshchagin::Model buildModel() const = 0;

 private:
  mutable std::shared_ptr<CompanionCache> cache_;
};

void bindTaskHelpers(py::module_& mod);  // _core._beta_for (companion_task.cpp)

}  // namespace vsbind
