/// @file
/// Many solves at once: the inputs of B rows in the caller's memory (every argument shared by all
/// rows or one per row, with a stride), written into a SolveInput row by row (BatchInput), the
/// results of each row copied into row b of the caller's arrays (BatchOutput), and solveBatch(),
/// which spreads the rows over threads with one Data per thread. Row b of a batch equals solve()
/// of row b's input bit for bit, whatever the number of threads. Frames, signs and units are
/// those of input.hpp and data.hpp.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "vereshchagin/data.hpp"
#include "vereshchagin/input.hpp"

namespace vereshchagin {

/// One argument's rows in the caller's memory, row-major: row b starts at data + b * stride.
struct StridedRows {
  const double* data = nullptr;  ///< row 0 (nullptr: the argument was not given)
  std::ptrdiff_t stride = 0;     ///< doubles from one row to the next (0: every row reads row 0)
  /// The first value of row b.
  const double* row(std::ptrdiff_t b) const { return data + b * stride; }
};

/// The rows of a constraint block (ConstraintBlock): per row alpha (6 x columns, row-major) and
/// beta (columns), or a classical acceleration (6) instead of beta.
struct BlockRows {
  /// The segment (segment order); -1: the last segment of a chain without segments, where nothing
  /// moves: the block adds no ConstraintBlock, its columns keep their place in nu (written 0).
  int segment = -1;
  int columns = 0;                  ///< 0..6
  Vector3 point = Vector3::Zero();  ///< ConstraintBlock::point: the frame's origin in the tip frame (m)
  StridedRows alpha;                ///< 6 x columns: unit wrenches [force; moment], base axes, about point
  StridedRows beta;                 ///< columns (ConstraintBlock::beta); not read with classical
  StridedRows classical;            ///< 6: ConstraintBlock::classical_acceleration (nullptr: beta is the set-point)
};

/// The rows of a wrench on a frame moving with a segment: [force; moment] ON the body, base axes.
struct WrenchRows {
  int segment = 0;  ///< segment order
  /// true: a SolveInput::wrenches entry, moment about `point`; false: added to column `segment`
  /// of f_ext (moment about the segment's tip origin).
  bool on_frame = false;
  Vector3 point = Vector3::Zero();  ///< the frame's origin in the segment's tip frame (m)
  StridedRows wrench;               ///< 6 per row
};

/// The inputs of `rows` solves (gravity and base_acceleration are the workspace inputs' own).
struct BatchInput {
  std::ptrdiff_t rows = 1;           ///< B
  StridedRows q;                     ///< n_joints per row (rad or m); required
  StridedRows q_dot;                 ///< n_joints per row (rad/s or m/s); required
  StridedRows f_ext;                 ///< n_segments x 6 per row, row-major: SolveInput::f_ext transposed (nullptr: 0)
  StridedRows ff_torques;            ///< n_joints per row (N m or N; nullptr: 0)
  StridedRows f_ext_pass_through;    ///< one weight per column of nu per row (nullptr: 0); checked by solve()
  StridedRows ff_pass_through;       ///< see f_ext_pass_through
  std::vector<BlockRows> blocks;     ///< the columns of nu, in this order
  std::vector<WrenchRows> wrenches;  ///< wrenches on frames or segments, every row
  /// Friction: empty: none; one entry: every row's; else one per row (nullptr: that row has none).
  /// Not owned: each must outlive the solves.
  std::vector<const FrictionModel*> friction;
  /// Point contacts of every row (SolveInput::contacts; empty: none), with their velocity tolerance.
  std::vector<PointContact> contacts;
  double contact_velocity_tolerance = 1e-6;  ///< SolveInput::contact_velocity_tolerance (m/s)
  double time_step = 0.0;                    ///< SolveInput::time_step (s; 0: the instant)
  int contact_max_pivots = -1;               ///< SolveInput::contact_max_pivots (-1: the default bound)

  /// Constraint columns of every row (the size of nu).
  int columns() const;
  /// The friction of row b (nullptr: none).
  const FrictionModel* frictionOf(std::ptrdiff_t b) const;
  /// Writes row b into `in` after in.clear() (gravity and base_acceleration kept). Allocates
  /// nothing while the blocks and frame wrenches fit in `in`'s reserve().
  void fillRow(std::ptrdiff_t b, SolveInput& in) const;
};

/// Where the results of row b go: each array + b * (its row's size), row-major.
struct BatchOutput {
  double* qdd = nullptr;                      ///< n_joints per row
  double* tau_command = nullptr;              ///< n_joints per row (Data::commandTorques())
  double* nu = nullptr;                       ///< BatchInput::columns() per row
  double* link_acc = nullptr;                 ///< (n_segments + 1) x 6 per row (Data::linkAccelerations()^T)
  double* smallest_singular_value = nullptr;  ///< 1 per row
  int* constraint_rank = nullptr;             ///< 1 per row
  /// Friction outputs (nullptr: not written): n_joints per row, with limit_torque and status
  /// (JointStatus as int); gauss_value and iterations 1 per row. A row without friction gets NaN
  /// and -1.
  double* friction_torque = nullptr;
  double* limit_torque = nullptr;  ///< see friction_torque
  double* gauss_value = nullptr;   ///< see friction_torque
  int* status = nullptr;           ///< see friction_torque
  int* iterations = nullptr;       ///< see friction_torque
  /// Contact outputs (nullptr: not written), k = the rows' contacts: per row the forces (k x 3,
  /// Data::contactForces() transposed), the statuses (k, ContactStatus as int) and the outcome (1,
  /// ContactOutcome as int).
  double* contact_force = nullptr;
  int* contact_status = nullptr;   ///< see contact_force
  int* contact_outcome = nullptr;  ///< see contact_force

  /// Copies `data`'s results (after a successful solve of a row with `columns` columns, with or
  /// without friction) as row b. Returns false when gauss_value is not finite (an overflow).
  bool write(std::ptrdiff_t b, const Data& data, int columns, bool with_friction) const;
};

/// The outputs of one row packed in one buffer of doubles, in this order: qdd and tau_command
/// (n_joints each), nu (m), link_acc ((n_segments + 1) x 6, row-major), then with friction
/// friction_torque and limit_torque (n_joints each) and status (n_joints int32 values in
/// ceil(n_joints / 2) doubles), then with contacts contact_force (contacts x 3, row-major) and
/// contact_status (contacts int32 values in ceil(contacts / 2) doubles). The Python package's SolveResult stores its
/// outputs (and pickles them) in this layout; the scalars live outside the buffer.
struct PackedRow {
  /// An output's place in the buffer (see offset()).
  enum Field {
    Qdd,             ///< joint accelerations (n_joints)
    TauCommand,      ///< command torques (n_joints)
    Nu,              ///< constraint magnitudes (m)
    LinkAcc,         ///< link accelerations ((n_segments + 1) x 6)
    FrictionTorque,  ///< friction torques (n_joints; with friction)
    LimitTorque,     ///< joint-limit reactions (n_joints; with friction)
    Status,          ///< JointStatus as int32 (n_joints; with friction)
    ContactForce,    ///< contact forces (contacts x 3)
    ContactStatus,   ///< ContactStatus as int32 (contacts)
    End,             ///< the end of the buffer
  };
  long n_joints = 0;      ///< n
  long n_segments = 0;    ///< segments of the model
  long m = 0;             ///< constraint columns (the size of nu)
  bool friction = false;  ///< whether the friction outputs are stored
  long contacts = 0;      ///< point contacts (the rows of contact_force)

  /// The first double of `field` (End: the buffer's length; the friction fields: their place as
  /// if stored). Inline, as output(): the solve path of the Python package calls them per solve.
  std::ptrdiff_t offset(Field field) const {
    const std::ptrdiff_t n = n_joints, link = 6 * (n_segments + 1), friction_start = 2 * n + m + link;
    if (field <= LinkAcc) return field == Qdd ? 0 : field == TauCommand ? n : field == Nu ? 2 * n : 2 * n + m;
    if (field <= Status) return friction_start + (field - FrictionTorque) * n;
    const std::ptrdiff_t contact_start = friction ? friction_start + 2 * n + (n + 1) / 2 : friction_start;
    if (field == ContactForce) return contact_start;
    return contact_start + 3 * contacts + (field == End ? (contacts + 1) / 2 : 0);
  }
  /// "n_joints = 7, n_segments = 8, m = 6 with friction" (or "without friction"; ", 2 contacts" when
  /// there are contacts).
  std::string describe() const;
  /// Whether the sizes are ones a model can have (0 .. 2^24 joints and segments, 0 .. 6 columns per
  /// segment): the check of a layout read from outside (an unpickled result) before it is allocated.
  bool plausible() const;
  /// Whether both describe the same layout.
  bool operator==(const PackedRow& o) const {
    return n_joints == o.n_joints && n_segments == o.n_segments && m == o.m && friction == o.friction &&
           contacts == o.contacts;
  }
  /// A BatchOutput that writes row 0 into `buffer` (offset(End) doubles; the friction outputs
  /// nullptr without friction, the contact ones without contacts) and the scalars (1 each) where
  /// the pointers point.
  BatchOutput output(double* buffer, double* smallest_singular_value, int* constraint_rank, double* gauss_value,
                     int* iterations, int* contact_outcome) const {
    double* const fr = friction ? buffer + offset(FrictionTorque) : nullptr;
    double* const ct = contacts > 0 ? buffer + offset(ContactForce) : nullptr;
    return {buffer,
            buffer + n_joints,
            buffer + offset(Nu),
            buffer + offset(LinkAcc),
            smallest_singular_value,
            constraint_rank,
            fr,
            fr ? fr + n_joints : nullptr,
            gauss_value,
            fr ? reinterpret_cast<int*>(fr + 2 * n_joints) : nullptr,
            iterations,
            ct,
            ct ? reinterpret_cast<int*>(ct + 3 * contacts) : nullptr,
            ct ? contact_outcome : nullptr};
  }
};

/// A thread's workspace for solveBatch(): a Data and a SolveInput for one model.
struct BatchWorkspace {
  /// Data(model, options), a SolveInput of the model with this gravity (m/s^2, base axes).
  BatchWorkspace(const Model& model, const SolverOptions& options, const KDL::Vector& gravity);
  Data data;         ///< the thread's Data
  SolveInput input;  ///< the row being solved
};

/// What solveBatch() reports.
struct BatchFailure {
  std::ptrdiff_t row = -1;  ///< the lowest failing row (-1: none failed, or a thread did not start)
  std::string message;      ///< "batch row b: <solve()'s message>", or why a thread did not start; empty: success
  bool ok() const { return message.empty(); }  ///< true when every row was solved and written
};

/// Solves rows 0 .. input.rows - 1 in contiguous chunks, one per workspace (chunk 0 on the calling
/// thread, the others on new threads), each row as solve(model, data, fillRow's input) with its
/// results written by `out`. Stops a chunk at its first failure and reports the lowest failing
/// row. If the system refuses to start a thread, the started ones are joined and the message
/// says so. On success (and rows > 0) workspaces[0] holds the state of the last row (solved once
/// more when the rows were spread over threads). Allocates (threads and the messages).
BatchFailure solveBatch(const Model& model, const BatchInput& input, const BatchOutput& out,
                        const std::vector<BatchWorkspace*>& workspaces);

/// Seconds per solve of row 0 of `input` on `w` (steady clock, averaged over `reps` >= 1 solves),
/// each followed by the copy of its results that BatchOutput::write makes (into buffers of its
/// own, allocated once before the clock starts): the C++ cost of one solve as a caller sees it,
/// for benchmarks. NaN if a solve fails.
double secondsPerSolve(const Model& model, const BatchInput& input, BatchWorkspace& w, long reps);

}  // namespace vereshchagin
