// The Python properties and methods Chain and Tree share (joint data, names, addressing), bound
// once for both: Model is PyChain or PyTree (an Addressable with a `robot` holding joints, links,
// root_link and notes). Docstrings: DOCS["Chain.<name>"] and DOCS["Tree.<name>"] (_docstrings.py).
#pragma once

#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "vereshchagin/inertia_check.hpp"

#include "addressing.hpp"
#include "common.hpp"

namespace vsbind {

// docOf("lower") is the docstring DOCS["Chain.lower"] or DOCS["Tree.lower"], after the class's name.
template <class Model>
auto memberDocs(const py::class_<Model>& cls) {
  const std::string prefix = cls.attr("__name__").template cast<std::string>() + ".";
  return [prefix](const char* member) { return doc(prefix + member); };
}

// The joints' names, types, limits, friction and damping, in q order.
template <class Model>
void bindJointData(py::class_<Model>& cls) {
  using vereshchagin::JointInfo;
  const auto docOf = memberDocs(cls);
  const auto field = [](double JointInfo::*f) {
    return [f](const Model& m) {
      const std::vector<JointInfo>& joints = m.jointInfos();
      py::array_t<double> a(static_cast<py::ssize_t>(joints.size()));
      for (std::size_t k = 0; k < joints.size(); ++k) a.mutable_data()[k] = joints[k].*f;
      return a;
    };
  };
  cls.def_property_readonly("joint_names", &Model::jointNames, docOf("joint_names"))
      .def_property_readonly(
          "joint_types",
          [](const Model& m) {
            std::vector<std::string> types;
            for (const auto& j : m.jointInfos()) types.push_back(j.type);
            return types;
          },
          docOf("joint_types"))
      .def_property_readonly("lower", field(&JointInfo::lower), docOf("lower"))
      .def_property_readonly("upper", field(&JointInfo::upper), docOf("upper"))
      .def_property_readonly("velocity_limit", field(&JointInfo::velocity_limit), docOf("velocity_limit"))
      .def_property_readonly("effort_limit", field(&JointInfo::effort_limit), docOf("effort_limit"))
      .def_property_readonly("friction", field(&JointInfo::friction), docOf("friction"))
      .def_property_readonly("damping", field(&JointInfo::damping), docOf("damping"));
}

// The base, the links, the notes, segment_index and joint_index.
template <class Model>
void bindNamesAndIndices(py::class_<Model>& cls) {
  const auto docOf = memberDocs(cls);
  cls.def_property_readonly(
         "root_link", [](const Model& m) { return m.rootLink(); }, docOf("root_link"))
      .def_property_readonly(
          "notes", [](const Model& m) { return m.robot.notes; }, docOf("notes"))
      .def_property_readonly(
          "inertia_check", [](const Model& m) { return vereshchagin::inertiaCheckName(m.inertia_check); },
          docOf("inertia_check"))
      .def_property_readonly(
          "link_names",
          [](const Model& m) {
            std::vector<std::string> names;
            for (const auto& l : m.linkPlacements()) names.push_back(l.link);
            return names;
          },
          docOf("link_names"))
      .def(
          "segment_index",
          [](const Model& m, const py::object& which) { return m.resolveMoving(which.ptr(), "segment_index").segment; },
          py::arg("name"), docOf("segment_index"))
      .def(
          "joint_index",
          [](const Model& m, const py::object& which) { return m.resolveJoint(which.ptr(), "joint_index"); },
          py::arg("name"), docOf("joint_index"));
}

}  // namespace vsbind
