// The messages of array_arg.hpp: an array argument that is not finite or not the vector asked for.
#include "vereshchagin/array_arg.hpp"

#include <cmath>

namespace vereshchagin {

std::string nonfiniteMessage(const ArrayArg& a, const char* name) {
  for (long k = 0, n = a.data ? a.size() : 0; k < n; ++k)
    if (!std::isfinite(a.data[k]))
      return std::string(name) + " contains NaN or Inf (flat index " + std::to_string(k) + ")";
  return "";
}

std::string vectorMessage(const ArrayArg& a, const char* name, long n) {
  if (a.ndim != 1 || a.shape[0] != n)
    return std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + a.shapeString();
  return nonfiniteMessage(a, name);
}

}  // namespace vereshchagin
