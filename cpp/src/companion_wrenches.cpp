// addFrameWrench (dynamics.hpp): a wrench about the origin of a frame moving with a segment, moved
// to the segment's tip origin at the kinematic state of a KinematicsData, for the f_ext of the
// dynamics companions. A moment about the point P is, about the tip origin T, n + (P - T) x f, and
// P - T = R_tip p in base axes (p: P in tip coordinates).
#include "vereshchagin/dynamics.hpp"

#include <cmath>

#include "kinematics_impl.hpp"

namespace vereshchagin {

Status addFrameWrench(const Model& model, KinematicsData& kdata, const FrameRef& frame, const Vector6& wrench,
                      Eigen::Ref<Matrix6X> f_ext) {
  detail::KinematicsImpl& k = kdata.impl();
  if (const Status s = k.checkModel(model); !s) return s;
  if (frame.segment < 0 || frame.segment >= k.ns)
    return k.fail(Error::OutOfRange, "wrench segment %d is out of range [0, %d)", frame.segment, k.ns);
  if (!k.has_q) return k.fail(Error::NoSolution, "no forwardKinematics(model, kdata, q) before this call");
  if (f_ext.cols() != k.ns)
    return k.fail(Error::SizeMismatch, "f_ext has %ld columns, expected %d (one per segment)",
                  static_cast<long>(f_ext.cols()), k.ns);
  const KDL::Vector& p = frame.in_tip.p;
  if (!wrench.allFinite() || !std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
    return k.fail(Error::NonfiniteInput, "wrench or frame offset is not finite");
  // R_tip p summed column by column, left to right (as KDL::Rotation * KDL::Vector).
  const Matrix3& R = k.st[static_cast<std::size_t>(frame.segment)].X.R;
  const Vector3 r = R.col(0) * p.x() + R.col(1) * p.y() + R.col(2) * p.z();
  const Vector3 f = wrench.head<3>();
  auto col = f_ext.col(frame.segment);
  col.head<3>() += f;
  col.tail<3>() += wrench.tail<3>() + r.cross(f);
  return Status();
}

}  // namespace vereshchagin
