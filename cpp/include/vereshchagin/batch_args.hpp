/// @file
/// The checks that turn arrays into a BatchInput (batch.hpp): each argument's shape per row, its
/// optional leading batch axis (B rows, the same B for every argument that has one), finite
/// values, and the constraint blocks' columns and frames. The messages name each argument as the
/// caller passes it (the Python package passes the names of Solver.solve and solve_batch); values
/// beyond finiteness (ranges, signs) are solve()'s to check.
#pragma once

#include <string>
#include <vector>

#include "vereshchagin/array_arg.hpp"
#include "vereshchagin/batch.hpp"
#include "vereshchagin/friction_model.hpp"
#include "vereshchagin/model.hpp"
#include "vereshchagin/robot_chain.hpp"

namespace vereshchagin {

/// What a shape message adds to "<name> must have shape (...)".
enum class ShapeHint {
  None,   ///< nothing
  Alpha,  ///< alpha's: shape "(6, m)", its columns are unit wrenches, (6,) is one column
  FExt,   ///< f_ext's: one row [force; moment] per segment, or a dict {segment: wrench}
};

/// The arrays of a friction model (the attributes of the Python package's Friction), checked into
/// `out` for n joints. static_friction: (n,), finite (N m or N). kinetic: (n,), finite, or nullptr
/// (out.kinetic_friction empty: equal to static). lower, upper: (n,) without NaN (+-infinity: no
/// limit; rad or m); both nullptr: no limits (out.lower, out.upper empty; out.limit_tolerance kept),
/// one nullptr: no limit on that side. Tolerances are stored as given. Messages: "friction.static
/// must have shape (n,), got (...)" (vectorMessage's), "friction.lower contains NaN"; the values'
/// signs and order are solve()'s to check.
std::string frictionFromArrays(FrictionModel& out, long n, const ArrayArg& static_friction, const ArrayArg* kinetic,
                               double velocity_tolerance, const ArrayArg* lower, const ArrayArg* upper,
                               double limit_tolerance);

/// The friction model of `friction=True`: the joints' own static friction and position limits
/// (JointInfo::friction, lower, upper: N m or N, rad or m), one entry per joint in joint order;
/// kinetic friction equal to static, tolerances FrictionModel's defaults.
FrictionModel frictionOfJoints(const std::vector<JointInfo>& joints);

/// Checks which of solve()'s end-segment arguments are given (alpha: the (6, m) directions, beta:
/// the set-point, a_desired: the tip's classical acceleration instead of beta) on a chain or, with
/// tree = true, a tree, which has no last segment. Messages: "alpha and beta constrain a chain's
/// last segment; a Tree has no last segment: pass constraints=...", "beta and a_desired given:
/// ...", "beta given without alpha", "a_desired given without alpha".
std::string endBlockArgs(bool alpha, bool beta, bool a_desired, bool tree);

/// Builds a BatchInput from row-major arrays, checking each as it is added (see the top of this
/// file). Every method returns "" on success, else the message; after a message the input is
/// incomplete and must not be solved. One BatchArgs serves many calls: start() clears it and
/// keeps its vectors' capacity, so a call with as many blocks as an earlier one allocates nothing
/// (a message allocates). The arrays must outlive the solves of `input`.
class BatchArgs {
 public:
  /// Clears `input` (1 row, nothing given, no blocks, wrenches or friction), `columns` and the
  /// memory of the checks. batch: arguments may have a leading batch axis; model: the robot the
  /// input is for (its segment names appear in messages; must outlive the BatchArgs' use).
  void start(bool batch, const Model& model);

  /// Checks that `a` holds rows of `shape` (ndim dimensions; in a batch also ndim + 1 with a
  /// leading batch axis, see batchAxis()) with finite values, and points `out` at them (stride 0:
  /// one row shared by all). Messages: "<name> must have shape (...)[ hint], got (...)" and
  /// "[batch row b: ]<name> contains NaN or Inf (flat index k)" (k within the row).
  std::string rows(StridedRows& out, const char* name, const ArrayArg& a, int ndim, const long* shape,
                   ShapeHint hint = ShapeHint::None);

  /// rows() of an (n,) vector per row; with scalar_ok and n == 1 also a scalar, or in a batch a
  /// (B,) array (one value per row).
  std::string vector(StridedRows& out, const char* name, ArrayArg a, long n, bool scalar_ok = false);

  /// Sets the batch size B to `n` if no argument has set it yet (argument `name`, whose shape is
  /// `shape`, e.g. "(4, 7)"), else checks that `n` is that B: "<name> has a batch axis (axis 0)
  /// of n rows (shape ...), but <first name and shape> has B".
  std::string batchAxis(long n, const char* name, const std::string& shape);

  /// Refuses a second keyed constraint block on the same frame: `point` (m, in the tip frame of
  /// `segment`) equal to an earlier keyed block's on the same segment. `label` names the key
  /// ("constraints['tool']") in this message and in later ones: "<label>: the same frame as
  /// <earlier label> (one entry per frame: put all its columns in one alpha)".
  std::string frame(int segment, const Vector3& point, const std::string& label);

  /// Appends a block on `segment` (segment order; -1: see BlockRows) with `alpha` (6, m) per row,
  /// m <= 6 ((6,): one column), named `name` in messages ("alpha", "constraints[2] alpha"). Its
  /// set-point: setPoint().
  std::string block(int segment, ArrayArg alpha, const char* name);

  /// The set-point of the block block() appended: beta (m,) per row, named `name` (nullptr: not
  /// given, which is refused: "beta is required when alpha is given (shape (m,))"; for m = 1 also
  /// a scalar or (B,)), or with classical = true `a` is the frame's classical acceleration (6,) per
  /// row, named "a_desired". Counts the block's columns; a keyed block (`label`, e.g.
  /// "constraints[2]", not "") may not bring its segment's columns (the end segment's alpha
  /// included) beyond 6.
  std::string setPoint(const ArrayArg* a, bool classical, const char* name, const std::string& label);

  /// Whether start() allowed a leading batch axis.
  bool batched() const { return batch_; }

  BatchInput input;  ///< the rows checked so far
  int columns = 0;   ///< constraint columns of every row (the size of nu)

 private:
  struct KeyedFrame {  // a keyed block's frame, for frame()
    int segment;
    Vector3 point;
    std::string label;
  };
  bool batch_ = false;
  const Model* model_ = nullptr;
  std::string first_;               // the argument that set the batch size, and its shape
  std::vector<int> segment_cols_;   // constraint columns per segment (sized at the first keyed block)
  std::vector<KeyedFrame> frames_;  // the frames of the keyed blocks: the first n_frames_ (storage reused)
  std::size_t n_frames_ = 0;
};

}  // namespace vereshchagin
