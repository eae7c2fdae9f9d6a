#include "chain_bindings.hpp"

#include <pybind11/stl.h>

#include "dynamics_common.hpp"
#include "model_properties.hpp"
#include "model_state.hpp"
#include "py_solver.hpp"  // inertiaCheckArg
#include "vereshchagin/urdf_loader.hpp"

namespace vsbind {

PyChain PyChain::fromUrdf(const py::object& source, const std::string& root, const std::string& tip,
                          vereshchagin::InertiaCheck inertia_check) {
  const UrdfSource src = urdfSourceArg(source);
  vereshchagin::UrdfOptions options;
  options.inertia_check = inertia_check;
  const vereshchagin::UrdfResult r = src.is_text
                                         ? vereshchagin::chainFromUrdfString(src.text_or_path, root, tip, options)
                                         : vereshchagin::chainFromUrdfFile(src.text_or_path, root, tip, options);
  if (!r.ok) raise(r.message);
  PyChain c;
  c.robot = r.robot;
  c.inertia_check = inertia_check;
  return c;
}

void PyChain::addSegment(const std::string& name, const py::object& joint, const py::object& tip,
                         const py::object& mass_obj, const py::object& com, const py::object& inertia,
                         const py::object& rotor_obj, const std::string& joint_name, const std::string& inertia_check) {
  const bool physical =
      inertiaCheckArg(inertia_check, "segment '" + name + "': ") == vereshchagin::InertiaCheck::Physical;
  const vereshchagin::InertiaCheck model_check =
      physical ? this->inertia_check : vereshchagin::InertiaCheck::JointSpace;
  // Every failure names the segment and the argument: "segment 'link3': mass must be ...".
  const std::string where = "segment '" + name + "': ";
  const std::string jname = joint_name.empty() ? name + "_joint" : joint_name;
  if (name.empty()) raise("name: a segment needs a non-empty name");
  for (const std::string& other : segmentNames())
    if (other == name) raise("name: a segment named '" + name + "' already exists (names must be unique)");
  for (const auto& j : robot.joints)
    if (j.name == jname)
      raise(where + "joint_name: a joint named '" + jname + "' already exists (names must be unique)");
  const double mass = scalarArg(mass_obj, (where + "mass").c_str());
  const double rotor_inertia = scalarArg(rotor_obj, (where + "rotor_inertia").c_str());
  JointSpec spec;
  if (py::isinstance<py::str>(joint)) {
    spec = jointFromString(joint.cast<std::string>());
  } else if (py::isinstance<JointSpec>(joint)) {
    spec = joint.cast<JointSpec>();
  } else {
    raise("joint must be a joint-type string such as 'rot_z' or a vereshchagin.Joint");
  }
  const KDL::Frame f_tip = tip.is_none() ? KDL::Frame::Identity() : frameFrom4x4(tip, (where + "tip").c_str());
  if (!std::isfinite(mass) || mass < 0.0) raise(where + "mass must be finite and >= 0, got " + fmtDouble(mass));
  const KDL::Vector c = com.is_none() ? KDL::Vector::Zero() : vec3(com, (where + "com").c_str());
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  if (!inertia.is_none()) {
    Array a = toArray(inertia, (where + "inertia").c_str());
    if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
      raise(where + "inertia must be a 3x3 matrix (about the centre of mass, tip-frame axes), got shape " +
            shapeStr(a));
    requireFinite(a, (where + "inertia").c_str());
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) I(r, k) = a.at(r, k);
  }
  const double scale = std::max(1.0, I.cwiseAbs().maxCoeff());
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) raise(where + "inertia must be symmetric");
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(I, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d moments = es.eigenvalues();  // ascending
  if (physical && moments(0) < -1e-12 * scale)
    raise(where + "inertia must be positive semi-definite (smallest eigenvalue " + std::to_string(moments(0)) +
          "); identified models with such inertias: inertia_check='joint_space'");
  if (physical && moments(0) + moments(1) < moments(2) - 1e-6 * std::abs(moments(2)))
    raise(where + "inertia's principal moments " + fmtDouble(moments(0)) + ", " + fmtDouble(moments(1)) + ", " +
          fmtDouble(moments(2)) +
          " violate the triangle inequality I1 + I2 >= I3 (no rigid body has them); "
          "identified models: inertia_check='joint_space'");
  if (!std::isfinite(rotor_inertia) || rotor_inertia < 0.0)
    raise(where + "rotor_inertia must be finite and >= 0, got " + fmtDouble(rotor_inertia));
  if (spec.type == KDL::Joint::Fixed && rotor_inertia != 0.0) raise(where + "rotor_inertia: a fixed joint has none");
  KDL::Joint j = spec.has_axis ? KDL::Joint(jname, spec.origin, spec.axis, spec.type, 1.0, 0.0, rotor_inertia)
                               : KDL::Joint(jname, spec.type, 1.0, 0.0, rotor_inertia);
  const KDL::RotationalInertia Ic(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
  const unsigned int seg = robot.chain.getNrOfSegments();
  robot.chain.addSegment(KDL::Segment(name, j, f_tip, KDL::RigidBodyInertia(mass, c, Ic)));
  robot.links.push_back({name, static_cast<int>(seg), KDL::Frame::Identity()});
  invalidateCompanions();
  this->inertia_check = model_check;  // after every check passed
  if (spec.type != KDL::Joint::Fixed) {
    vereshchagin::JointInfo info;
    info.name = jname;
    const bool prismatic = spec.type == KDL::Joint::TransX || spec.type == KDL::Joint::TransY ||
                           spec.type == KDL::Joint::TransZ || spec.type == KDL::Joint::TransAxis;
    info.type = prismatic ? "prismatic" : "continuous";
    info.segment = seg;
    robot.joints.push_back(info);
  }
}

py::array_t<double> PyChain::rotorInertia() const {
  py::array_t<double> a(static_cast<py::ssize_t>(robot.joints.size()));
  for (size_t k = 0; k < robot.joints.size(); ++k)
    a.mutable_data()[k] = robot.chain.getSegment(robot.joints[k].segment).getJoint().getInertia();
  return a;
}

void PyChain::setRotorInertia(const py::object& values) {
  const Array a = rotorInertiaArg(values, robot.joints.size());
  KDL::Chain rebuilt;
  size_t jk = 0;
  for (unsigned int i = 0; i < robot.chain.getNrOfSegments(); ++i) {
    const KDL::Segment& seg = robot.chain.getSegment(i);
    const KDL::Joint& j = seg.getJoint();
    const KDL::Joint nj =
        j.getType() == KDL::Joint::Fixed ? j : withRotorInertia(j, a.at(static_cast<py::ssize_t>(jk++)));
    rebuilt.addSegment(KDL::Segment(seg.getName(), nj, seg.getFrameToTip(), seg.getInertia()));
  }
  robot.chain = rebuilt;
  invalidateCompanions();
}

py::array PyChain::fk(const py::object& q_obj, const py::object& segment) const {
  return fkOf(*this, q_obj, resolveOptional(segment, "segment"));
}

py::array PyChain::jacobian(const py::object& q_obj, const py::object& segment) const {
  return jacobianOf(*this, q_obj, resolveOptional(segment, "segment"));
}

py::array PyChain::twist(const py::object& q_obj, const py::object& qd_obj, const py::object& segment) const {
  return twistOf(*this, q_obj, qd_obj, resolveOptional(segment, "segment"));
}

vereshchagin::Model PyChain::buildModel() const {
  vereshchagin::ModelOptions options;
  options.inertia_check = inertia_check;
  return vereshchagin::Model(robot, options);
}

py::tuple PyChain::getState() const {
  py::list segments, joints, links;
  for (unsigned int i = 0; i < robot.chain.getNrOfSegments(); ++i)
    segments.append(segmentState(robot.chain.getSegment(i)));
  for (const auto& j : robot.joints) joints.append(jointInfoState(j));
  for (const auto& l : robot.links) links.append(linkState(l));
  return py::make_tuple(1, segments, joints, links, robot.root_link, py::cast(robot.notes),
                        vereshchagin::inertiaCheckName(inertia_check));
}

PyChain PyChain::fromState(const py::tuple& state) {
  if ((state.size() != 6 && state.size() != 7) || !py::isinstance<py::int_>(state[0]) ||
      state[0].cast<long long>() != 1)
    raise("Chain state: unknown format");
  PyChain c;
  std::vector<int> moving;
  int i = 0;
  for (const auto& item : stateList(state[1], "Chain state: segments")) {
    const KDL::Segment s = segmentFromState(item, "Chain state: segment " + std::to_string(i));
    if (s.getJoint().getType() != KDL::Joint::Fixed) moving.push_back(i);
    c.robot.chain.addSegment(s);
    ++i;
  }
  for (const auto& item : stateList(state[2], "Chain state: joints"))
    c.robot.joints.push_back(jointInfoFromState(item, "Chain state: joint record"));
  for (const auto& item : stateList(state[3], "Chain state: links"))
    c.robot.links.push_back(linkFromState(item, "Chain state: link record"));
  checkStateIndices(c.robot.joints, c.robot.links, moving, c.segmentCount(), "Chain state");
  c.robot.root_link = state[4].cast<std::string>();
  c.robot.notes = state[5].cast<std::vector<std::string>>();
  if (state.size() == 7) c.inertia_check = inertiaCheckArg(state[6].cast<std::string>(), "Chain state: ");
  return c;
}

namespace {

// Joint: the joint types of Chain.add_segment.
void bindJointSpec(py::module_& mod) {
  py::class_<JointSpec>(mod, "Joint", doc("Joint"))
      .def_static(
          "revolute",
          [](const py::object& axis, const py::object& origin) {
            return makeAxisJoint(KDL::Joint::RotAxis, axis, origin);
          },
          py::arg("axis"), py::arg("origin") = py::none(), doc("Joint.revolute"))
      .def_static(
          "prismatic",
          [](const py::object& axis, const py::object& origin) {
            return makeAxisJoint(KDL::Joint::TransAxis, axis, origin);
          },
          py::arg("axis"), py::arg("origin") = py::none(), doc("Joint.prismatic"))
      .def_static(
          "fixed", []() { return JointSpec(); }, doc("Joint.fixed"))
      .def("__repr__", &JointSpec::repr);
}

// fk, jacobian and twist of any segment (or link) of a Chain.
void bindChainKinematics(py::class_<PyChain>& cls) {
  cls.def("fk", &PyChain::fk, py::arg("q"), py::arg("segment") = py::none(), doc("Chain.fk"))
      .def("jacobian", &PyChain::jacobian, py::arg("q"), py::arg("segment") = py::none(), doc("Chain.jacobian"))
      .def("twist", &PyChain::twist, py::arg("q"), py::arg("qd"), py::arg("segment") = py::none(), doc("Chain.twist"));
}

}  // namespace

void bindChain(py::module_& mod) {
  bindJointSpec(mod);

  py::class_<PyChain> cls(mod, "Chain", doc("Chain"));
  bindJointData(cls);
  bindNamesAndIndices(cls);
  cls.def(py::init<>())
      .def("add_segment", &PyChain::addSegment, doc("Chain.add_segment"), py::arg("name"), py::arg("joint"),
           py::arg("tip") = py::none(), py::arg("mass") = 0.0, py::arg("com") = py::none(),
           py::arg("inertia") = py::none(), py::arg("rotor_inertia") = 0.0, py::arg("joint_name") = "",
           py::arg("inertia_check") = "physical")
      .def_static(
          "from_urdf",
          [](const py::object& source, const std::string& root, const std::string& tip,
             const std::string& inertia_check) {
            return PyChain::fromUrdf(source, root, tip, inertiaCheckArg(inertia_check, ""));
          },
          py::arg("source"), py::arg("root") = "", py::arg("tip") = "", py::arg("inertia_check") = "physical",
          doc("Chain.from_urdf"))
      .def_property_readonly(
          "n_joints", [](const PyChain& c) { return c.robot.chain.getNrOfJoints(); }, doc("Chain.n_joints"))
      .def_property_readonly(
          "n_segments", [](const PyChain& c) { return c.robot.chain.getNrOfSegments(); }, doc("Chain.n_segments"))
      .def_property_readonly("segment_names", &PyChain::segmentNames, doc("Chain.segment_names"))
      .def_property("rotor_inertia", &PyChain::rotorInertia, &PyChain::setRotorInertia, doc("Chain.rotor_inertia"))
      .def_property_readonly(
          "segment_masses",
          [](const PyChain& c) {
            py::array_t<double> m(static_cast<py::ssize_t>(c.robot.chain.getNrOfSegments()));
            for (unsigned int i = 0; i < c.robot.chain.getNrOfSegments(); ++i)
              m.mutable_data()[i] = c.robot.chain.getSegment(i).getInertia().getMass();
            return m;
          },
          doc("Chain.segment_masses"));
  bindChainKinematics(cls);
  cls.def(py::pickle([](const PyChain& c) { return c.getState(); },
                     [](const py::tuple& t) { return PyChain::fromState(t); }))
      .def("__copy__", [](const PyChain& c) { return c; })
      .def(
          "__deepcopy__", [](const PyChain& c, const py::dict&) { return c; }, py::arg("memo"))
      .def("__repr__", [](const PyChain& c) {
        return "<vereshchagin.Chain with " + std::to_string(c.robot.chain.getNrOfSegments()) + " segments, " +
               std::to_string(c.robot.chain.getNrOfJoints()) + " joints>";
      });
}

}  // namespace vsbind
