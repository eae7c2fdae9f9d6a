// Pickle states of model parts and the URDF source argument (model_state.hpp).
#include "model_state.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

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

// A state record: a tuple of exactly n entries.
py::tuple record(const py::handle& obj, std::size_t n, const std::string& what) {
  if (!py::isinstance<py::tuple>(obj) || py::len(obj) != n)
    raise(what + " must be a tuple of " + std::to_string(n) + " entries");
  return py::reinterpret_borrow<py::tuple>(obj);
}

// The entries of a state tuple as doubles: exactly `n` finite reals, or raises naming `what`.
void finiteEntries(const py::handle& obj, std::size_t n, const std::string& what, double* out) {
  const py::tuple t = record(obj, n, what);
  for (std::size_t k = 0; k < n; ++k) {
    out[k] = t[k].cast<double>();
    if (!std::isfinite(out[k])) raise(what + " holds a non-finite value");
  }
}

KDL::RigidBodyInertia inertiaFromState(const py::handle& obj, const std::string& what) {
  double raw[13];
  finiteEntries(obj, 13, what + " inertia", raw);
  if (raw[0] < 0.0) raise(what + " inertia has a negative mass");
  KDL::RigidBodyInertia I;
  std::memcpy(static_cast<void*>(&I), raw, sizeof(raw));
  return I;
}

py::tuple frameState(const KDL::Frame& f) {
  return py::make_tuple(f.M(0, 0), f.M(0, 1), f.M(0, 2), f.M(1, 0), f.M(1, 1), f.M(1, 2), f.M(2, 0), f.M(2, 1),
                        f.M(2, 2), f.p.x(), f.p.y(), f.p.z());
}

KDL::Frame frameFromState(const py::handle& obj, const std::string& what) {
  double d[12];
  finiteEntries(obj, 12, what, d);
  return KDL::Frame(KDL::Rotation(d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7], d[8]),
                    KDL::Vector(d[9], d[10], d[11]));
}

py::tuple vectorState(const KDL::Vector& v) {
  return py::make_tuple(v.x(), v.y(), v.z());
}
KDL::Vector vectorFromState(const py::handle& obj, const std::string& what) {
  double d[3];
  finiteEntries(obj, 3, what, d);
  return KDL::Vector(d[0], d[1], d[2]);
}

}  // namespace

long long stateInt(const py::handle& obj, long long lo, long long hi, const std::string& what) {
  if (PyBool_Check(obj.ptr()) || !PyLong_Check(obj.ptr())) raise(what + " must be an int");
  const std::optional<long long> v = intWithin(obj.ptr(), lo, hi);
  if (!v) raise(what + " is out of range (" + std::to_string(lo) + " .. " + std::to_string(hi) + ")");
  return *v;
}

py::tuple segmentState(const KDL::Segment& s) {
  const KDL::Joint& j = s.getJoint();
  return py::make_tuple(s.getName(), j.getName(), static_cast<int>(j.getType()), vectorState(j.JointOrigin()),
                        vectorState(j.JointAxis()), j.getInertia(), j.getDamping(), j.getStiffness(),
                        frameState(s.getFrameToTip()), inertiaState(s.getInertia()));
}

KDL::Segment segmentFromState(const py::handle& obj, const std::string& what) {
  const py::tuple t = record(obj, 10, what);
  const auto type =
      static_cast<KDL::Joint::JointType>(stateInt(t[2], KDL::Joint::RotAxis, KDL::Joint::Fixed, what + " joint type"));
  const std::string jname = t[1].cast<std::string>();
  double params[3];  // rotor inertia, damping, stiffness
  for (int k = 0; k < 3; ++k) {
    params[k] = t[5 + k].cast<double>();
    if (!std::isfinite(params[k])) raise(what + " joint parameters must be finite");
  }
  if (params[0] < 0.0) raise(what + " rotor inertia must be >= 0");
  const KDL::Vector origin = vectorFromState(t[3], what + " joint origin"),
                    axis = vectorFromState(t[4], what + " joint axis");
  const bool has_axis = type == KDL::Joint::RotAxis || type == KDL::Joint::TransAxis;
  if (has_axis && !(axis.Norm() > 0.0)) raise(what + " joint axis must be non-zero");
  const KDL::Joint j = has_axis ? KDL::Joint(jname, origin, axis, type, 1.0, 0.0, params[0], params[1], params[2])
                                : KDL::Joint(jname, type, 1.0, 0.0, params[0], params[1], params[2]);
  return KDL::Segment(t[0].cast<std::string>(), j, frameFromState(t[8], what + " tip frame"),
                      inertiaFromState(t[9], what));
}

py::tuple jointInfoState(const vereshchagin::JointInfo& j) {
  return py::make_tuple(j.name, j.type, j.lower, j.upper, j.velocity_limit, j.effort_limit, j.friction, j.damping,
                        j.segment);
}

vereshchagin::JointInfo jointInfoFromState(const py::handle& obj, const std::string& what) {
  const py::tuple t = record(obj, 9, what);
  vereshchagin::JointInfo j;
  j.name = t[0].cast<std::string>();
  j.type = t[1].cast<std::string>();
  j.lower = t[2].cast<double>();
  j.upper = t[3].cast<double>();
  j.velocity_limit = t[4].cast<double>();
  j.effort_limit = t[5].cast<double>();
  j.friction = t[6].cast<double>();
  j.damping = t[7].cast<double>();
  if (std::isnan(j.lower) || std::isnan(j.upper) || !(j.lower <= j.upper))
    raise(what + " limits must satisfy lower <= upper");
  if (!std::isfinite(j.friction) || j.friction < 0.0) raise(what + " friction must be finite and >= 0");
  j.segment = static_cast<unsigned int>(stateInt(t[8], 0, std::numeric_limits<int>::max(), what + " segment"));
  return j;
}

py::tuple linkState(const vereshchagin::LinkPlacement& l) {
  return py::make_tuple(l.link, l.segment, frameState(l.in_segment_tip));
}

vereshchagin::LinkPlacement linkFromState(const py::handle& obj, const std::string& what) {
  const py::tuple t = record(obj, 3, what);
  return {t[0].cast<std::string>(),
          static_cast<int>(stateInt(t[1], -1, std::numeric_limits<int>::max(), what + " segment")),
          frameFromState(t[2], what + " frame")};
}

void checkStateIndices(const std::vector<vereshchagin::JointInfo>& joints,
                       const std::vector<vereshchagin::LinkPlacement>& links, const std::vector<int>& moving_segments,
                       int n_segments, const std::string& what) {
  if (joints.size() != moving_segments.size())
    raise(what + ": " + std::to_string(joints.size()) + " joint records for " + std::to_string(moving_segments.size()) +
          " moving joints");
  for (std::size_t k = 0; k < joints.size(); ++k)
    if (static_cast<int>(joints[k].segment) != moving_segments[k])
      raise(what + ": joint record " + std::to_string(k) + " names segment " + std::to_string(joints[k].segment) +
            ", but that joint moves segment " + std::to_string(moving_segments[k]));
  for (const vereshchagin::LinkPlacement& l : links)
    if (l.segment >= n_segments)
      raise(what + ": link '" + l.link + "' names segment " + std::to_string(l.segment) + " of " +
            std::to_string(n_segments));
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
