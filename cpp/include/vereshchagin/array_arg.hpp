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

/// "" if `a` is a finite vector of shape (n,), else "<name> must have shape (n,), got <shape>" or
/// nonfiniteMessage's.
std::string vectorMessage(const ArrayArg& a, const char* name, long n);

}  // namespace vereshchagin
