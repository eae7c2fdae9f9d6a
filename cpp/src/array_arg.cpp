// The messages of array_arg.hpp: an argument that is no real array, not finite or not the vector
// asked for.
#include "vereshchagin/array_arg.hpp"

#include <cmath>

namespace vereshchagin {

std::string nonfiniteMessage(const ArrayArg& a, const char* name) {
  for (long k = 0, n = a.data ? a.size() : 0; k < n; ++k)
    if (!std::isfinite(a.data[k]))
      return std::string(name) + " contains NaN or Inf (flat index " + std::to_string(k) + ")";
  return "";
}

std::string notArrayMessage(const char* name, bool none) {
  return std::string(name) + (none ? " must be a real array, got None" : " must be a real number or array, got bool");
}

std::string unconvertedMessage(const char* name, const std::string& type, const std::string& note) {
  const std::string why = std::string(name) + " must be a real array (numbers of equal-length rows), got " + type;
  return note.empty() ? why : why + " (its conversion raised " + note + ")";
}

bool realDtype(char kind, int ndim) {
  return (kind == 'f' || kind == 'i' || kind == 'u') && ndim <= 3;
}

std::string dtypeMessage(const char* name, char kind, const std::string& dtype, int ndim) {
  if (realDtype(kind, ndim)) return "";
  if (kind != 'f' && kind != 'i' && kind != 'u')
    return std::string(name) + " must hold real numbers (int or float), got dtype " + dtype;
  return std::string(name) + " has " + std::to_string(ndim) + " dimensions; at most 3 are meaningful";
}

std::string vectorMessage(const ArrayArg& a, const char* name, long n) {
  if (a.ndim != 1 || a.shape[0] != n)
    return std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + a.shapeString();
  return nonfiniteMessage(a, name);
}

}  // namespace vereshchagin
