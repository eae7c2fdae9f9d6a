// The immutable robot behind a Model (model.hpp): its segments in preorder with parents and
// joint indices, names and lookup tables, URDF data, and the validation result.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include "vereshchagin/model.hpp"

#include "hd_core.hpp"  // ModelSource

namespace vereshchagin {
namespace detail {

struct ModelImpl {
  ModelSource source;  // segments, parent, joint (per segment)
  ModelOptions options;
  std::vector<int> segment_of_joint;
  std::vector<std::string> segment_names, joint_names;
  std::string base_name;
  std::vector<JointInfo> joint_infos;
  std::vector<LinkPlacement> links;
  std::unordered_map<std::string, int> segment_index, joint_index, link_index;  // link_index: into links
  bool is_chain = true;
  Error error = Error::None;
  std::string message;
};

}  // namespace detail
}  // namespace vereshchagin
