// Model (model.hpp): sources from chains, trees and URDF loads; names; validation.
#include "vereshchagin/model.hpp"

#include <utility>

#include "model_impl.hpp"

namespace vereshchagin {

namespace detail {
ModelSource chainModelSource(const KDL::Chain& chain);
ModelSource treeModelSource(const KDL::Tree& tree, const std::string& root_name);
}  // namespace detail

namespace {

using detail::ModelImpl;

// Names, tables and validation of a source; `links` empty: one link per segment (its tip).
std::shared_ptr<const ModelImpl> finish(detail::ModelSource source, const ModelOptions& options, std::string base,
                                        std::vector<JointInfo> joints, std::vector<LinkPlacement> links) {
  auto m = std::make_shared<ModelImpl>();
  m->options = options;
  source.base = options.base;
  source.base_inertia = options.base_inertia;
  m->base_name = std::move(base);
  m->joint_infos = std::move(joints);
  const std::size_t ns = source.segments.size();
  for (std::size_t i = 0; i < ns; ++i) {
    const KDL::Segment& seg = source.segments[i];
    m->segment_names.push_back(seg.getName());
    m->segment_index.emplace(seg.getName(), static_cast<int>(i));
    if (source.parent[i] != static_cast<int>(i) - 1) m->is_chain = false;
    if (source.joint[i] >= 0) {
      m->segment_of_joint.push_back(static_cast<int>(i));
      m->joint_names.push_back(seg.getJoint().getName());
      m->joint_index.emplace(seg.getJoint().getName(), source.joint[i]);
    }
  }
  if (links.empty()) {
    for (std::size_t i = 0; i < ns; ++i)
      links.push_back(LinkPlacement{source.segments[i].getName(), static_cast<int>(i), KDL::Frame::Identity()});
  }
  m->links = std::move(links);
  for (std::size_t k = 0; k < m->links.size(); ++k) m->link_index.emplace(m->links[k].link, static_cast<int>(k));
  // The solver's model, validated (every check and message in one place).
  m->hd = detail::buildHdModel(std::move(source), options.inertia_check);
  if (m->hd->error != 0) {
    m->error = static_cast<Error>(m->hd->error);
    m->message = m->hd->message;
  }
  return m;
}

// A tree load's own base kind unless the options name one; its base inertia added to theirs.
ModelOptions treeOptions(const RobotTree& robot, ModelOptions options) {
  if (options.base == BaseKind::Fixed) options.base = robot.base;
  options.base_inertia = options.base_inertia + robot.base_inertia;
  return options;
}

}  // namespace

Model::Model() : Model(KDL::Chain()) {}

Model::Model(const KDL::Chain& chain, const ModelOptions& options)
    : impl_(finish(detail::chainModelSource(chain), options, "base", {}, {})) {}

Model::Model(const KDL::Tree& tree, const std::string& root_segment, const ModelOptions& options)
    : impl_(finish(detail::treeModelSource(tree, root_segment), options,
                   root_segment.empty() ? tree.getRootSegment()->first : root_segment, {}, {})) {}

Model::Model(const RobotChain& robot, const ModelOptions& options)
    : impl_(finish(detail::chainModelSource(robot.chain), options, robot.root_link, robot.joints, robot.links)) {}

Model::Model(const RobotTree& robot, const ModelOptions& options)
    : impl_(finish(detail::treeModelSource(robot.tree, std::string()), treeOptions(robot, options), robot.root_link,
                   robot.joints, robot.links)) {}

Model detail::ModelAccess::withOptions(const Model& model, const ModelOptions& options) {
  const ModelImpl& old = model.impl();
  if (old.options.inertia_check == options.inertia_check) return model;
  auto m = std::make_shared<ModelImpl>(old);
  m->options = options;
  m->error = Error::None;
  m->message.clear();
  m->hd = detail::buildHdModel(old.source(), options.inertia_check);
  if (m->hd->error != 0) {
    m->error = static_cast<Error>(m->hd->error);
    m->message = m->hd->message;
  }
  return Model(std::move(m));
}

Status Model::status() const noexcept {
  return Status(impl_->error, impl_->message.c_str());
}
const ModelOptions& Model::options() const noexcept {
  return impl_->options;
}
unsigned int Model::nrOfJoints() const noexcept {
  return static_cast<unsigned int>(impl_->segment_of_joint.size());
}
unsigned int Model::nq() const noexcept {
  return nrOfJoints() + static_cast<unsigned int>(impl_->hd->nbq);
}
unsigned int Model::nv() const noexcept {
  return nrOfJoints() + static_cast<unsigned int>(impl_->hd->nbv);
}
BaseKind Model::baseKind() const noexcept {
  return impl_->hd->base;
}
unsigned int Model::nrOfSegments() const noexcept {
  return static_cast<unsigned int>(impl_->source().segments.size());
}
bool Model::isChain() const noexcept {
  return impl_->is_chain;
}
const KDL::Segment& Model::segment(int i) const {
  return impl_->source().segments[static_cast<std::size_t>(i)];
}
const std::vector<KDL::Segment>& Model::segments() const noexcept {
  return impl_->source().segments;
}
const std::vector<int>& Model::parents() const noexcept {
  return impl_->source().parent;
}
const std::vector<int>& Model::jointOfSegment() const noexcept {
  return impl_->source().joint;
}
const std::vector<int>& Model::segmentOfJoint() const noexcept {
  return impl_->segment_of_joint;
}
const std::vector<std::string>& Model::segmentNames() const noexcept {
  return impl_->segment_names;
}
const std::vector<std::string>& Model::jointNames() const noexcept {
  return impl_->joint_names;
}
const std::string& Model::baseName() const noexcept {
  return impl_->base_name;
}
const std::vector<JointInfo>& Model::jointInfos() const noexcept {
  return impl_->joint_infos;
}
const std::vector<LinkPlacement>& Model::links() const noexcept {
  return impl_->links;
}

int Model::segmentIndex(const std::string& name) const noexcept {
  const auto it = impl_->segment_index.find(name);
  return it == impl_->segment_index.end() ? -1 : it->second;
}

int Model::jointIndex(const std::string& name) const noexcept {
  const auto it = impl_->joint_index.find(name);
  return it == impl_->joint_index.end() ? -1 : it->second;
}

bool Model::findFrame(const std::string& name, FrameRef& out) const noexcept {
  const int s = segmentIndex(name);
  if (s >= 0) {
    out = FrameRef{s, KDL::Frame::Identity()};
    return true;
  }
  const auto it = impl_->link_index.find(name);
  if (it != impl_->link_index.end()) {
    const LinkPlacement& l = impl_->links[static_cast<std::size_t>(it->second)];
    out = FrameRef{l.segment, l.in_segment_tip};
    return true;
  }
  if (name == impl_->base_name) {
    out = FrameRef{-1, KDL::Frame::Identity()};
    return true;
  }
  return false;
}

const char* errorName(Error code) noexcept {
  switch (code) {
    case Error::None:
      return "None";
    case Error::Degraded:
      return "Degraded";
    case Error::NotUpToDate:
      return "NotUpToDate";
    case Error::SizeMismatch:
      return "SizeMismatch";
    case Error::OutOfRange:
      return "OutOfRange";
    case Error::NonfiniteInput:
      return "NonfiniteInput";
    case Error::InvalidModel:
      return "InvalidModel";
    case Error::DegenerateInertia:
      return "DegenerateInertia";
    case Error::TooManyConstraints:
      return "TooManyConstraints";
    case Error::NoSolution:
      return "NoSolution";
    case Error::InvalidOptions:
      return "InvalidOptions";
    case Error::NonfiniteResult:
      return "NonfiniteResult";
    case Error::ConcurrentCall:
      return "ConcurrentCall";
    case Error::StateOutOfRange:
      return "StateOutOfRange";
    case Error::InvalidFriction:
      return "InvalidFriction";
    case Error::NotConverged:
      return "NotConverged";
    case Error::InvalidContact:
      return "InvalidContact";
    case Error::NoContactSolution:
      return "NoContactSolution";
  }
  return "Unknown";
}

}  // namespace vereshchagin
