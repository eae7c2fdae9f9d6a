// WholeBodySolver (whole_body.hpp): the workspace, the checks of a call's input and the order of
// its steps (the free solve and response columns, the rows, the programme, the results).
#include "vereshchagin/whole_body.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>

#include "vereshchagin/momentum.hpp"
#include "whole_body_impl.hpp"

namespace vereshchagin {

WholeBodySolver::Impl::Impl(const Model& mdl, const WholeBodyOptions& opt)
    : model(&mdl), options(opt), data(mdl), free(mdl) {
  nv = static_cast<int>(mdl.nv());
  nj = static_cast<int>(mdl.nrOfJoints());
  nb = nv - nj;
  const int kmax = std::max(0, opt.max_contacts), mmax = std::max(0, opt.max_task_rows) + 3 * kmax;
  const int pmax = nj + 3 * kmax;
  joints.resize(nj);
  R.resize(nv, pmax);
  dtau.resize(nv, nj);
  segs.resize(3 * kmax);
  W.resize(6, 3 * kmax);
  J6.resize(6, nv);
  JR.resize(6, pmax);
  E.resize(mmax, pmax);
  e.resize(mmax);
  qdd0.resize(nv);
  qr = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(pmax, mmax);
  Q.resize(pmax, pmax);
  for (Eigen::VectorXd* v : {&xp, &x, &w, &t, &pv, &work, &y}) v->resize(std::max(pmax, mmax));
  P.resize(pmax, pmax);
  C.resize(pmax, pmax);
  D.resize(9 * kmax, 3 * kmax);  // cone rows reserved for up to 8 facets (more: reallocated once)
  G.resize(9 * kmax, pmax);
  g.resize(9 * kmax);
  lqp_p = pmax, lqp_k = 9 * kmax;
  lqp.reserve(lqp_p, lqp_k);
  if (mdl.baseKind() == BaseKind::FreeFlyer && mdl.status()) {  // M from p = M c_dot for a unit base velocity
    DynamicsData dd(mdl);
    Eigen::VectorXd q0 = Eigen::VectorXd::Zero(mdl.nq()), v0 = Eigen::VectorXd::Zero(nv);
    q0(6) = 1.0;
    v0(0) = 1.0;
    Vector6 h;
    if (centroidalMomentum(mdl, dd, JointPositions(q0), JointVelocities(v0), h)) mass = h(0);
  }
}

Status WholeBodySolver::Impl::fail(Error code, const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::vsnprintf(message, sizeof(message), format, args);
  va_end(args);
  return Status(code, message);
}

WholeBodySolver::WholeBodySolver(const Model& model, const WholeBodyOptions& options)
    : impl_(std::make_unique<Impl>(model, options)) {}
WholeBodySolver::~WholeBodySolver() = default;
WholeBodySolver::WholeBodySolver(WholeBodySolver&&) noexcept = default;
WholeBodySolver& WholeBodySolver::operator=(WholeBodySolver&&) noexcept = default;

Status WholeBodySolver::status() const noexcept {
  if (!impl_->data.status()) return impl_->data.status();
  if (impl_->options.max_contacts < 0 || impl_->options.max_task_rows < 0 || !(impl_->options.tolerance > 0.0))
    return Status(Error::InvalidOptions, "WholeBodyOptions: capacities must be >= 0 and tolerance > 0");
  return Status();
}

namespace {

// The checks of solve()'s input beyond those of solve(model, data, input).
Status checkInput(WholeBodySolver::Impl& s, const SolveInput& in, const Eigen::Ref<const Eigen::VectorXi>& actuated) {
  if (actuated.size() != 0 && actuated.size() != s.nj)
    return s.fail(Error::SizeMismatch, "actuated has %ld entries, expected %d (one per joint) or none",
                  (long)actuated.size(), s.nj);
  if (in.friction != nullptr || in.time_step != 0.0 || in.base_acceleration != KDL::Twist::Zero())
    return s.fail(Error::OutOfRange, "whole-body least effort takes no friction, time_step or base_acceleration");
  const int ns = static_cast<int>(s.model->nrOfSegments());
  int rows = 0;
  for (const ConstraintBlock& b : in.constraints) {
    if (b.segment == kCenterOfMass && !(s.mass > 0.0 && b.alfa.bottomRows<3>().leftCols(b.columns).isZero(0.0)))
      return s.fail(Error::OutOfRange,
                    "a centre-of-mass task needs a free-flyer base with mass and alfa's moment rows zero");
    if (b.segment < kCenterOfMass || b.segment >= ns || b.columns < 0 || b.columns > 6)
      return s.fail(Error::OutOfRange, "a task block's segment %d (or its %d columns) is out of range", b.segment,
                    b.columns);
    rows += b.columns;
  }
  if (rows > s.options.max_task_rows || static_cast<int>(in.contacts.size()) > s.options.max_contacts)
    return s.fail(Error::TooManyConstraints, "%d task rows and %d supports; capacity %d and %d", rows,
                  (int)in.contacts.size(), s.options.max_task_rows, s.options.max_contacts);
  for (std::size_t c = 0; c < in.contacts.size(); ++c) {
    const PointContact& pc = in.contacts[c];
    const bool ok = pc.segment >= 0 && pc.segment < ns && pc.isSupport() && pc.mu >= 0.0 && std::isfinite(pc.mu) &&
                    pc.facets >= 3 && pc.facets <= 64 && std::abs(pc.normal.norm() - 1.0) <= 1e-6 &&
                    pc.point.allFinite();
    if (!ok)
      return s.fail(Error::InvalidContact,
                    "support %d: needs a segment in [0, %d), no force set-point, mu >= 0, 3..64 facets and a "
                    "unit normal",
                    (int)c, ns);
  }
  s.mt = rows;
  s.k = static_cast<int>(in.contacts.size());
  s.na = 0;
  for (int j = 0; j < s.nj; ++j)
    if (actuated.size() == 0 || actuated(j) != 0) s.joints(s.na++) = j;
  s.p = s.na + 3 * s.k;
  s.m = s.mt + 3 * s.k;
  return Status();
}

}  // namespace

Status WholeBodySolver::solve(const SolveInput& input, const Eigen::Ref<const Eigen::VectorXi>& actuated,
                              WholeBodyResult& result) {
  Impl& s = *impl_;
  if (const Status st = status(); !st) return st;
  if (const Status st = checkInput(s, input, actuated); !st) return st;
  if (const Status st = s.columns(input); !st) return st;
  s.rows(input);
  if (!s.eliminate()) return Status(Error::NoSolution, s.message);
  if (!s.program(input)) return Status(Error::NoSolution, s.message);
  const Eigen::Ref<const Eigen::VectorXd> x = s.x.head(s.p);
  result.tau.setZero(s.nv);
  for (int i = 0; i < s.na; ++i) result.tau(s.nb + s.joints(i)) = x(i);
  result.forces.resize(3, s.k);
  for (int c = 0; c < s.k; ++c) result.forces.col(c) = x.segment(s.na + 3 * c, 3);
  result.qdd.resize(s.nv);
  result.qdd.noalias() = s.R.leftCols(s.p) * x;
  result.qdd += s.qdd0;
  result.effort = x.head(s.na).squaredNorm();
  result.residual = s.residual;
  return Status();
}

}  // namespace vereshchagin
