/// @file
/// A RobotChain or RobotTree as plain records (strings, integers and doubles only), bit for bit,
/// and back with every record checked: the form the Python pickle states are made of. A record
/// from anywhere (a crafted state, a file) is refused with a message naming the record at fault
/// rather than handed to a solver.
#pragma once

#include <array>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "vereshchagin/robot_chain.hpp"
#include "vereshchagin/robot_tree.hpp"
#include "vereshchagin/status.hpp"

namespace vereshchagin {

/// One KDL segment, bit for bit.
struct SegmentRecord {
  std::string name;                          ///< the segment's name
  std::string joint_name;                    ///< its joint's name
  long long joint_type = KDL::Joint::Fixed;  ///< KDL::Joint::JointType number, RotAxis (0) .. Fixed (8)
  std::array<double, 3> origin{};            ///< joint origin, parent tip frame, m (read for RotAxis / TransAxis)
  std::array<double, 3> axis{};              ///< joint axis, parent tip frame (read for RotAxis / TransAxis, non-zero)
  double rotor_inertia = 0.0;                ///< KDL::Joint's inertia, >= 0 (kg m^2 or kg)
  double damping = 0.0;                      ///< KDL::Joint's damping
  double stiffness = 0.0;                    ///< KDL::Joint's stiffness
  /// The tip frame in the joint frame at q = 0: rotation row by row (9), then position (3, m).
  std::array<double, 12> tip{};
  /// KDL::RigidBodyInertia's 13 stored doubles: mass (kg, >= 0), mass x centre of mass (kg m,
  /// tip frame), rotational inertia about the tip origin (kg m^2, 3x3).
  std::array<double, 13> inertia{};
  long long parent = -1;  ///< trees: index of the parent segment (< this one's, -1: the base); chains: unused
};

/// A JointInfo whose segment index may be anything (checked by robotFromRecord).
struct JointRecord {
  JointInfo info;         ///< name, type, limits (lower <= upper), friction (finite, >= 0), damping
  long long segment = 0;  ///< index of the segment the joint moves
};

/// A LinkPlacement whose segment index and frame may be anything (checked by robotFromRecord).
struct LinkRecord {
  std::string link;                ///< the link's name
  long long segment = -1;          ///< the segment holding it (-1: the base)
  std::array<double, 12> frame{};  ///< its pose in that segment's tip frame, as SegmentRecord::tip
};

/// A whole robot: segments in segment order (robot_tree.hpp), joints in q order, links.
struct RobotRecord {
  std::string root_link;                ///< the base frame's name
  std::vector<SegmentRecord> segments;  ///< chain order, or the tree's segment order
  std::vector<JointRecord> joints;      ///< one per moving joint, in q order
  std::vector<LinkRecord> links;        ///< every link and where it went
  std::vector<std::string> notes;       ///< approximations made while building
};

/// A SegmentRecord's fields but `parent`, in declaration order: an entry of a pickle state.
using SegmentTuple = std::tuple<std::string, std::string, long long, std::array<double, 3>, std::array<double, 3>,
                                double, double, double, std::array<double, 12>, std::array<double, 13>>;
/// A JointRecord: its JointInfo's name, type, lower, upper, velocity_limit, effort_limit,
/// friction and damping, then the segment index.
using JointTuple = std::tuple<std::string, std::string, double, double, double, double, double, double, long long>;
/// A LinkRecord: link, segment, frame.
using LinkTuple = std::tuple<std::string, long long, std::array<double, 12>>;

/// A RobotRecord's segments, joints and links as tuples of plain values (what the Python pickle
/// states hold; root_link and notes stay with the RobotRecord).
struct RecordTuples {
  std::vector<std::pair<SegmentTuple, long long>> segments;  ///< each segment and its parent index
  std::vector<JointTuple> joints;                            ///< q order
  std::vector<LinkTuple> links;                              ///< as RobotRecord::links
};

/// The tuples of `record`'s segments, joints and links, bit for bit.
RecordTuples recordTuples(const RobotRecord& record);
/// The inverse of recordTuples: sets `record`'s segments, joints and links (nothing is checked
/// here: robotFromRecord checks the result).
void setRecordTuples(const RecordTuples& tuples, RobotRecord& record);

/// A chain's pickle state holds its segments without parent indices: the SegmentTuple of each of
/// `segments`, in order.
std::vector<SegmentTuple> withoutParents(const std::vector<std::pair<SegmentTuple, long long>>& segments);
/// The inverse of withoutParents: each of `segments` with parent index -1 (a chain's parent field
/// is unused; robotFromRecord ignores it for a chain).
std::vector<std::pair<SegmentTuple, long long>> withUnusedParents(const std::vector<SegmentTuple>& segments);

/// A whole robot as the Python pickle states hold it, whichever the robot: root_link, each
/// segment with its parent index (a chain's: unused), the joints (q order), the links and the
/// notes (vereshchagin/_models.py lays them out as a Chain's or a Tree's state).
using StateRecords = std::tuple<std::string, std::vector<std::pair<SegmentTuple, long long>>, std::vector<JointTuple>,
                                std::vector<LinkTuple>, std::vector<std::string>>;

/// The StateRecords of `robot`, bit for bit (robotRecord, then recordTuples).
StateRecords stateRecords(const RobotChain& robot);
StateRecords stateRecords(const RobotTree& robot);  ///< see stateRecords(const RobotChain&)
/// robotFromRecord of `records` (setRecordTuples, then every check and message of robotFromRecord).
Status robotFromState(const StateRecords& records, RobotChain& out, std::string& message);
/// The same for a tree (robotFromRecord's tree checks and "Tree state: " messages).
Status robotFromState(const StateRecords& records, RobotTree& out, std::string& message);

/// The records of a chain (SegmentRecord::parent = i - 1) and of a tree.
RobotRecord robotRecord(const RobotChain& robot);
RobotRecord robotRecord(const RobotTree& robot);  ///< see robotRecord(const RobotChain&)

/// The chain of `record`, after checking every record: joint types in range, finite values,
/// rotor inertia >= 0, non-zero axes, no negative mass, joint limits lower <= upper, friction
/// >= 0, one joint record per moving segment naming that segment, link records on segments that
/// exist. On failure Error::InvalidModel with a message starting "Chain state: " (e.g. "Chain
/// state: segment 2 inertia has a negative mass", "Chain state: joint record 0 names segment 9,
/// but that joint moves segment 0") in `message`; `out` is then unspecified.
Status robotFromRecord(const RobotRecord& record, RobotChain& out, std::string& message);
/// The same for a tree ("Tree state: "), also checking parent indices (-1 .. i - 1) and names
/// KDL accepts (unique).
Status robotFromRecord(const RobotRecord& record, RobotTree& out, std::string& message);

}  // namespace vereshchagin
