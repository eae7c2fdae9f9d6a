// robot_state.hpp: a RobotChain and a RobotTree (robot_fixture.hpp) to records and back, bit for
// bit (records compared field by field, the inertia's stored doubles included), and every check
// of robotFromRecord with its message.
#include <cstring>
#include <string>

#include "robot_fixture.hpp"
#include "vereshchagin/robot_state.hpp"

namespace {

bool sameRecords(const vereshchagin::RobotRecord& a, const vereshchagin::RobotRecord& b) {
  bool same = a.root_link == b.root_link && a.notes == b.notes && a.segments.size() == b.segments.size() &&
              a.joints.size() == b.joints.size() && a.links.size() == b.links.size();
  for (std::size_t i = 0; same && i < a.segments.size(); ++i) {
    const auto &s = a.segments[i], &t = b.segments[i];
    same = s.name == t.name && s.joint_name == t.joint_name && s.joint_type == t.joint_type && s.origin == t.origin &&
           s.axis == t.axis && s.rotor_inertia == t.rotor_inertia && s.tip == t.tip && s.inertia == t.inertia &&
           s.parent == t.parent;
  }
  for (std::size_t k = 0; same && k < a.joints.size(); ++k)
    same = a.joints[k].info.name == b.joints[k].info.name && a.joints[k].segment == b.joints[k].segment &&
           a.joints[k].info.friction == b.joints[k].info.friction && a.joints[k].info.lower == b.joints[k].info.lower;
  for (std::size_t k = 0; same && k < a.links.size(); ++k)
    same = a.links[k].link == b.links[k].link && a.links[k].segment == b.links[k].segment &&
           a.links[k].frame == b.links[k].frame;
  return same;
}

// robotFromRecord's message for a tree (tree != 0) or chain record after `edit`.
template <class Edit>
std::string refusal(bool tree, Edit edit) {
  vereshchagin::RobotRecord r =
      tree ? vereshchagin::robotRecord(robotfixture::tree()) : vereshchagin::robotRecord(robotfixture::chain());
  edit(r);
  std::string message;
  vereshchagin::RobotTree t;
  vereshchagin::RobotChain c;
  const vereshchagin::Status s =
      tree ? vereshchagin::robotFromRecord(r, t, message) : vereshchagin::robotFromRecord(r, c, message);
  if (!s) CHECK(s.code() == vereshchagin::Error::InvalidModel);
  return s ? std::string() : std::string(s.message());
}

}  // namespace

TEST_CASE("records round-trip a chain and a tree bit for bit") {
  const vereshchagin::RobotRecord chain = vereshchagin::robotRecord(robotfixture::chain());
  vereshchagin::RobotChain c;
  std::string message;
  REQUIRE(vereshchagin::robotFromRecord(chain, c, message));
  CHECK(sameRecords(vereshchagin::robotRecord(c), chain));
  CHECK(chain.segments[1].parent == 0);
  const vereshchagin::RobotRecord tree = vereshchagin::robotRecord(robotfixture::tree());
  vereshchagin::RobotTree t;
  REQUIRE(vereshchagin::robotFromRecord(tree, t, message));
  CHECK(sameRecords(vereshchagin::robotRecord(t), tree));
  CHECK(t.parent == robotfixture::tree().parent);
  CHECK(GetTreeElementQNr(t.tree.getSegments().find("slider")->second) == 2);
}

TEST_CASE("record tuples round-trip a tree's records bit for bit") {
  const vereshchagin::RobotRecord tree = vereshchagin::robotRecord(robotfixture::tree());
  const vereshchagin::RecordTuples tuples = vereshchagin::recordTuples(tree);
  REQUIRE(tuples.segments.size() == tree.segments.size());
  CHECK(std::get<0>(tuples.segments[2].first) == "slider");
  CHECK(tuples.segments[2].second == tree.segments[2].parent);
  CHECK(std::get<8>(tuples.joints[2]) == tree.joints[2].segment);
  vereshchagin::RobotRecord back;
  back.root_link = tree.root_link;
  back.notes = tree.notes;
  back.links.push_back({"stale", 0, {}});  // replaced, not appended to
  vereshchagin::setRecordTuples(tuples, back);
  CHECK(sameRecords(back, tree));
}

TEST_CASE("robotFromRecord refuses crafted records naming the record") {
  using R = vereshchagin::RobotRecord;
  CHECK(refusal(false, [](R&) {}).empty());
  CHECK(refusal(true, [](R&) {}).empty());
  CHECK(refusal(false, [](R& r) { r.segments[0].joint_type = 99; }) ==
        "Chain state: segment 0 joint type is out of range (0 .. 8)");
  CHECK(refusal(false, [](R& r) { r.segments[1].inertia[0] = -1.0; }) ==
        "Chain state: segment 1 inertia has a negative mass");
  CHECK(refusal(true, [](R& r) { r.segments[1].inertia[4] = NAN; }) ==
        "Tree state: segment 1 inertia holds a non-finite value");
  CHECK(refusal(false, [](R& r) { r.segments[0].rotor_inertia = -1.0; }) ==
        "Chain state: segment 0 rotor inertia must be >= 0");
  CHECK(refusal(false, [](R& r) { r.segments[0].tip[3] = INFINITY; }) ==
        "Chain state: segment 0 tip frame holds a non-finite value");
  CHECK(refusal(false, [](R& r) {
          r.segments[0].joint_type = KDL::Joint::RotAxis;
          r.segments[0].axis = {0.0, 0.0, 0.0};
        }) == "Chain state: segment 0 joint axis must be non-zero");
  CHECK(refusal(false, [](R& r) { r.segments.pop_back(); }) == "Chain state: 2 joint records for 1 moving joints");
  CHECK(refusal(false, [](R& r) { r.joints[0].segment = 1000000; }) ==
        "Chain state: joint record 0 names segment 1000000, but that joint moves segment 0");
  CHECK(refusal(false, [](R& r) { r.joints[0].segment = 1LL << 40; }) ==
        "Chain state: joint record segment is out of range (0 .. 2147483647)");
  CHECK(refusal(false, [](R& r) { r.joints[0].info.lower = 2.0; }) ==
        "Chain state: joint record limits must satisfy lower <= upper");
  CHECK(refusal(true, [](R& r) { r.joints[0].info.friction = -1.0; }) ==
        "Tree state: joint record friction must be finite and >= 0");
  CHECK(refusal(false, [](R& r) { r.links[0].segment = 5; }) == "Chain state: link 'base' names segment 5 of 2");
  CHECK(refusal(true, [](R& r) { r.links[0].segment = -2; }) ==
        "Tree state: link record segment is out of range (-1 .. 2147483647)");
  CHECK(refusal(true, [](R& r) { r.segments[1].parent = 1; }) ==
        "Tree state: segment 1: parent index is out of range (-1 .. 0)");
  CHECK(refusal(true, [](R& r) { r.segments[2].name = "arm"; }) == "Tree state: segment 'arm' cannot be added");
}

TEST_CASE("a chain's segment tuples drop and regain the unused parent index") {
  const vereshchagin::RobotRecord chain = vereshchagin::robotRecord(robotfixture::chain());
  const vereshchagin::RecordTuples tuples = vereshchagin::recordTuples(chain);
  const std::vector<vereshchagin::SegmentTuple> bare = vereshchagin::withoutParents(tuples.segments);
  REQUIRE(bare.size() == tuples.segments.size());
  CHECK(bare[1] == tuples.segments[1].first);
  const auto back = vereshchagin::withUnusedParents(bare);
  REQUIRE(back.size() == bare.size());
  CHECK(back[1].first == bare[1]);
  CHECK(back[1].second == -1);
  CHECK(vereshchagin::withoutParents(back) == bare);
}

TEST_CASE("state records round-trip a chain and a tree, and are refused as records are") {
  const vereshchagin::RobotTree tree = robotfixture::tree();
  const vereshchagin::RobotChain chain = robotfixture::chain();
  vereshchagin::RobotTree t;
  vereshchagin::RobotChain c;
  std::string message;
  REQUIRE(vereshchagin::robotFromState(vereshchagin::stateRecords(tree), t, message));
  REQUIRE(vereshchagin::robotFromState(vereshchagin::stateRecords(chain), c, message));
  CHECK(sameRecords(vereshchagin::robotRecord(t), vereshchagin::robotRecord(tree)));
  CHECK(sameRecords(vereshchagin::robotRecord(c), vereshchagin::robotRecord(chain)));
  CHECK(std::get<0>(vereshchagin::stateRecords(tree)) == tree.root_link);
  vereshchagin::StateRecords bad = vereshchagin::stateRecords(chain);
  std::get<1>(bad).pop_back();  // one segment fewer than joint records
  CHECK_FALSE(vereshchagin::robotFromState(bad, c, message));
  CHECK(message.rfind("Chain state", 0) == 0);
}
