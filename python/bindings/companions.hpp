// The kinematics and dynamics companions of Chain and Tree (fk, jacobian, inverse_dynamics, ...) run
// on a vereshchagin::Model built from the Python model at its first companion call and kept, with its
// workspace, until the model changes (add_segment, rotor_inertia). Callers hold the GIL.
#pragma once

#include <memory>

#include "vereshchagin/dynamics.hpp"

#include "addressing.hpp"

namespace vsbind {

// What the companions need of a Python model: its names (Addressable) and its cached C++ model.
class CompanionModel : public Addressable {
 public:
  vereshchagin::DynamicsData& companions() const {  // built at first use from buildModel()
    if (!cache_) cache_ = std::make_shared<vereshchagin::DynamicsData>(buildModel());
    return *cache_;
  }
  void invalidateCompanions() { cache_.reset(); }  // the robot changed

 protected:
  virtual vereshchagin::Model buildModel() const = 0;

 private:
  mutable std::shared_ptr<vereshchagin::DynamicsData> cache_;  // its model(): the one built
};

}  // namespace vsbind
