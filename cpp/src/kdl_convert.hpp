// KDL frames and vectors as the fixed-size Eigen types of spatial.hpp (model building only; the
// sweeps never convert).
#pragma once

#include <kdl/frames.hpp>

#include "vereshchagin/spatial.hpp"

namespace vereshchagin {
namespace detail {

inline Vector3 toEigen(const KDL::Vector& v) {
  return Vector3(v.x(), v.y(), v.z());
}

inline Pose toPose(const KDL::Frame& f) {
  Pose X;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) X.R(r, c) = f.M(r, c);
    X.p(r) = f.p(r);
  }
  return X;
}

}  // namespace detail
}  // namespace vereshchagin
