// libFuzzer target: URDF text -> chainFromUrdfString (both solvers) and treeFromUrdfString. Properties in
// fuzz_checks.hpp.
#include <cstdio>
#include <cstdlib>

#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bad = fuzzutil::checkUrdf(data, size);
  if (!bad.empty()) {
    std::fprintf(stderr, "fuzz_urdf: property violated: %s\n", bad.c_str());
    std::abort();
  }
  return 0;
}
