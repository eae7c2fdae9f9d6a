// KinematicsData and forward kinematics (kinematics.hpp): the outward sweep over the parent array
// in the base frame (kinematics_impl.hpp).
#include <cmath>
#include <cstdio>

#include "kdl_convert.hpp"
#include "kinematics_impl.hpp"

namespace vereshchagin {
namespace detail {

namespace {

// Segment i's constants. KDL::Segment::twist(0, 1) is the joint's twist per unit q_dot, root axes,
// reference point the tip origin; moved to the root origin: v_r = v_tip - w x p_tip.
KinSegment makeSegment(const KDL::Segment& s, int joint, int parent) {
  KinSegment k;
  k.X0 = toPose(s.pose(0.0));
  k.joint = joint;
  k.parent = parent;
  const KDL::RigidBodyInertia& rbi = s.getInertia();
  k.mass = rbi.getMass();
  k.com = toEigen(rbi.getCOG());
  const Matrix3 I_origin = Eigen::Map<const Matrix3>(rbi.getRotationalInertia().data);
  const Matrix3 C = skew(k.com);
  k.I_com = 0.5 * (I_origin + I_origin.transpose()) + k.mass * C * C;  // parallel axes: about the com
  if (joint < 0) return k;
  k.rotor = s.getJoint().getInertia();
  const KDL::Twist t = s.twist(0.0, 1.0);
  const Vector3 w = toEigen(t.rot);
  const Vector3 v = toEigen(t.vel) - w.cross(k.X0.p);
  k.S_r << v, w;
  k.w_norm = w.norm();
  if (k.w_norm == 0.0) {
    k.kind = JointKind::Prismatic;
    return k;
  }
  k.kind = JointKind::Revolute;
  k.k = w / k.w_norm;
  k.kxv = k.k.cross(v) / k.w_norm;
  k.kv = k.k.dot(v);
  const Matrix3 K = skew(k.k);
  const Vector3 d = k.X0.p - k.kxv;
  k.KR = K * k.X0.R;
  k.KKR = K * k.KR;
  k.Kd = K * d;
  k.KKd = K * k.Kd;
  return k;
}

// The screw motion E = exp(q [S_r]) of a joint, applied to X0: for a revolute joint E.R is the
// rotation by theta = |w_r| q about k, E = I + sin(theta) K + (1 - cos(theta)) K K with K = [k]x
// (Rodrigues), and E.p = (I - E.R) (k x v_r) / |w_r| + k (k . v_r) q; so tip(q) = E X0 has
// R = X0.R + sin K X0.R + (1 - cos) K K X0.R and p = X0.p + sin K d + (1 - cos) K K d + k (k . v_r) q
// with d = X0.p - k x v_r / |w_r|, K X0.R, K K X0.R, K d, K K d constants of the segment. For a
// prismatic joint E = (I, v_r q).
void jointPose(const KinSegment& s, double q, Matrix3& R, Vector3& p) {
  if (s.kind == JointKind::Prismatic) {
    R = s.X0.R;
    p = s.X0.p + s.S_r.head<3>() * q;
    return;
  }
  const double theta = s.w_norm * q;
  const double sn = std::sin(theta), c1 = 1.0 - std::cos(theta);
  R = s.X0.R + sn * s.KR + c1 * s.KKR;
  p = s.X0.p + sn * s.Kd + c1 * s.KKd + s.k * (s.kv * q);
}

}  // namespace

KinematicsImpl::KinematicsImpl(const Model& m) : model(m) {
  ns = static_cast<int>(m.nrOfSegments());
  nj = static_cast<int>(m.nrOfJoints());
  seg.reserve(static_cast<std::size_t>(ns));
  for (int i = 0; i < ns; ++i)
    seg.push_back(makeSegment(m.segment(i), m.jointOfSegment()[static_cast<std::size_t>(i)],
                              m.parents()[static_cast<std::size_t>(i)]));
  st.resize(static_cast<std::size_t>(ns));
}

Status KinematicsImpl::fail(Error code, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(message.data(), message.size(), fmt, args);
  va_end(args);
  return Status(code, message.data());
}

Status KinematicsImpl::checkModel(const Model& m) {
  if (!m.sameAs(model))
    return fail(Error::NotUpToDate, "this workspace was built for another model (build one per Model)");
  return Status();
}

Status KinematicsImpl::checkResult(const Eigen::Ref<const Eigen::MatrixXd>& out) {
  // x - x is 0 for a finite x and NaN for Inf and NaN, and NaN stays in a sum: four independent
  // sums without early exit, which the compiler vectorizes (Eigen's allFinite on a strided Ref
  // costs several times more, on every companion call). A contiguous result is one column.
  double sums[4] = {0.0, 0.0, 0.0, 0.0};
  const bool contiguous = out.outerStride() == out.rows();
  for (Eigen::Index c = 0; c < (contiguous ? 1 : out.cols()); ++c) {
    const double* x = out.data() + c * out.outerStride();
    const Eigen::Index n = contiguous ? out.size() : out.rows();
    Eigen::Index r = 0;
    for (; r + 4 <= n; r += 4)
      for (int l = 0; l < 4; ++l) sums[l] += x[r + l] - x[r + l];
    for (; r < n; ++r) sums[0] += x[r] - x[r];
  }
  if (std::isnan(sums[0] + sums[1] + sums[2] + sums[3]))
    return fail(Error::NonfiniteResult, "the result overflows the double range");
  return Status();
}

Status KinematicsImpl::checkVector(const Eigen::Ref<const Eigen::VectorXd>& v, const char* name) {
  if (v.size() != nj)
    return fail(Error::SizeMismatch, "%s has %ld entries, the model has %d joints", name, static_cast<long>(v.size()),
                nj);
  for (int j = 0; j < nj; ++j)
    if (!std::isfinite(v(j))) return fail(Error::NonfiniteInput, "%s[%d] is not finite", name, j);
  return Status();
}

Status KinematicsImpl::checkFrame(const FrameRef& frame, bool need_qd) {
  if (frame.segment < -1 || frame.segment >= ns)
    return fail(Error::OutOfRange, "frame segment %d is out of range [-1, %d)", frame.segment, ns);
  if (!has_q) return fail(Error::NoSolution, "no forwardKinematics(model, kdata, q) before this call");
  if (need_qd && !has_qd)
    return fail(Error::NoSolution, "velocities need forwardKinematics(model, kdata, q, q_dot) before this call");
  return Status();
}

void KinematicsImpl::place(const Eigen::Ref<const Eigen::VectorXd>& q) {
  for (int i = 0; i < ns; ++i) {
    const KinSegment& s = seg[static_cast<std::size_t>(i)];
    KinState& x = st[static_cast<std::size_t>(i)];
    Matrix3 R;
    Vector3 p;
    if (s.joint < 0) {
      R = s.X0.R;
      p = s.X0.p;
    } else {
      jointPose(s, q(s.joint), R, p);
    }
    if (s.parent < 0) {
      x.X.R = R;
      x.X.p = p;
      x.S = s.S_r;
      continue;
    }
    const KinState& up = st[static_cast<std::size_t>(s.parent)];
    x.X.R.noalias() = up.X.R * R;
    x.X.p.noalias() = up.X.R * p;
    x.X.p += up.X.p;
    if (s.joint < 0) continue;
    // The axis, fixed in the parent's tip frame, to base axes about the base origin.
    x.S.tail<3>().noalias() = up.X.R * s.S_r.tail<3>();
    x.S.head<3>().noalias() = up.X.R * s.S_r.head<3>();
    x.S.head<3>() += up.X.p.cross(x.S.tail<3>());
  }
}

void KinematicsImpl::velocities(const Eigen::Ref<const Eigen::VectorXd>& qd) {
  for (int i = 0; i < ns; ++i) {
    const KinSegment& s = seg[static_cast<std::size_t>(i)];
    KinState& x = st[static_cast<std::size_t>(i)];
    if (s.parent < 0)
      x.V.setZero();
    else
      x.V = st[static_cast<std::size_t>(s.parent)].V;
    if (s.joint >= 0) x.V.noalias() += x.S * qd(s.joint);
  }
}

Vector3 KinematicsImpl::origin(const FrameRef& frame) const {
  if (frame.segment < 0) return toEigen(frame.in_tip.p);
  const KinState& x = st[static_cast<std::size_t>(frame.segment)];
  return x.X.p + x.X.R * toEigen(frame.in_tip.p);
}

}  // namespace detail

KinematicsData::KinematicsData(const Model& model) : impl_(std::make_unique<detail::KinematicsImpl>(model)) {}
KinematicsData::~KinematicsData() = default;
KinematicsData::KinematicsData(KinematicsData&&) noexcept = default;
KinematicsData& KinematicsData::operator=(KinematicsData&&) noexcept = default;

const Model& KinematicsData::model() const noexcept {
  return impl_->model;
}
const Pose& KinematicsData::tipPose(int i) const {
  return impl_->st[static_cast<std::size_t>(i)].X;
}
const Vector6& KinematicsData::spatialVelocity(int i) const {
  return impl_->st[static_cast<std::size_t>(i)].V;
}
const Vector6& KinematicsData::jointAxis(int i) const {
  return impl_->st[static_cast<std::size_t>(i)].S;
}
bool KinematicsData::hasPositions() const noexcept {
  return impl_->has_q;
}
bool KinematicsData::hasVelocities() const noexcept {
  return impl_->has_qd;
}

Status forwardKinematics(const Model& model, KinematicsData& kdata, const JointPositions& q) {
  detail::KinematicsImpl& k = kdata.impl();
  if (const Status s = k.checkModel(model); !s) return s;
  if (const Status s = k.checkVector(*q, "q"); !s) return s;
  k.has_q = k.has_qd = false;
  k.place(*q);
  k.has_q = true;
  return Status();
}

Status forwardKinematics(const Model& model, KinematicsData& kdata, const JointPositions& q,
                         const JointVelocities& q_dot) {
  detail::KinematicsImpl& k = kdata.impl();
  if (const Status s = k.checkModel(model); !s) return s;
  if (const Status s = k.checkVector(*q, "q"); !s) return s;
  if (const Status s = k.checkVector(*q_dot, "q_dot"); !s) return s;
  k.has_q = k.has_qd = false;
  k.place(*q);
  k.velocities(*q_dot);
  k.has_q = k.has_qd = true;
  return Status();
}

}  // namespace vereshchagin
