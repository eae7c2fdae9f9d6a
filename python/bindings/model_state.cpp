// Pickle states of model parts and the URDF source argument (model_state.hpp).
#include "model_state.hpp"

#include <cstring>
#include <fstream>

namespace vsbind {

namespace {

// KDL::RigidBodyInertia keeps (m, m c, I about the reference point); its public constructor takes
// the inertia about the centre of mass and would round the stored values differently. The
// state copies the 13 stored doubles so a pickled chain solves bit for bit like the original.
static_assert(sizeof(KDL::RigidBodyInertia) == 13 * sizeof(double), "unexpected KDL::RigidBodyInertia layout");

py::tuple inertiaState(const KDL::RigidBodyInertia& I) {
  double raw[13];
  std::memcpy(raw, static_cast<const void*>(&I), sizeof(raw));
  py::tuple t(13);
  for (int k = 0; k < 13; ++k) t[k] = raw[k];
  return t;
}

KDL::RigidBodyInertia inertiaFromState(const py::tuple& t) {
  double raw[13];
  for (int k = 0; k < 13; ++k) raw[k] = t[k].cast<double>();
  KDL::RigidBodyInertia I;
  std::memcpy(static_cast<void*>(&I), raw, sizeof(raw));
  return I;
}

py::tuple frameState(const KDL::Frame& f) {
  return py::make_tuple(f.M(0, 0), f.M(0, 1), f.M(0, 2), f.M(1, 0), f.M(1, 1), f.M(1, 2), f.M(2, 0), f.M(2, 1),
                        f.M(2, 2), f.p.x(), f.p.y(), f.p.z());
}

KDL::Frame frameFromState(const py::tuple& t) {
  auto d = [&](int k) { return t[k].cast<double>(); };
  return KDL::Frame(KDL::Rotation(d(0), d(1), d(2), d(3), d(4), d(5), d(6), d(7), d(8)),
                    KDL::Vector(d(9), d(10), d(11)));
}

py::tuple vectorState(const KDL::Vector& v) {
  return py::make_tuple(v.x(), v.y(), v.z());
}
KDL::Vector vectorFromState(const py::tuple& t) {
  return KDL::Vector(t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>());
}

}  // namespace

py::tuple segmentState(const KDL::Segment& s) {
  const KDL::Joint& j = s.getJoint();
  return py::make_tuple(s.getName(), j.getName(), static_cast<int>(j.getType()), vectorState(j.JointOrigin()),
                        vectorState(j.JointAxis()), j.getInertia(), j.getDamping(), j.getStiffness(),
                        frameState(s.getFrameToTip()), inertiaState(s.getInertia()));
}

KDL::Segment segmentFromState(const py::tuple& t) {
  const auto type = static_cast<KDL::Joint::JointType>(t[2].cast<int>());
  const std::string jname = t[1].cast<std::string>();
  const double rotor = t[5].cast<double>(), damping = t[6].cast<double>(), stiffness = t[7].cast<double>();
  const KDL::Joint j =
      (type == KDL::Joint::RotAxis || type == KDL::Joint::TransAxis)
          ? KDL::Joint(jname, vectorFromState(t[3].cast<py::tuple>()), vectorFromState(t[4].cast<py::tuple>()), type,
                       1.0, 0.0, rotor, damping, stiffness)
          : KDL::Joint(jname, type, 1.0, 0.0, rotor, damping, stiffness);
  return KDL::Segment(t[0].cast<std::string>(), j, frameFromState(t[8].cast<py::tuple>()),
                      inertiaFromState(t[9].cast<py::tuple>()));
}

py::tuple jointInfoState(const vereshchagin::JointInfo& j) {
  return py::make_tuple(j.name, j.type, j.lower, j.upper, j.velocity_limit, j.effort_limit, j.friction, j.damping,
                        j.segment);
}

vereshchagin::JointInfo jointInfoFromState(const py::tuple& t) {
  vereshchagin::JointInfo j;
  j.name = t[0].cast<std::string>();
  j.type = t[1].cast<std::string>();
  j.lower = t[2].cast<double>();
  j.upper = t[3].cast<double>();
  j.velocity_limit = t[4].cast<double>();
  j.effort_limit = t[5].cast<double>();
  j.friction = t[6].cast<double>();
  j.damping = t[7].cast<double>();
  j.segment = t[8].cast<unsigned int>();
  return j;
}

py::tuple linkState(const vereshchagin::LinkPlacement& l) {
  return py::make_tuple(l.link, l.segment, frameState(l.in_segment_tip));
}

vereshchagin::LinkPlacement linkFromState(const py::tuple& t) {
  return {t[0].cast<std::string>(), t[1].cast<int>(), frameFromState(t[2].cast<py::tuple>())};
}

UrdfSource urdfSourceArg(const py::object& source) {
  if (!py::isinstance<py::str>(source) && !py::hasattr(source, "__fspath__"))
    raise("source must be URDF XML text or a file path");
  UrdfSource out;
  out.text_or_path = py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>();
  out.is_text = out.text_or_path.find('<') != std::string::npos;
  if (!out.is_text) {
    std::ifstream probe(out.text_or_path);
    if (!probe) raise("URDF source is neither XML text nor a readable file: '" + out.text_or_path + "'");
  }
  return out;
}

}  // namespace vsbind
