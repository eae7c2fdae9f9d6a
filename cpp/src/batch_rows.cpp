// BatchInput, BatchOutput and PackedRow (batch.hpp): a row of strided inputs written into a
// SolveInput, a Data's results copied out as a row of row-major arrays, and one row's outputs
// packed in one buffer.
#include <algorithm>
#include <cmath>
#include <string>

#include "vereshchagin/batch.hpp"

namespace vereshchagin {

int BatchInput::columns() const {
  int m = 0;
  for (const BlockRows& b : blocks) m += b.columns;
  return m;
}

const FrictionModel* BatchInput::frictionOf(std::ptrdiff_t b) const {
  if (friction.empty()) return nullptr;
  return friction.size() == 1 ? friction[0] : friction[static_cast<std::size_t>(b)];
}

void BatchInput::fillRow(std::ptrdiff_t b, SolveInput& in) const {
  using MapV = Eigen::Map<const Eigen::VectorXd>;
  const auto nq = in.q.size(), nv = in.q_dot.size(), ns = in.f_ext.cols();  // (nq, nv: base_kind.hpp)
  in.clear();
  in.q = MapV(q.row(b), nq);
  in.q_dot = MapV(q_dot.row(b), nv);
  if (f_ext.data) in.f_ext = Eigen::Map<const Matrix6X>(f_ext.row(b), 6, ns);  // (ns, 6) rows
  for (const WrenchRows& w : wrenches) {
    const Eigen::Map<const Vector6> wrench(w.wrench.row(b));
    if (!w.on_frame) {
      in.f_ext.col(w.segment) += wrench;
      continue;
    }
    FrameWrench& out = in.wrenches.emplace_back();
    out.segment = w.segment;
    out.wrench = wrench;
    out.point = w.point;
  }
  if (ff_torques.data) in.ff_torques = MapV(ff_torques.row(b), nv);
  in.friction = frictionOf(b);
  in.contacts = contacts;  // within in.contacts' capacity after the first row
  in.contact_velocity_tolerance = contact_velocity_tolerance;
  in.time_step = time_step;
  in.contact_max_pivots = contact_max_pivots;
  const double* f_pass = f_ext_pass_through.data ? f_ext_pass_through.row(b) : nullptr;
  const double* t_pass = ff_pass_through.data ? ff_pass_through.row(b) : nullptr;
  int col = 0;
  for (const BlockRows& blk : blocks) {
    if (blk.segment < 0) {  // the last segment of a chain without segments: nothing can move
      col += blk.columns;
      continue;
    }
    ConstraintBlock& out = in.constraints.emplace_back();
    out.segment = blk.segment;
    out.columns = blk.columns;
    out.point = blk.point;
    out.classical = blk.classical.data != nullptr;
    if (out.classical) out.classical_acceleration = Eigen::Map<const Vector6>(blk.classical.row(b));
    const double *alpha = blk.alpha.row(b), *beta = out.classical ? nullptr : blk.beta.row(b);
    for (int c = 0; c < blk.columns; ++c, ++col) {
      for (int r = 0; r < 6; ++r) out.alfa(r, c) = alpha[r * blk.columns + c];
      out.beta(c) = beta ? beta[c] : 0.0;
      if (f_pass) out.f_ext_pass_through(c) = f_pass[col];
      if (t_pass) out.ff_pass_through(c) = t_pass[col];
    }
  }
}

bool BatchOutput::write(std::ptrdiff_t b, const Data& d, int columns, bool with_friction) const {
  const std::ptrdiff_t n = d.qdd().size(), links = d.linkAccelerations().size();
  std::copy_n(d.qdd().data(), n, qdd + b * n);
  std::copy_n(d.commandTorques().data(), n, tau_command + b * n);
  // nu has no entry for columns on a chain without segments (nothing moves): their magnitude is 0.
  std::fill_n(nu + b * columns, columns, 0.0);
  std::copy_n(d.nu().data(), d.nu().size(), nu + b * columns);
  std::copy_n(d.linkAccelerations().data(), links, link_acc + b * links);
  constraint_rank[b] = d.constraintRank();
  smallest_singular_value[b] = d.smallestSingularValue();
  if (contact_force != nullptr) {
    const auto forces = d.contactForces();
    const std::ptrdiff_t k = forces.cols();
    for (std::ptrdiff_t c = 0; c < k; ++c) std::copy_n(forces.col(c).data(), 3, contact_force + 3 * (b * k + c));
    for (std::ptrdiff_t c = 0; c < k; ++c) contact_status[b * k + c] = static_cast<int>(d.contactStatus()[c]);
    contact_outcome[b] = static_cast<int>(d.contactOutcome());
  }
  if (friction_torque == nullptr) return true;
  if (!with_friction) {
    std::fill_n(friction_torque + b * n, n, std::nan(""));
    std::fill_n(limit_torque + b * n, n, std::nan(""));
    std::fill_n(status + b * n, n, -1);
    gauss_value[b] = std::nan("");
    iterations[b] = -1;
    return true;
  }
  // A floating base's rows first (nv rows, the joints' n after them): no friction, no limit there.
  const std::ptrdiff_t nb = n - static_cast<std::ptrdiff_t>(d.jointStatus().size());
  std::fill_n(friction_torque + b * n, nb, 0.0);
  std::fill_n(limit_torque + b * n, nb, 0.0);
  std::fill_n(status + b * n, nb, static_cast<int>(JointStatus::Moving));
  std::copy_n(d.frictionTorques().data(), n - nb, friction_torque + b * n + nb);
  std::copy_n(d.limitTorques().data(), n - nb, limit_torque + b * n + nb);
  for (std::ptrdiff_t j = nb; j < n; ++j) status[b * n + j] = static_cast<int>(d.jointStatus()[j - nb]);
  gauss_value[b] = d.gaussValue();
  iterations[b] = d.iterations();
  return std::isfinite(gauss_value[b]);
}

std::string PackedRow::describe() const {
  return "n_joints = " + std::to_string(n_joints) + ", n_segments = " + std::to_string(n_segments) +
         ", m = " + std::to_string(m) + (friction ? " with" : " without") + " friction" +
         (contacts > 0 ? ", " + std::to_string(contacts) + " contacts" : "");
}

bool PackedRow::plausible() const {
  constexpr long kMax = 1L << 24;
  return n_joints >= 0 && n_segments >= 0 && m >= 0 && n_joints <= kMax && n_segments <= kMax && m <= 6 * n_segments &&
         contacts >= 0 && contacts <= kMax;
}

BatchWorkspace::BatchWorkspace(const Model& model, const SolverOptions& options, const KDL::Vector& gravity)
    : data(model, options), input(model) {
  input.gravity = gravity;
}

}  // namespace vereshchagin
