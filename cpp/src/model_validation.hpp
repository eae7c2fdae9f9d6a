// Geometric validity of a KDL segment (private to the library): what ChainHdSolver checks about a
// segment's frames before it builds its model. Inertial parameters are checked in buildModel().
#pragma once

#include <kdl/segment.hpp>

namespace vereshchagin {
namespace detail {

// nullptr if the segment's geometry is usable, else a short description of the problem:
//  * the tip frame (KDL Segment::getFrameToTip(), the tip in the joint-rotated frame at q = 0)
//    must be finite with a proper rotation: |R^T R - I|_max <= 1e-6 and det R > 0;
//  * the joint's origin and axis (RotAxis / TransAxis joints) must be finite.
const char* segmentGeometryProblem(const KDL::Segment& segment);

}  // namespace detail
}  // namespace vereshchagin
