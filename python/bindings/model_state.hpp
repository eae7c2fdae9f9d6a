// Pickle states of Chain and Tree (tuples of the C++ records of robot_state.hpp, which checks
// them) and the URDF source argument of from_urdf.
#pragma once

#include <string>

#include "common.hpp"
#include "model_class.hpp"

namespace vsbind {

// An int entry of a state record within [lo, hi] (raises naming `what` otherwise).
long long stateInt(const py::handle& obj, long long lo, long long hi, const std::string& what);

// Chain: (1, segments, joints, links, root_link, notes, inertia_check); Tree: (1, root_link,
// [(segment, parent)], joints, links, notes, inertia_check). A segment: (name, joint name, joint
// type, origin, axis, rotor inertia, damping, stiffness, tip frame (12), the 13 stored inertia
// doubles), restored bit for bit; a joint: (name, type, lower, upper, velocity_limit,
// effort_limit, friction, damping, segment); a link: (name, segment, frame (12)). States of six
// entries (no inertia_check) load as 'physical'. Crafted states raise SolverError naming the record.
template <class Model>
py::tuple modelState(const Model& model);
template <class Model>
Model modelFromState(const py::tuple& state);

// Chain.from_urdf / Tree.from_urdf: `source` is URDF XML text (str holding '<') or a readable file
// path (str or os.PathLike); `tip` is unused for a Tree. Raises SolverError otherwise.
template <class Model>
Model modelFromUrdf(const py::object& source, const std::string& root, const std::string& tip,
                    const std::string& inertia_check);

}  // namespace vsbind
