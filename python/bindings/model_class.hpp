// The Python Chain and Tree: one template over the C++ robot (RobotChain / RobotTree) on what every
// Python call on a model shares (CompanionModel). The domain logic is the C++ library's
// (robot_access.hpp, robot_edit.hpp, robot_state.hpp).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vereshchagin/dynamics.hpp"
#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/robot_access.hpp"

#include "common.hpp"

namespace vsbind {

using O = const py::object&;  // a Python argument

// A frame resolved to a segment (-1: the base) and the frame's pose in that segment's tip frame.
struct FrameTarget {
  int segment = -1;
  KDL::Frame link_in_tip = KDL::Frame::Identity();
  bool merged = false;  // a merged link away from the tip: moments must be moved
};

// What every Python call on a Chain or Tree shares: the one addressing rule of frames and joints
// (names, looked up by robot_access.hpp, and int indices, negative from the end; messages start
// with the caller's `label`), the inertia check the model was built with, and the companions'
// (fk, jacobian, ...) Model with its workspace, built at their first call and kept until the
// robot changes (add_segment, rotor_inertia). Callers hold the GIL.
class CompanionModel {
 public:
  virtual ~CompanionModel() = default;
  virtual vereshchagin::RobotRef names() const = 0;  // the robot, for lookups and the companions

  // Any frame: segment, merged link, base link (segment -1) or index.
  [[gnu::noinline]] FrameTarget resolveTarget(PyObject* which, const std::string& label) const {
    if (!PyUnicode_Check(which)) return {indexInRange(which, names().segmentCount(), label, "segment")};
    vereshchagin::FrameRef ref;
    std::string message;
    if (!names().findFrame(py::handle(which).cast<std::string>(), ref, message)) raise(label + ": " + message);
    return {ref.segment, ref.in_tip, ref.segment >= 0 && ref.in_tip.p.Norm() != 0.0};  // -1: the base or on it
  }
  // The same for calls that need a moving segment: the base raises.
  FrameTarget resolveMoving(PyObject* which, const std::string& label) const {
    const FrameTarget t = resolveTarget(which, label);
    if (t.segment < 0)
      raise(label + ": '" + py::str(which).cast<std::string>() + "' is (part of) the fixed base, not a moving segment");
    return t;
  }
  // Joint index from a joint name or an int index (negative from the end).
  int resolveJoint(PyObject* which, const std::string& label) const {
    if (!PyUnicode_Check(which)) return indexInRange(which, static_cast<int>(jointInfos().size()), label, "joint");
    int index = -1;
    std::string message;
    if (!names().findJoint(py::handle(which).cast<std::string>(), index, message)) raise(label + ": " + message);
    return index;
  }
  const std::vector<vereshchagin::JointInfo>& jointInfos() const { return names().joints(); }

  vereshchagin::DynamicsData& companions() const {  // built at first use
    if (!cache_) cache_ = std::make_shared<vereshchagin::DynamicsData>(names().model({inertia_check}));
    return *cache_;
  }
  void invalidateCompanions() { cache_.reset(); }  // the robot changed

  // The inertia check the model was built with: JointSpace once any part of it was accepted only
  // by that check (from_urdf or add_segment with inertia_check='joint_space'). A Solver uses it
  // unless told otherwise.
  vereshchagin::InertiaCheck inertia_check = vereshchagin::InertiaCheck::Physical;

 private:
  // The int value of an index argument, or raises with robot_access.hpp's messages: the valid range
  // (an int beyond the C range is out of range like any other) or, for a non-int, what names a `what`.
  static int indexInRange(PyObject* which, int n, const std::string& label, const std::string& what) {
    if (PyBool_Check(which) || !PyIndex_Check(which))
      raise(label + ": " +
            vereshchagin::indexTypeMessage(what, py::str(py::type::of(py::handle(which)).attr("__name__"))));
    const std::optional<long long> v = intWithin(which, -n, n - 1);
    if (!v) raise(label + ": " + vereshchagin::indexRangeMessage(what, py::str(which), n));
    return static_cast<int>(*v < 0 ? *v + n : *v);
  }
  mutable std::shared_ptr<vereshchagin::DynamicsData> cache_;  // its model(): the one built
};

template <class Robot>
struct PyModel : CompanionModel {
  Robot robot;
  vereshchagin::RobotRef names() const override { return robot; }
};

using PyChain = PyModel<vereshchagin::RobotChain>;
using PyTree = PyModel<vereshchagin::RobotTree>;

}  // namespace vsbind
