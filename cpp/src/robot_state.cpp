// RobotChain and RobotTree as plain records, and back with every record checked (robot_state.hpp).
#include "vereshchagin/robot_state.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace vereshchagin {

namespace {

// KDL::RigidBodyInertia keeps (m, m c, I about the reference point); its public constructor takes
// the inertia about the centre of mass and would round the stored values differently. The record
// copies the 13 stored doubles so a restored robot solves bit for bit like the original.
static_assert(sizeof(KDL::RigidBodyInertia) == 13 * sizeof(double), "unexpected KDL::RigidBodyInertia layout");

constexpr long long kMaxIndex = std::numeric_limits<int>::max();

template <std::size_t N>
bool allFinite(const std::array<double, N>& a) {
  for (double v : a)
    if (!std::isfinite(v)) return false;
  return true;
}

std::array<double, 12> frameRecord(const KDL::Frame& f) {
  return {f.M(0, 0), f.M(0, 1), f.M(0, 2), f.M(1, 0), f.M(1, 1), f.M(1, 2),
          f.M(2, 0), f.M(2, 1), f.M(2, 2), f.p.x(),   f.p.y(),   f.p.z()};
}

KDL::Frame frameOf(const std::array<double, 12>& d) {
  return KDL::Frame(KDL::Rotation(d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7], d[8]),
                    KDL::Vector(d[9], d[10], d[11]));
}

SegmentRecord segmentRecord(const KDL::Segment& s, int parent) {
  const KDL::Joint& j = s.getJoint();
  SegmentRecord r;
  r.name = s.getName();
  r.joint_name = j.getName();
  r.joint_type = j.getType();
  r.origin = {j.JointOrigin().x(), j.JointOrigin().y(), j.JointOrigin().z()};
  r.axis = {j.JointAxis().x(), j.JointAxis().y(), j.JointAxis().z()};
  r.rotor_inertia = j.getInertia();
  r.damping = j.getDamping();
  r.stiffness = j.getStiffness();
  r.tip = frameRecord(s.getFrameToTip());
  const KDL::RigidBodyInertia I = s.getInertia();
  std::memcpy(r.inertia.data(), static_cast<const void*>(&I), sizeof(I));
  r.parent = parent;
  return r;
}

// "" if the record describes a segment, else why (after "segment i").
std::string segmentFault(const SegmentRecord& r) {
  if (r.joint_type < KDL::Joint::RotAxis || r.joint_type > KDL::Joint::Fixed)
    return " joint type is out of range (0 .. 8)";
  if (!std::isfinite(r.rotor_inertia) || !std::isfinite(r.damping) || !std::isfinite(r.stiffness))
    return " joint parameters must be finite";
  if (r.rotor_inertia < 0.0) return " rotor inertia must be >= 0";
  if (!allFinite(r.origin)) return " joint origin holds a non-finite value";
  if (!allFinite(r.axis)) return " joint axis holds a non-finite value";
  const bool has_axis = r.joint_type == KDL::Joint::RotAxis || r.joint_type == KDL::Joint::TransAxis;
  if (has_axis && !(KDL::Vector(r.axis[0], r.axis[1], r.axis[2]).Norm() > 0.0)) return " joint axis must be non-zero";
  if (!allFinite(r.tip)) return " tip frame holds a non-finite value";
  if (!allFinite(r.inertia)) return " inertia holds a non-finite value";
  if (r.inertia[0] < 0.0) return " inertia has a negative mass";
  return "";
}

KDL::Segment segmentOf(const SegmentRecord& r) {
  const auto type = static_cast<KDL::Joint::JointType>(r.joint_type);
  const KDL::Vector origin(r.origin[0], r.origin[1], r.origin[2]), axis(r.axis[0], r.axis[1], r.axis[2]);
  const bool has_axis = type == KDL::Joint::RotAxis || type == KDL::Joint::TransAxis;
  const KDL::Joint j =
      has_axis ? KDL::Joint(r.joint_name, origin, axis, type, 1.0, 0.0, r.rotor_inertia, r.damping, r.stiffness)
               : KDL::Joint(r.joint_name, type, 1.0, 0.0, r.rotor_inertia, r.damping, r.stiffness);
  KDL::RigidBodyInertia I;
  std::memcpy(static_cast<void*>(&I), r.inertia.data(), sizeof(I));
  return KDL::Segment(r.name, j, frameOf(r.tip), I);
}

// Joint and link records, checked against the segments (`moving`: the moving segments in q
// order), into `joints` and `links`; "" or why (after "Chain state" / "Tree state").
std::string metadataFault(const RobotRecord& record, const std::vector<int>& moving, std::vector<JointInfo>& joints,
                          std::vector<LinkPlacement>& links) {
  const long long n_segments = static_cast<long long>(record.segments.size());
  for (const JointRecord& j : record.joints) {
    const JointInfo& i = j.info;
    if (std::isnan(i.lower) || std::isnan(i.upper) || !(i.lower <= i.upper))
      return ": joint record limits must satisfy lower <= upper";
    if (!std::isfinite(i.friction) || i.friction < 0.0) return ": joint record friction must be finite and >= 0";
    if (j.segment < 0 || j.segment > kMaxIndex)
      return ": joint record segment is out of range (0 .. " + std::to_string(kMaxIndex) + ")";
    joints.push_back(i);
    joints.back().segment = static_cast<unsigned int>(j.segment);
  }
  for (const LinkRecord& l : record.links) {
    if (l.segment < -1 || l.segment > kMaxIndex)
      return ": link record segment is out of range (-1 .. " + std::to_string(kMaxIndex) + ")";
    if (!allFinite(l.frame)) return ": link record frame holds a non-finite value";
    links.push_back({l.link, static_cast<int>(l.segment), frameOf(l.frame)});
  }
  if (joints.size() != moving.size())
    return ": " + std::to_string(joints.size()) + " joint records for " + std::to_string(moving.size()) +
           " moving joints";
  for (std::size_t k = 0; k < joints.size(); ++k)
    if (static_cast<int>(joints[k].segment) != moving[k])
      return ": joint record " + std::to_string(k) + " names segment " + std::to_string(joints[k].segment) +
             ", but that joint moves segment " + std::to_string(moving[k]);
  for (const LinkRecord& l : record.links)
    if (l.segment >= n_segments)
      return ": link '" + l.link + "' names segment " + std::to_string(l.segment) + " of " + std::to_string(n_segments);
  return "";
}

Status failed(std::string& message, const std::string& text) {
  message = text;
  return Status(Error::InvalidModel, message.c_str());
}

}  // namespace

RecordTuples recordTuples(const RobotRecord& record) {
  RecordTuples t;
  for (const SegmentRecord& s : record.segments)
    t.segments.push_back({{s.name, s.joint_name, s.joint_type, s.origin, s.axis, s.rotor_inertia, s.damping,
                           s.stiffness, s.tip, s.inertia},
                          s.parent});
  for (const auto& [j, segment] : record.joints)
    t.joints.emplace_back(j.name, j.type, j.lower, j.upper, j.velocity_limit, j.effort_limit, j.friction, j.damping,
                          segment);
  for (const LinkRecord& l : record.links) t.links.emplace_back(l.link, l.segment, l.frame);
  return t;
}

void setRecordTuples(const RecordTuples& tuples, RobotRecord& record) {
  record.segments.clear();
  record.joints.clear();
  record.links.clear();
  for (const auto& [s, parent] : tuples.segments)
    record.segments.push_back(std::apply([p = parent](const auto&... x) { return SegmentRecord{x..., p}; }, s));
  for (const auto& [name, type, lower, upper, velocity, effort, friction, damping, segment] : tuples.joints)
    record.joints.push_back({{name, type, lower, upper, velocity, effort, friction, damping}, segment});
  for (const auto& [link, segment, frame] : tuples.links) record.links.push_back({link, segment, frame});
}

std::vector<SegmentTuple> withoutParents(const std::vector<std::pair<SegmentTuple, long long>>& segments) {
  std::vector<SegmentTuple> out;
  for (const auto& s : segments) out.push_back(s.first);
  return out;
}

std::vector<std::pair<SegmentTuple, long long>> withUnusedParents(const std::vector<SegmentTuple>& segments) {
  std::vector<std::pair<SegmentTuple, long long>> out;
  for (const SegmentTuple& s : segments) out.emplace_back(s, -1);
  return out;
}

RobotRecord robotRecord(const RobotChain& robot) {
  RobotRecord r;
  r.root_link = robot.root_link;
  for (unsigned int i = 0; i < robot.chain.getNrOfSegments(); ++i)
    r.segments.push_back(segmentRecord(robot.chain.getSegment(i), static_cast<int>(i) - 1));
  for (const JointInfo& j : robot.joints) r.joints.push_back({j, j.segment});
  for (const LinkPlacement& l : robot.links) r.links.push_back({l.link, l.segment, frameRecord(l.in_segment_tip)});
  r.notes = robot.notes;
  return r;
}

RobotRecord robotRecord(const RobotTree& robot) {
  RobotRecord r;
  r.root_link = robot.root_link;
  for (std::size_t i = 0; i < robot.segment_names.size(); ++i)
    r.segments.push_back(
        segmentRecord(robot.tree.getSegments().find(robot.segment_names[i])->second.segment, robot.parent[i]));
  for (const JointInfo& j : robot.joints) r.joints.push_back({j, j.segment});
  for (const LinkPlacement& l : robot.links) r.links.push_back({l.link, l.segment, frameRecord(l.in_segment_tip)});
  r.notes = robot.notes;
  return r;
}

Status robotFromRecord(const RobotRecord& record, RobotChain& out, std::string& message) {
  out = RobotChain();
  std::vector<int> moving;
  for (std::size_t i = 0; i < record.segments.size(); ++i) {
    const SegmentRecord& s = record.segments[i];
    if (const std::string fault = segmentFault(s); !fault.empty())
      return failed(message, "Chain state: segment " + std::to_string(i) + fault);
    if (s.joint_type != KDL::Joint::Fixed) moving.push_back(static_cast<int>(i));
    out.chain.addSegment(segmentOf(s));
  }
  if (const std::string fault = metadataFault(record, moving, out.joints, out.links); !fault.empty())
    return failed(message, "Chain state" + fault);
  out.root_link = record.root_link;
  out.notes = record.notes;
  message.clear();
  return Status();
}

Status robotFromRecord(const RobotRecord& record, RobotTree& out, std::string& message) {
  out = RobotTree();
  out.root_link = record.root_link;
  out.tree = KDL::Tree(record.root_link);
  std::vector<int> moving;
  for (std::size_t i = 0; i < record.segments.size(); ++i) {
    const SegmentRecord& s = record.segments[i];
    const std::string what = "Tree state: segment " + std::to_string(i);
    if (const std::string fault = segmentFault(s); !fault.empty()) return failed(message, what + fault);
    if (s.parent < -1 || s.parent >= static_cast<long long>(i))
      return failed(message, what + ": parent index is out of range (-1 .. " +
                                 std::to_string(static_cast<long long>(i) - 1) + ")");
    const int parent = static_cast<int>(s.parent);
    if (!out.tree.addSegment(segmentOf(s), parent < 0 ? out.root_link : out.segment_names[std::size_t(parent)]))
      return failed(message, "Tree state: segment '" + s.name + "' cannot be added");
    if (s.joint_type != KDL::Joint::Fixed) moving.push_back(static_cast<int>(i));
    out.segment_names.push_back(s.name);
    out.parent.push_back(parent);
  }
  if (const std::string fault = metadataFault(record, moving, out.joints, out.links); !fault.empty())
    return failed(message, "Tree state" + fault);
  out.notes = record.notes;
  message.clear();
  return Status();
}

namespace {

template <class Robot>
StateRecords stateOf(const Robot& robot) {
  const RobotRecord r = robotRecord(robot);
  RecordTuples t = recordTuples(r);
  return {r.root_link, std::move(t.segments), std::move(t.joints), std::move(t.links), r.notes};
}

template <class Robot>
Status fromState(const StateRecords& records, Robot& out, std::string& message) {
  RobotRecord r;
  r.root_link = std::get<0>(records);
  r.notes = std::get<4>(records);
  setRecordTuples({std::get<1>(records), std::get<2>(records), std::get<3>(records)}, r);
  return robotFromRecord(r, out, message);
}

}  // namespace

StateRecords stateRecords(const RobotChain& robot) {
  return stateOf(robot);
}
StateRecords stateRecords(const RobotTree& robot) {
  return stateOf(robot);
}
Status robotFromState(const StateRecords& records, RobotChain& out, std::string& message) {
  return fromState(records, out, message);
}
Status robotFromState(const StateRecords& records, RobotTree& out, std::string& message) {
  return fromState(records, out, message);
}

}  // namespace vereshchagin
