// Deterministic random KDL trees for the tests (draws from testutil::RandomGen, random_chain.hpp).
//
// A tree grows segment by segment from the segment "root" (the base): each new segment hangs from
// the newest segment (half of the time: long branches) or from a uniformly drawn earlier one
// (random branching). Its joint is fixed with probability p_fixed, else a random moving joint of
// RandomGen::movingJoint (revolute or prismatic about random axes); tip frames and rigid-body
// inertias as for random chains. Segment k is named "s<k>", its joint "j<k>".
#pragma once

#include <string>
#include <vector>

#include <kdl/tree.hpp>

#include "random_chain.hpp"

namespace testutil {

struct TreeSpec {
  int n_joints = 10;  // moving joints
  double p_fixed = 0.15;
  bool allow_prismatic = true;
  bool rotor_inertia = true;
};

inline KDL::Tree randomTree(RandomGen& g, const TreeSpec& spec) {
  KDL::Tree tree("root");
  std::vector<std::string> names{"root"};
  int moving = 0;
  for (int k = 0; moving < spec.n_joints; ++k) {
    const int last = static_cast<int>(names.size()) - 1;
    const std::string& parent = names[g.coin(0.5) ? last : g.integer(0, last)];
    const std::string name = "s" + std::to_string(k), joint = "j" + std::to_string(k);
    const bool fixed = g.coin(spec.p_fixed);
    const KDL::Joint j =
        fixed ? KDL::Joint(joint, KDL::Joint::Fixed) : g.movingJoint(joint, spec.allow_prismatic, spec.rotor_inertia);
    tree.addSegment(g.segment(name, j), parent);
    names.push_back(name);
    moving += fixed ? 0 : 1;
  }
  return tree;
}

}  // namespace testutil
