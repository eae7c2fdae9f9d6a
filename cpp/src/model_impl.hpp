// The immutable robot behind a Model (model.hpp): its segments in preorder with parents and
// joint indices, the solver's model, names and lookup tables, URDF data, and the validation result.
#pragma once

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "vereshchagin/model.hpp"

#include "hd_core.hpp"  // ModelSource

namespace vereshchagin {
namespace detail {

struct ModelImpl {
  // The solver's model (segments, parent, joint per segment in hd->source), built and validated
  // once; every HdCore of this Model shares it.
  std::shared_ptr<const HdModel> hd;
  const ModelSource& source() const { return hd->source; }
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

// What the solver facades need of a Model beyond its public face.
struct ModelAccess {
  // The same robot validated with other options (a facade's setOptions()).
  static Model withOptions(const Model& model, const ModelOptions& options);
};

}  // namespace detail
}  // namespace vereshchagin
