// The shared addressing rule of Chain and Tree (addressing.hpp).
#include "addressing.hpp"

namespace vsbind {

std::string nameList(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t k = 0; k < names.size() && k < 12; ++k) out += (k ? ", '" : "'") + names[k] + "'";
  if (names.size() > 12) out += ", ... (" + std::to_string(names.size()) + " in all)";
  return out;
}

std::vector<std::string> Addressable::segmentNames() const {
  std::vector<std::string> out;
  for (int i = 0; i < segmentCount(); ++i) out.push_back(segmentName(i));
  return out;
}

std::vector<std::string> Addressable::jointNames() const {
  std::vector<std::string> out;
  for (const auto& j : jointInfos()) out.push_back(j.name);
  return out;
}

namespace {

// The int value of an index argument, or raises naming the valid range (an int beyond the C range
// is out of range like any other).
int indexInRange(PyObject* which, int n, const std::string& label, const char* what) {
  const std::optional<long long> v = intWithin(which, -n, n - 1);
  if (!v)
    raise(label + ": " + what + " index " + py::str(which).cast<std::string>() + " out of range for " +
          std::to_string(n) + " " + what + "s (valid " + std::to_string(-n) + " .. " + std::to_string(n - 1) +
          (std::string(what) == "segment" ? "; the base is addressed by its name only)" : ")"));
  return static_cast<int>(*v < 0 ? *v + n : *v);
}

}  // namespace

Addressable::Target Addressable::resolveTarget(PyObject* which, const std::string& label) const {
  const int ns = segmentCount();
  const std::string& root_link = rootLink();
  Target t;
  if (PyUnicode_Check(which)) {
    const std::string name = py::handle(which).cast<std::string>();
    vereshchagin::FrameRef ref;
    if (frameByName(name, ref)) {
      t.segment = ref.segment;  // -1: the base or a link of it
      t.link_in_tip = ref.in_tip;
      t.merged = ref.segment >= 0 && ref.in_tip.p.Norm() != 0.0;
      return t;
    }
    raise(label + ": no segment or link named '" + name + "' (segments: " + nameList(segmentNames()) +
          (root_link.empty() ? "" : "; base: '" + root_link + "'") + ")");
  }
  if (PyBool_Check(which) || !PyIndex_Check(which))
    raise(label + ": a segment is named by a str (segment or link name) or an int index, got " +
          std::string(py::str(py::type::of(py::handle(which)).attr("__name__"))));
  t.segment = indexInRange(which, ns, label, "segment");
  return t;
}

Addressable::Target Addressable::resolveOptional(const py::object& which, const std::string& label) const {
  if (!which.is_none()) return resolveTarget(which.ptr(), label);
  Target t;
  t.segment = segmentCount() - 1;
  return t;
}

Addressable::Target Addressable::resolveMoving(PyObject* which, const std::string& label) const {
  Target t = resolveTarget(which, label);
  if (t.segment < 0)
    raise(label + ": '" + py::str(which).cast<std::string>() + "' is (part of) the fixed base, not a moving segment");
  return t;
}

int Addressable::resolveJoint(PyObject* which, const std::string& label) const {
  if (PyUnicode_Check(which)) {
    const std::string name = py::handle(which).cast<std::string>();
    if (const int j = jointByName(name); j >= 0) return j;
    raise(label + ": no joint named '" + name + "' (joints: " + nameList(jointNames()) + ")");
  }
  if (PyBool_Check(which) || !PyIndex_Check(which))
    raise(label + ": a joint is named by a str or an int index, got " +
          std::string(py::str(py::type::of(py::handle(which)).attr("__name__"))));
  return indexInRange(which, static_cast<int>(jointInfos().size()), label, "joint");
}

}  // namespace vsbind
