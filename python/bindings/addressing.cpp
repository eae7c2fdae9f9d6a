// The shared addressing rule of Chain and Tree (addressing.hpp).
#include "addressing.hpp"

#include "vereshchagin/robot_access.hpp"

namespace vsbind {

namespace {

// The int value of an index argument, or raises with robot_access.hpp's messages: the valid range
// (an int beyond the C range is out of range like any other) or, for a non-int, what names a `what`.
int indexInRange(PyObject* which, int n, const std::string& label, const std::string& what) {
  if (PyBool_Check(which) || !PyIndex_Check(which))
    raise(label + ": " +
          vereshchagin::indexTypeMessage(what, py::str(py::type::of(py::handle(which)).attr("__name__"))));
  const std::optional<long long> v = intWithin(which, -n, n - 1);
  if (!v) raise(label + ": " + vereshchagin::indexRangeMessage(what, py::str(which), n));
  return static_cast<int>(*v < 0 ? *v + n : *v);
}

}  // namespace

FrameTarget Addressable::resolveTarget(PyObject* which, const std::string& label) const {
  if (!PyUnicode_Check(which)) return {indexInRange(which, segmentCount(), label, "segment")};
  vereshchagin::FrameRef ref;
  std::string message;
  if (!frameByName(py::handle(which).cast<std::string>(), ref, message)) raise(label + ": " + message);
  return {ref.segment, ref.in_tip, ref.segment >= 0 && ref.in_tip.p.Norm() != 0.0};  // -1: the base or on it
}

FrameTarget Addressable::resolveOptional(const py::object& which, const std::string& label) const {
  return which.is_none() ? FrameTarget{segmentCount() - 1} : resolveTarget(which.ptr(), label);
}

FrameTarget Addressable::resolveMoving(PyObject* which, const std::string& label) const {
  const FrameTarget t = resolveTarget(which, label);
  if (t.segment < 0)
    raise(label + ": '" + py::str(which).cast<std::string>() + "' is (part of) the fixed base, not a moving segment");
  return t;
}

int Addressable::resolveJoint(PyObject* which, const std::string& label) const {
  if (!PyUnicode_Check(which)) return indexInRange(which, static_cast<int>(jointInfos().size()), label, "joint");
  int index = -1;
  std::string message;
  if (!jointByName(py::handle(which).cast<std::string>(), index, message)) raise(label + ": " + message);
  return index;
}

}  // namespace vsbind
