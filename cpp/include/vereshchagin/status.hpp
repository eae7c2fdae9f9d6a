/// @file
/// Error codes and the status every call of the (model, data, input) API returns.
///
/// The codes keep the numbers of KDL::SolverI (E_SIZE_MISMATCH = -4, ...) and of HdSolver's and
/// FrictionSolver's E_* constants, so a code compares equal whichever face reported it:
/// static_cast<int>(Error::SizeMismatch) == KDL::SolverI::E_SIZE_MISMATCH. The message lives in
/// the object that failed (a Data, a KinematicsData, a Model): no heap allocation on failure.
#pragma once

namespace vereshchagin {

/// Error codes (see the top of this file); None: success.
enum class Error : int {
  None = 0,
  Degraded = 1,               ///< a result was produced, with a documented fallback (e.g. a massless chain)
  NotUpToDate = -3,           ///< the object was built for another model (or the model changed)
  SizeMismatch = -4,          ///< an argument has the wrong size for the model
  OutOfRange = -6,            ///< an index or a value out of its documented range
  NonfiniteInput = -100,      ///< NaN or Inf in an input
  InvalidModel = -101,        ///< the model failed validation (message says why)
  DegenerateInertia = -102,   ///< a joint's articulated inertia D_j <= 0
  TooManyConstraints = -103,  ///< more than 6 columns on one segment, or more than the workspace holds
  NoSolution = -104,          ///< results asked for before a successful solve
  InvalidOptions = -105,      ///< options out of range
  NonfiniteResult = -106,     ///< finite inputs whose results overflow
  ConcurrentCall = -107,      ///< another thread is inside a call on the same Data
  StateOutOfRange = -108,     ///< a state so large that round-off dominates
  InvalidFriction = -110,     ///< friction sizes or values
  NotConverged = -111,        ///< friction iteration bound exceeded, or an unbounded limit reaction
  InvalidContact = -112,      ///< a contact's segment, point, normal, mu, facets or force set-point
  NoContactSolution = -113,   ///< no contact forces meet the contact conditions (or none was found)
};

/// Short name of a code ("SizeMismatch", ...); "Unknown" for a number that is not one.
const char* errorName(Error code) noexcept;

/// What a call returns: its code and, for a failure, a message naming the argument, joint or
/// segment at fault (owned by the object the call wrote; valid until its next call). Test it:
///     if (const Status s = solve(model, data, input); !s) std::puts(s.message);
class [[nodiscard]] Status {
 public:
  constexpr Status() noexcept = default;
  /// A code and its message (not copied: it must outlive the Status).
  constexpr Status(Error code, const char* message) noexcept : code_(code), message_(message) {}
  constexpr Error code() const noexcept { return code_; }              ///< the code
  constexpr const char* message() const noexcept { return message_; }  ///< the message (see the class description)
  /// The KDL::SolverI number of the code (0 on success).
  constexpr int value() const noexcept { return static_cast<int>(code_); }
  /// True on success (Error::None) and on Error::Degraded (a result with a documented fallback).
  constexpr bool ok() const noexcept { return value() >= 0; }
  constexpr explicit operator bool() const noexcept { return ok(); }  ///< ok()

 private:
  Error code_ = Error::None;
  const char* message_ = "";
};

}  // namespace vereshchagin
