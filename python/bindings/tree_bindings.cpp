// Python face of PyTree (tree_bindings.hpp): vereshchagin.Tree.
#include "tree_bindings.hpp"

#include <pybind11/stl.h>

#include "model_properties.hpp"
#include "py_solver.hpp"  // inertiaCheckArg

namespace vsbind {

namespace {

const char* kTreeDoc = R"doc(A kinematic tree of segments (a joint followed by a rigid body), on a KDL::Tree.

Load it from a URDF with :meth:`from_urdf`: every link below the root, fixed joints merged into
their parent links exactly as :meth:`Chain.from_urdf` merges them, so every segment has a moving
joint. Segment order: depth-first preorder from the base, at every link the children in the
alphabetical order of their joints' names; ``parent[i] < i`` (-1: a child of the base). Joint
order (q) = segment order. Frames are addressed as for :class:`Chain`: segment name, merged link
name, index (negative from the end); the base only by its link name (:attr:`root_link`).
Trees pickle and copy.
)doc";

const char* kFromUrdfDoc = R"doc(Load the tree below ``root`` of a URDF (file path or XML text).

Parameters
----------
source : str or os.PathLike
    URDF XML text (anything containing '<') or the path of a URDF file.
root : str, optional
    The base link (default: the URDF's root link). Its links fixed to it form the base.
inertia_check : {'physical', 'joint_space'}
    As for :meth:`Chain.from_urdf`: 'physical' (default) rejects link inertias that no rigid
    body has; 'joint_space' accepts identified models (any symmetric inertia).

Returns
-------
Tree

Raises
------
SolverError
    Malformed XML, an unknown root link, no moving joint below it, a floating or planar joint
    below it (the message names the joint and a ``root=`` below it), invalid limits, friction,
    damping or inertias. Mimic joints are loaded as independent joints (listed in
    :attr:`notes`), as Pinocchio's URDF parser does by default.
)doc";

const char* kFkDoc = R"doc(Pose of a frame in the base frame.

Parameters
----------
q : array_like, shape (n,)
    Joint positions in q order, rad or m.
segment : str or int
    Segment name or index (negative from the end), a link merged into a segment (its own
    frame), or the base link's name (identity).

Returns
-------
ndarray, shape (4, 4)
    Homogeneous transform of the frame in the base frame (m).
)doc";

const char* kJacobianDoc = R"doc(Geometric Jacobian of a frame.

Parameters
----------
q : array_like, shape (n,)
    Joint positions in q order, rad or m.
segment : str or int
    As in :meth:`fk`.

Returns
-------
ndarray, shape (6, n)
    Rows ``[linear; angular]``: the velocity of the frame's origin and the angular velocity,
    base-frame axes, per unit joint velocity; zero columns for joints off the path from the
    base (all zero for the base).
)doc";

const char* kTwistDoc = R"doc(Velocity of a frame.

Parameters
----------
q, qd : array_like, shape (n,)
    Joint positions (rad or m) and velocities (rad/s or m/s) in q order.
segment : str or int
    As in :meth:`fk`.

Returns
-------
ndarray, shape (6,)
    ``[v; omega]``: linear velocity of the frame's origin (m/s) and angular velocity (rad/s),
    base-frame axes; ``jacobian(q, segment) @ qd``.
)doc";

const char* kChainDoc = R"doc(The serial chain from the base to a segment.

Parameters
----------
tip : str or int
    A segment (name, merged link name or index); the chain ends at that segment's tip frame.

Returns
-------
Chain
    The path's segments (bit for bit), their joints (limits, friction, damping) and merged
    links; ``root_link`` is the tree's. Segments off the path, and their masses, are left out
    (a note says so): unlike ``Chain.from_urdf(root, tip)``, which lumps side branches rigidly
    into the path, the arms of a two-arm robot become independent chains.
)doc";

// Tree-only properties: sizes, segment names, the parent array, segment masses, base_name.
void bindStructure(py::class_<PyTree>& cls) {
  cls.def_property_readonly(
         "n_joints", [](const PyTree& t) { return t.robot.tree.getNrOfJoints(); },
         "int: number of moving joints n (the length of q, qd).")
      .def_property_readonly(
          "n_segments", [](const PyTree& t) { return t.segmentCount(); },
          "int: number of segments (one per moving joint).")
      .def_property_readonly("segment_names", &PyTree::segmentNames,
                             "list of str: segment names in segment order (a segment is named after its tip link).")
      .def_property_readonly(
          "base_name", [](const PyTree& t) { return t.robot.root_link; }, "str: the same as :attr:`root_link`.")
      .def_property_readonly(
          "parent",
          [](const PyTree& t) {
            py::array_t<std::int64_t> a(static_cast<py::ssize_t>(t.robot.parent.size()));
            for (std::size_t i = 0; i < t.robot.parent.size(); ++i) a.mutable_data()[i] = t.robot.parent[i];
            return a;
          },
          "ndarray of int64 (n_segments,): index of each segment's parent segment, -1 for the children of the base; "
          "parent[i] < i.")
      .def_property_readonly(
          "segment_masses",
          [](const PyTree& t) {
            py::array_t<double> m(static_cast<py::ssize_t>(t.segmentCount()));
            for (int i = 0; i < t.segmentCount(); ++i) m.mutable_data()[i] = t.segment(i).getInertia().getMass();
            return m;
          },
          "ndarray (n_segments,): mass of each segment's rigid body (merged links included), kg.");
}

}  // namespace

void bindTree(py::module_& mod) {
  py::class_<PyTree> cls(mod, "Tree", kTreeDoc);
  cls.def_static(
      "from_urdf",
      [](const py::object& source, const py::object& root, const std::string& inertia_check) {
        const std::string root_name = root.is_none() ? std::string() : root.cast<std::string>();
        return PyTree::fromUrdf(source, root_name, inertiaCheckArg(inertia_check, ""));
      },
      py::arg("source"), py::arg("root") = py::none(), py::arg("inertia_check") = "physical", kFromUrdfDoc);
  bindStructure(cls);
  bindJointData(cls);
  bindNamesAndIndices(cls,
                      "list of str: approximations made while building the tree (mimic joints modelled as "
                      "independent joints).");
  cls.def("fk", &PyTree::fk, py::arg("q"), py::arg("segment"), kFkDoc)
      .def("jacobian", &PyTree::jacobian, py::arg("q"), py::arg("segment"), kJacobianDoc)
      .def("twist", &PyTree::twist, py::arg("q"), py::arg("qd"), py::arg("segment"), kTwistDoc)
      .def("chain", &PyTree::pathChain, py::arg("tip"), kChainDoc);
  bindTreeDynamics(cls);
  cls.def(py::pickle([](const PyTree& t) { return t.getState(); },
                     [](const py::tuple& s) { return PyTree::fromState(s); }))
      .def("__copy__", [](const PyTree& t) { return t; })
      .def(
          "__deepcopy__", [](const PyTree& t, const py::dict&) { return t; }, py::arg("memo"))
      .def("__repr__", [](const PyTree& t) {
        return "<vereshchagin.Tree with " + std::to_string(t.segmentCount()) + " segments, " +
               std::to_string(t.robot.tree.getNrOfJoints()) + " joints, base '" + t.robot.root_link + "'>";
      });
}

}  // namespace vsbind
