// Python face of PyTree (tree_bindings.hpp): vereshchagin.Tree.
#include "tree_bindings.hpp"

#include <pybind11/stl.h>

#include "model_properties.hpp"
#include "py_solver.hpp"  // inertiaCheckArg

namespace vsbind {

namespace {

// Tree-only properties: sizes, segment names, the parent array, segment masses, base_name.
void bindStructure(py::class_<PyTree>& cls) {
  cls.def_property_readonly(
         "n_joints", [](const PyTree& t) { return t.robot.tree.getNrOfJoints(); }, doc("Tree.n_joints"))
      .def_property_readonly(
          "n_segments", [](const PyTree& t) { return t.segmentCount(); }, doc("Tree.n_segments"))
      .def_property_readonly("segment_names", &PyTree::segmentNames, doc("Tree.segment_names"))
      .def_property_readonly(
          "base_name", [](const PyTree& t) { return t.robot.root_link; }, doc("Tree.base_name"))
      .def_property_readonly(
          "parent",
          [](const PyTree& t) {
            py::array_t<std::int64_t> a(static_cast<py::ssize_t>(t.robot.parent.size()));
            for (std::size_t i = 0; i < t.robot.parent.size(); ++i) a.mutable_data()[i] = t.robot.parent[i];
            return a;
          },
          doc("Tree.parent"))
      .def_property_readonly(
          "segment_masses",
          [](const PyTree& t) {
            py::array_t<double> m(static_cast<py::ssize_t>(t.segmentCount()));
            for (int i = 0; i < t.segmentCount(); ++i) m.mutable_data()[i] = t.segment(i).getInertia().getMass();
            return m;
          },
          doc("Tree.segment_masses"));
}

}  // namespace

void bindTree(py::module_& mod) {
  py::class_<PyTree> cls(mod, "Tree", doc("Tree"));
  cls.def_static(
      "from_urdf",
      [](const py::object& source, const py::object& root, const std::string& inertia_check) {
        const std::string root_name = root.is_none() ? std::string() : root.cast<std::string>();
        return PyTree::fromUrdf(source, root_name, inertiaCheckArg(inertia_check, ""));
      },
      py::arg("source"), py::arg("root") = py::none(), py::arg("inertia_check") = "physical", doc("Tree.from_urdf"));
  bindStructure(cls);
  bindJointData(cls);
  bindNamesAndIndices(cls);
  cls.def("fk", &PyTree::fk, py::arg("q"), py::arg("segment"), doc("Tree.fk"))
      .def("jacobian", &PyTree::jacobian, py::arg("q"), py::arg("segment"), doc("Tree.jacobian"))
      .def("twist", &PyTree::twist, py::arg("q"), py::arg("qd"), py::arg("segment"), doc("Tree.twist"))
      .def("chain", &PyTree::pathChain, py::arg("tip"), doc("Tree.chain"));
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
