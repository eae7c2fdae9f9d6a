// Python Tree: a RobotTree (KDL::Tree, segment order, parent array, joint and link metadata)
// loaded from a URDF. The solver engine reads `robot` (robot_tree.hpp states the segment and
// joint order); frames and joints are addressed by the rule of addressing.hpp, as for Chain.
#pragma once

#include <string>
#include <vector>

#include <kdl/jntarray.hpp>
#include <kdl/segment.hpp>

#include "vereshchagin/inertia_check.hpp"
#include "vereshchagin/robot_tree.hpp"

#include "addressing.hpp"
#include "chain_bindings.hpp"
#include "common.hpp"

namespace vsbind {

inline bool isPrismatic(KDL::Joint::JointType type) {
  return type == KDL::Joint::TransAxis || type == KDL::Joint::TransX || type == KDL::Joint::TransY ||
         type == KDL::Joint::TransZ;
}

struct PyTree : CompanionModel {
  vereshchagin::RobotTree robot;
  vereshchagin::InertiaCheck inertia_check = vereshchagin::InertiaCheck::Physical;  // as PyChain's

  int segmentCount() const override { return static_cast<int>(robot.segment_names.size()); }
  const std::string& segmentName(int index) const override {
    return robot.segment_names[static_cast<std::size_t>(index)];
  }
  const std::vector<vereshchagin::LinkPlacement>& linkPlacements() const override { return robot.links; }
  const std::vector<vereshchagin::JointInfo>& jointInfos() const override { return robot.joints; }
  const std::string& rootLink() const override { return robot.root_link; }

  static PyTree fromUrdf(const py::object& source, const std::string& root, vereshchagin::InertiaCheck inertia_check);
  // Pickle state: root link, segments in segment order (bit for bit) with their parent indices,
  // joint and link metadata, notes.
  py::tuple getState() const;
  static PyTree fromState(const py::tuple& state);

  // The KDL segment at a segment index, and the index of its joint in q.
  const KDL::Segment& segment(int index) const;
  unsigned int qIndex(int index) const;
  // Segment indices from the base's child down to `index`.
  std::vector<int> pathTo(int index) const;
  py::array fk(const py::object& q, const py::object& segment) const;
  py::array jacobian(const py::object& q, const py::object& segment) const;
  py::array twist(const py::object& q, const py::object& qd, const py::object& segment) const;
  // Rotor inertia of each joint in q order; the setter rebuilds the KDL::Tree with it.
  py::array_t<double> rotorInertia() const;
  void setRotorInertia(const py::object& values);
  // The serial chain from the base to a segment: that path's segments, joints and links only.
  PyChain pathChain(const py::object& tip) const;

 protected:
  vereshchagin::Model buildModel() const override;
};

void bindTree(py::module_& mod);
// Tree.inverse_dynamics, mass_matrix, ... (tree_dynamics.cpp).
void bindTreeDynamics(py::class_<PyTree>& cls);

}  // namespace vsbind
