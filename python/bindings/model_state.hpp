// Pickle states of model parts (KDL segments bit for bit, joint metadata, link placements) and
// the URDF source argument, shared by Chain and Tree.
#pragma once

#include <string>

#include <kdl/segment.hpp>

#include "vereshchagin/robot_chain.hpp"  // JointInfo, LinkPlacement

#include "common.hpp"

namespace vsbind {

// (name, joint name, joint type, origin, axis, rotor inertia, damping, stiffness, tip frame,
// 13 stored inertia doubles): restores the segment bit for bit.
py::tuple segmentState(const KDL::Segment& s);
KDL::Segment segmentFromState(const py::tuple& t);
py::tuple jointInfoState(const vereshchagin::JointInfo& j);
vereshchagin::JointInfo jointInfoFromState(const py::tuple& t);
py::tuple linkState(const vereshchagin::LinkPlacement& l);
vereshchagin::LinkPlacement linkFromState(const py::tuple& t);

// A URDF `source` argument (str or os.PathLike): XML text when it contains '<', else a path that
// must be readable. Raises SolverError otherwise.
struct UrdfSource {
  std::string text_or_path;
  bool is_text = false;
};
UrdfSource urdfSourceArg(const py::object& source);

}  // namespace vsbind
