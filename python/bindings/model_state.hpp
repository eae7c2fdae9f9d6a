// Pickle states of model parts (KDL segments bit for bit, joint metadata, link placements) and
// the URDF source argument, shared by Chain and Tree.
#pragma once

#include <string>
#include <vector>

#include <kdl/segment.hpp>

#include "vereshchagin/robot_chain.hpp"  // JointInfo, LinkPlacement

#include "common.hpp"

namespace vsbind {

// (name, joint name, joint type, origin, axis, rotor inertia, damping, stiffness, tip frame,
// 13 stored inertia doubles): restores the segment bit for bit.
py::tuple segmentState(const KDL::Segment& s);
// The *FromState functions check every record (sizes, types, finite values, index ranges) and
// raise SolverError naming `what`: a crafted state never reaches the solver.
KDL::Segment segmentFromState(const py::handle& t, const std::string& what);
py::tuple jointInfoState(const vereshchagin::JointInfo& j);
vereshchagin::JointInfo jointInfoFromState(const py::handle& t, const std::string& what);
py::tuple linkState(const vereshchagin::LinkPlacement& l);
vereshchagin::LinkPlacement linkFromState(const py::handle& t, const std::string& what);
// An int entry of a state record within [lo, hi] (raises naming `what` otherwise).
long long stateInt(const py::handle& obj, long long lo, long long hi, const std::string& what);
// A list entry of a state tuple (raises naming `what` otherwise).
inline py::list stateList(const py::handle& obj, const std::string& what) {
  if (!py::isinstance<py::list>(obj)) raise(what + " must be a list");
  return py::reinterpret_borrow<py::list>(obj);
}
// Joint records one per moving segment (moving_segments: their indices in order, as the model
// numbers joints), link records on segments that exist (-1: the base).
void checkStateIndices(const std::vector<vereshchagin::JointInfo>& joints,
                       const std::vector<vereshchagin::LinkPlacement>& links, const std::vector<int>& moving_segments,
                       int n_segments, const std::string& what);

// A URDF `source` argument (str or os.PathLike): XML text when it contains '<', else a path that
// must be readable. Raises SolverError otherwise.
struct UrdfSource {
  std::string text_or_path;
  bool is_text = false;
};
UrdfSource urdfSourceArg(const py::object& source);

}  // namespace vsbind
