// The Python properties and methods Chain and Tree share (joint data, names, addressing), bound
// once for both: Model is PyChain or PyTree (an Addressable with a `robot` holding joints, links,
// root_link and notes).
#pragma once

#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "vereshchagin/inertia_check.hpp"

#include "addressing.hpp"
#include "common.hpp"

namespace vsbind {

// The joints' names, types, limits, friction and damping, in q order.
template <class Model>
void bindJointData(py::class_<Model>& cls) {
  using vereshchagin::JointInfo;
  const auto field = [](double JointInfo::*f) {
    return [f](const Model& m) {
      const std::vector<JointInfo>& joints = m.jointInfos();
      py::array_t<double> a(static_cast<py::ssize_t>(joints.size()));
      for (std::size_t k = 0; k < joints.size(); ++k) a.mutable_data()[k] = joints[k].*f;
      return a;
    };
  };
  cls.def_property_readonly("joint_names", &Model::jointNames, "list of str: moving joint names in q order.")
      .def_property_readonly(
          "joint_types",
          [](const Model& m) {
            std::vector<std::string> types;
            for (const auto& j : m.jointInfos()) types.push_back(j.type);
            return types;
          },
          "list of str: 'revolute', 'continuous' or 'prismatic' per moving joint.")
      .def_property_readonly(
          "lower", field(&JointInfo::lower),
          "ndarray (n,): lower position limits, rad or m (-inf: none; URDF continuous joints have none).")
      .def_property_readonly("upper", field(&JointInfo::upper),
                             "ndarray (n,): upper position limits, rad or m (+inf: none).")
      .def_property_readonly(
          "velocity_limit", field(&JointInfo::velocity_limit),
          "ndarray (n,): URDF velocity limits, rad/s or m/s (inf: none). Not enforced by the solver.")
      .def_property_readonly("effort_limit", field(&JointInfo::effort_limit),
                             "ndarray (n,): URDF effort limits, N m or N (inf: none). Not enforced by the solver.")
      .def_property_readonly(
          "friction", field(&JointInfo::friction),
          "ndarray (n,): static (breakaway) friction per joint, N m or N (URDF <dynamics friction>); "
          "used by friction=True.")
      .def_property_readonly(
          "damping", field(&JointInfo::damping),
          "ndarray (n,): viscous damping per joint, N m s/rad or N s/m (URDF <dynamics damping>); not "
          "applied by the solver.");
}

// The base, the links, the notes, segment_index and joint_index.
template <class Model>
void bindNamesAndIndices(py::class_<Model>& cls, const char* notes_doc) {
  cls.def_property_readonly(
         "root_link", [](const Model& m) { return m.rootLink(); },
         "str: name of the base link (the base frame); the base is addressed by this name only.")
      .def_property_readonly(
          "notes", [](const Model& m) { return m.robot.notes; }, notes_doc)
      .def_property_readonly(
          "inertia_check", [](const Model& m) { return vereshchagin::inertiaCheckName(m.inertia_check); },
          "str: the inertia check the model was built with, 'physical' or 'joint_space' (once any part was "
          "accepted only by 'joint_space': from_kdl, or from_urdf / add_segment with that option). A Solver "
          "uses it unless given inertia_check.")
      .def_property_readonly(
          "link_names",
          [](const Model& m) {
            std::vector<std::string> names;
            for (const auto& l : m.linkPlacements()) names.push_back(l.link);
            return names;
          },
          "list of str: every URDF link of the model (segments, merged links, base links); segment and merged link "
          "names address frames in fk, jacobian, twist, constraints= and f_ext dicts; base links only in fk, jacobian "
          "and twist.")
      .def(
          "segment_index",
          [](const Model& m, const py::object& which) { return m.resolveMoving(which.ptr(), "segment_index").segment; },
          py::arg("name"), R"doc(Index of a segment.

Parameters
----------
name : str or int
    A segment name, the name of a link merged into a segment by fixed joints (its segment's
    index), or an index (negative from the end).

Returns
-------
int
    In ``0 .. n_segments - 1``.

Raises
------
SolverError
    Unknown names (the message lists the segments), indices out of range, and the base link
    (it is no segment; ``fk``, ``jacobian`` and ``twist`` accept it by name).
)doc")
      .def(
          "joint_index",
          [](const Model& m, const py::object& which) { return m.resolveJoint(which.ptr(), "joint_index"); },
          py::arg("name"), R"doc(Index of a moving joint in q.

Parameters
----------
name : str or int
    A joint name or an index (negative from the end).

Returns
-------
int
    In ``0 .. n_joints - 1``.
)doc");
}

}  // namespace vsbind
