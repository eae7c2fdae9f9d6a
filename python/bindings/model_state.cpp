// Pickle states of Chain and Tree as tuples of robot_state.hpp's records (read by pybind11's STL
// casters; the C++ library checks the records), and from_urdf's source argument.
#include <pybind11/stl.h>

#include "model_class.hpp"
#include "py_solver.hpp"  // inertiaCheckArg
#include "vereshchagin/robot_state.hpp"
#include "vereshchagin/urdf_loader.hpp"

namespace vsbind {

namespace {

using vereshchagin::RecordTuples;
using vereshchagin::RobotRecord;
// A state's segments: a Tree's are (segment, parent index) pairs, a Chain's segments alone.
template <bool tree>
using Segments =
    std::vector<std::conditional_t<tree, std::pair<vereshchagin::SegmentTuple, long long>, vereshchagin::SegmentTuple>>;

// The records of a state (layouts: vereshchagin/_models.py); a malformed entry raises naming `what`.
template <bool tree>
RobotRecord recordFrom(const py::tuple& state, const std::string& what) {
  RobotRecord r;
  RecordTuples t;
  try {
    if constexpr (tree)
      t.segments = state[2].template cast<Segments<tree>>();
    else
      t.segments = vereshchagin::withUnusedParents(state[1].template cast<Segments<tree>>());
    t.joints = state[tree ? 3 : 2].template cast<std::vector<vereshchagin::JointTuple>>();
    t.links = state[tree ? 4 : 3].template cast<std::vector<vereshchagin::LinkTuple>>();
    r.root_link = state[tree ? 1 : 4].template cast<std::string>();
    r.notes = state[5].template cast<std::vector<std::string>>();
  } catch (const py::cast_error&) {
    raise(what + ": malformed records (segments, joints and links must be lists of tuples of the pickled layout)");
  }
  vereshchagin::setRecordTuples(t, r);
  return r;
}

}  // namespace

template <class Model>
py::tuple modelState(const Model& model) {
  constexpr bool tree = std::is_same_v<Model, PyTree>;
  const RobotRecord r = vereshchagin::robotRecord(model.robot);
  const RecordTuples t = vereshchagin::recordTuples(r);
  const char* check = vereshchagin::inertiaCheckName(model.inertia_check);
  if constexpr (tree)
    return py::make_tuple(1, r.root_link, t.segments, t.joints, t.links, r.notes, check);
  else
    return py::make_tuple(1, vereshchagin::withoutParents(t.segments), t.joints, t.links, r.root_link, r.notes, check);
}

template <class Model>
Model modelFromState(const py::tuple& state) {
  constexpr bool tree = std::is_same_v<Model, PyTree>;
  const std::string what = tree ? "Tree state" : "Chain state";
  if ((state.size() != 6 && state.size() != 7) || !py::isinstance<py::int_>(state[0]) ||
      state[0].cast<long long>() != 1)
    raise(what + ": unknown format");
  Model model;
  std::string message;
  if (!vereshchagin::robotFromRecord(recordFrom<tree>(state, what), model.robot, message)) raise(message);
  if (state.size() == 7) model.inertia_check = inertiaCheckArg(state[6].cast<std::string>(), what + ": ");
  return model;
}

template <class Model>
Model modelFromUrdf(const py::object& source, const std::string& root, const std::string& tip,
                    const std::string& inertia_check) {
  const vereshchagin::UrdfOptions options{inertiaCheckArg(inertia_check, "")};
  if (!py::isinstance<py::str>(source) && !py::hasattr(source, "__fspath__"))
    raise("source must be URDF XML text or a file path");
  const std::string text = py::str(py::module_::import("os").attr("fspath")(source));
  auto r = [&] {
    if constexpr (std::is_same_v<Model, PyTree>)
      return vereshchagin::treeFromUrdf(text, root, options);
    else
      return vereshchagin::chainFromUrdf(text, root, tip, options);
  }();
  if (!r.ok) raise(r.message);
  Model model;
  model.robot = std::move(r.robot);
  model.inertia_check = options.inertia_check;
  return model;
}

template py::tuple modelState(const PyChain&);
template py::tuple modelState(const PyTree&);
template PyChain modelFromState(const py::tuple&);
template PyTree modelFromState(const py::tuple&);
template PyChain modelFromUrdf(const py::object&, const std::string&, const std::string&, const std::string&);
template PyTree modelFromUrdf(const py::object&, const std::string&, const std::string&, const std::string&);

}  // namespace vsbind
