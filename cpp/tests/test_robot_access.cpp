// robot_access.hpp on a RobotChain and a RobotTree (robot_fixture.hpp): counts, names, masses,
// rotor inertias (getter, setter, its refusals with the robot unchanged), lookups by name (and
// their messages) and the chain of one tree path, against the URDF's own numbers and the chain loader's result.
#include <string>
#include <vector>

#include "robot_fixture.hpp"
#include "vereshchagin/robot_access.hpp"

TEST_CASE("counts, names and masses on a chain and a tree") {
  const vereshchagin::RobotTree tree = robotfixture::tree();
  const vereshchagin::RobotChain chain = robotfixture::chain();
  CHECK(vereshchagin::segmentCount(tree) == 3);
  CHECK(vereshchagin::jointCount(tree) == 3);
  CHECK(vereshchagin::segmentCount(chain) == 2);
  CHECK(vereshchagin::jointCount(chain) == 2);
  CHECK(vereshchagin::segmentName(tree, 2) == "slider");
  CHECK(vereshchagin::segmentAt(tree, 2).getInertia().getMass() == 3.0);
  CHECK(vereshchagin::segmentName(chain, 1) == "finger");  // the merged group takes its last link's name
  CHECK(vereshchagin::segmentMasses(tree) == std::vector<double>{2.0, 1.1, 3.0});
  CHECK(vereshchagin::segmentMasses(chain) == std::vector<double>{2.0, 1.1});
  CHECK(vereshchagin::findJoint(tree, "j_slider") == 2);
  CHECK(vereshchagin::findJoint(chain, "j_slider") == -1);
}

TEST_CASE("frames by name: segments, merged links, the base") {
  const vereshchagin::RobotTree tree = robotfixture::tree();
  vereshchagin::FrameRef ref;
  REQUIRE(vereshchagin::findFrame(tree, "finger", ref));
  CHECK(ref.segment == 1);
  CHECK(ref.in_tip.p.Norm() == 0.0);
  REQUIRE(vereshchagin::findFrame(tree, "hand", ref));  // merged: 0.05 m below the tip
  CHECK(ref.segment == 1);
  CHECK(ref.in_tip.p.z() == doctest::Approx(-0.05));
  REQUIRE(vereshchagin::findFrame(tree, "base", ref));
  CHECK(ref.segment == -1);
  ref.segment = 7;
  CHECK_FALSE(vereshchagin::findFrame(tree, "nowhere", ref));
  CHECK(ref.segment == 7);
  REQUIRE(vereshchagin::findFrame(robotfixture::chain(), "finger", ref));
  CHECK(ref.segment == 1);
}

TEST_CASE("lookups by name name what exists when they fail") {
  const vereshchagin::RobotTree tree = robotfixture::tree();
  vereshchagin::FrameRef ref;
  std::string message;
  CHECK(vereshchagin::findFrame(tree, "hand", ref, message));
  CHECK(ref.segment == 1);
  CHECK(message.empty());
  const vereshchagin::Status s = vereshchagin::findFrame(tree, "nowhere", ref, message);
  CHECK(s.code() == vereshchagin::Error::OutOfRange);
  CHECK(std::string(s.message()) == message);
  CHECK(message.rfind("no segment or link named 'nowhere' (segments: '", 0) == 0);
  CHECK(message.find("'slider'; base: 'base')") != std::string::npos);
  int index = -1;
  CHECK(vereshchagin::findJoint(tree, "j_slider", index, message));
  CHECK(index == 2);
  CHECK_FALSE(vereshchagin::findJoint(robotfixture::chain(), "j_slider", index, message));
  CHECK(message.rfind("no joint named 'j_slider' (joints: '", 0) == 0);
  std::vector<std::string> many;
  for (int k = 0; k < 13; ++k) many.push_back("n" + std::to_string(k));
  CHECK(vereshchagin::nameList({"a", "b"}) == "'a', 'b'");
  CHECK(vereshchagin::nameList(many).find("'n11', ... (13 in all)") != std::string::npos);
  CHECK(vereshchagin::nameList(many).find("'n12'") == std::string::npos);
}

TEST_CASE("index messages name the valid range and what names an item") {
  CHECK(vereshchagin::indexRangeMessage("segment", "9", 7) ==
        "segment index 9 out of range for 7 segments (valid -7 .. 6; the base is addressed by its name only)");
  CHECK(vereshchagin::indexRangeMessage("joint", "-8", 7) ==
        "joint index -8 out of range for 7 joints (valid -7 .. 6)");
  CHECK(vereshchagin::indexTypeMessage("segment", "float") ==
        "a segment is named by a str (segment or link name) or an int index, got float");
  CHECK(vereshchagin::indexTypeMessage("joint", "list") == "a joint is named by a str or an int index, got list");
}

TEST_CASE("rotor inertia is set per joint and refused when negative") {
  for (int tree_or_chain = 0; tree_or_chain < 2; ++tree_or_chain) {
    vereshchagin::RobotTree tree = robotfixture::tree();
    vereshchagin::RobotChain chain = robotfixture::chain();
    std::string message;
    const std::vector<double> values =
        tree_or_chain ? std::vector<double>{0.1, 0.2, 0.3} : std::vector<double>{0.1, 0.2};
    const vereshchagin::Status ok = tree_or_chain ? vereshchagin::setRotorInertia(tree, values, message)
                                                  : vereshchagin::setRotorInertia(chain, values, message);
    REQUIRE(ok);
    CHECK((tree_or_chain ? vereshchagin::rotorInertia(tree) : vereshchagin::rotorInertia(chain)) == values);
    std::vector<double> bad = values;
    bad.back() = -0.1;
    const vereshchagin::Status s = tree_or_chain ? vereshchagin::setRotorInertia(tree, bad, message)
                                                 : vereshchagin::setRotorInertia(chain, bad, message);
    CHECK(s.code() == vereshchagin::Error::OutOfRange);
    CHECK(std::string(s.message()) ==
          "rotor_inertia must be >= 0, got -0.100000 at joint " + std::to_string(values.size() - 1));
    CHECK((tree_or_chain ? vereshchagin::rotorInertia(tree) : vereshchagin::rotorInertia(chain)) == values);
    const vereshchagin::Status size = vereshchagin::setRotorInertia(chain, {1.0, 2.0, 3.0, 4.0}, message);
    CHECK(std::string(size.message()) == "rotor_inertia must have 2 entries, got 4");
  }
  vereshchagin::RobotTree tree = robotfixture::tree();
  std::string message;
  REQUIRE(vereshchagin::setRotorInertia(tree, {0.1, 0.2, 0.3}, message));
  CHECK(tree.tree.getNrOfSegments() == 3);  // q numbering kept
  CHECK(GetTreeElementQNr(tree.tree.getSegments().find("slider")->second) == 2);
}

TEST_CASE("pathChain is the chain loader's chain of the same path") {
  const vereshchagin::RobotChain path = vereshchagin::pathChain(robotfixture::tree(), 1);
  const vereshchagin::RobotChain loaded = robotfixture::chain();
  REQUIRE(path.chain.getNrOfSegments() == 2);
  CHECK(path.root_link == "base");
  REQUIRE(path.joints.size() == 2);
  CHECK(path.joints[1].name == "j_hand");
  CHECK(path.joints[0].friction == 0.5);
  CHECK(path.joints[1].segment == 1);
  for (unsigned int i = 0; i < 2; ++i) {
    CHECK(path.chain.getSegment(i).getName() == loaded.chain.getSegment(i).getName());
    CHECK(path.chain.getSegment(i).getInertia().getMass() == loaded.chain.getSegment(i).getInertia().getMass());
  }
  std::vector<std::string> links;
  for (const auto& l : path.links) links.push_back(l.link);
  CHECK(links.size() == 4);
  REQUIRE(!path.notes.empty());
  CHECK(path.notes.back() == "extracted from a tree: the 1 segments off the path to 'finger' are left out");
}

TEST_CASE("RobotRef reads a chain and a tree as the functions above do") {
  const vereshchagin::RobotTree tree = robotfixture::tree();
  const vereshchagin::RobotChain chain = robotfixture::chain();
  const vereshchagin::RobotRef t(tree), c(chain);
  CHECK(t.segmentCount() == 3);
  CHECK(c.segmentCount() == 2);
  CHECK(&t.joints() == &tree.joints);
  CHECK(&c.joints() == &chain.joints);
  CHECK(vereshchagin::linkNames(tree).size() == tree.links.size());
  vereshchagin::FrameRef ref;
  std::string message;
  CHECK(t.findFrame("finger", ref, message));
  CHECK(ref.segment == 1);
  CHECK_FALSE(c.findFrame("nowhere", ref, message));
  CHECK(message.find("no segment or link named 'nowhere'") == 0);
  int index = -1;
  CHECK(t.findJoint("j_slider", index, message));
  CHECK(index == 2);
  CHECK_FALSE(c.findJoint("j_slider", index, message));
  CHECK(message.find("no joint named 'j_slider'") == 0);
  // A tree's Model orders its segments as the RobotTree does (the Python Tree relies on it).
  const vereshchagin::Model model = t.model(vereshchagin::ModelOptions{});
  REQUIRE(model.status());
  CHECK(model.segmentNames() == tree.segment_names);
  CHECK(c.model(vereshchagin::ModelOptions{}).nrOfSegments() == 2);
}

TEST_CASE("rotor inertia from an array checks its shape first") {
  vereshchagin::RobotChain chain = robotfixture::chain();
  const double values[3] = {0.1, 0.2, 0.3};
  vereshchagin::ArrayArg a;
  a.data = values;
  a.ndim = 1;
  a.shape[0] = 3;
  std::string message;
  CHECK(vereshchagin::setRotorInertia(chain, a, message).code() == vereshchagin::Error::SizeMismatch);
  CHECK(message == "rotor_inertia must have shape (2,), got (3,)");
  CHECK(vereshchagin::rotorInertia(chain) == vereshchagin::rotorInertia(robotfixture::chain()));
  a.shape[0] = 2;
  REQUIRE(vereshchagin::setRotorInertia(chain, a, message));
  CHECK(vereshchagin::rotorInertia(chain) == std::vector<double>{0.1, 0.2});
}
