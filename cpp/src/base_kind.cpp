// The names of the base kinds (base_kind.hpp), as Tree.from_urdf(base=...) spells them.
#include "vereshchagin/base_kind.hpp"

namespace vereshchagin {

const char* baseKindName(BaseKind kind) noexcept {
  return kind == BaseKind::FreeFlyer ? "free" : kind == BaseKind::Planar ? "planar" : "fixed";
}

bool baseKindFromName(const std::string& name, BaseKind& out) noexcept {
  if (name == "fixed") {
    out = BaseKind::Fixed;
  } else if (name == "free" || name == "free_flyer") {
    out = BaseKind::FreeFlyer;
  } else if (name == "planar") {
    out = BaseKind::Planar;
  } else {
    return false;
  }
  return true;
}

}  // namespace vereshchagin
