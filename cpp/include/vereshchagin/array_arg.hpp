/// @file
/// A row-major array of doubles with its shape, as a caller hands it over (e.g. the buffer of a
/// float64 numpy array): what the array-based entry points of companion_call.hpp, kinematics.hpp
/// and task.hpp read, and the messages that name such an argument when it is not what they need.
#pragma once

#include <string>

namespace vereshchagin {

/// A row-major (C order) array of doubles with at most 3 dimensions; it does not own `data`.
struct ArrayArg {
  const double* data = nullptr;  ///< the first element (nullptr: no array)
  int ndim = 0;                  ///< the number of dimensions, 0 (a scalar) to 3
  long shape[3] = {0, 0, 0};     ///< the extent of each of the first ndim dimensions

  /// The number of elements: the product of the extents (1 for a scalar).
  long size() const {
    long s = 1;
    for (int k = 0; k < ndim; ++k) s *= shape[k];
    return s;
  }
  /// The shape as Python prints it: "()", "(7,)", "(2, 7)".
  std::string shapeString() const {
    std::string s = "(";
    for (int k = 0; k < ndim; ++k) s += (k ? ", " : "") + std::to_string(shape[k]);
    return s + (ndim == 1 ? ",)" : ")");
  }
};

/// "" if every element of `a` is finite, else "<name> contains NaN or Inf (flat index k)" for the
/// first that is not (k counts in row-major order).
std::string nonfiniteMessage(const ArrayArg& a, const char* name);

/// Why a Python argument `name` that is None (none = true) or a bool cannot be an array:
/// "<name> must be a real array, got None", "<name> must be a real number or array, got bool".
std::string notArrayMessage(const char* name, bool none);

/// Why `name` of Python type `type` could not be read as an array: "<name> must be a real array
/// (numbers of equal-length rows), got <type>", then " (its conversion raised <note>)" unless
/// `note` (the conversion's error, "Type: message") is empty.
std::string unconvertedMessage(const char* name, const std::string& type, const std::string& note);

/// Whether an array of numpy dtype kind `kind` and `ndim` dimensions is a real array the solver
/// takes: kind 'f', 'i' or 'u', at most 3 dimensions.
bool realDtype(char kind, int ndim);

/// "" for an array of numpy dtype kind 'f', 'i' or 'u' (`dtype`: its name) with at most 3
/// dimensions (realDtype), else why not: "<name> must hold real numbers (int or float), got dtype <dtype>",
/// "<name> has <ndim> dimensions; at most 3 are meaningful".
std::string dtypeMessage(const char* name, char kind, const std::string& dtype, int ndim);

/// "" if `a` is a finite vector of shape (n,), else "<name> must have shape (n,), got <shape>" or
/// nonfiniteMessage's.
std::string vectorMessage(const ArrayArg& a, const char* name, long n);

}  // namespace vereshchagin
