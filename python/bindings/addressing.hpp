// One addressing rule for every Python call that names a frame or a joint, shared by Chain and
// Tree: a segment name, a link merged into a segment by fixed joints (its pose in that segment's
// tip frame), the base link by its own name (segment -1), or an int index (negative from the
// end); joints by name or index. The lookups and their messages are the C++ library's
// (robot_access.hpp); error messages start with the caller's `label`.
#pragma once

#include <string>
#include <vector>

#include <kdl/frames.hpp>

#include "vereshchagin/model.hpp"        // FrameRef
#include "vereshchagin/robot_chain.hpp"  // JointInfo
#include "vereshchagin/status.hpp"

#include "common.hpp"

namespace vsbind {

// A frame resolved to a segment (-1: the base) and the frame's pose in that segment's tip frame.
struct FrameTarget {
  int segment = -1;
  KDL::Frame link_in_tip = KDL::Frame::Identity();
  bool merged = false;  // a merged link away from the tip: moments must be moved
};

// The names of a model (as the derived type stores them) and the rule that resolves them.
class Addressable {
 public:
  virtual ~Addressable() = default;
  virtual int segmentCount() const = 0;
  virtual const std::string& segmentName(int index) const = 0;
  virtual const std::vector<vereshchagin::JointInfo>& jointInfos() const = 0;

  // Any frame: segment, merged link, base link (segment -1) or index.
  FrameTarget resolveTarget(PyObject* which, const std::string& label) const;
  // The same for calls that need a moving segment: the base raises.
  FrameTarget resolveMoving(PyObject* which, const std::string& label) const;
  // resolveTarget, with None meaning the last segment (the default of Chain.fk, jacobian, ...).
  FrameTarget resolveOptional(const py::object& which, const std::string& label) const;
  // Joint index from a joint name or an int index (negative from the end).
  int resolveJoint(PyObject* which, const std::string& label) const;

 protected:
  // robot_access.hpp's findFrame and findJoint with their messages.
  using Status = vereshchagin::Status;
  virtual Status frameByName(const std::string& name, vereshchagin::FrameRef& out, std::string& message) const = 0;
  virtual Status jointByName(const std::string& name, int& index, std::string& message) const = 0;
};

}  // namespace vsbind
