// libFuzzer target: bytes -> a KDL chain and solver inputs -> every solver entry point. Properties
// in fuzz_checks.hpp.
#include <cstdio>
#include <cstdlib>

#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bad = fuzzutil::checkSolver(data, size);
  if (!bad.empty()) {
    std::fprintf(stderr, "fuzz_solver: property violated: %s\n", bad.c_str());
    std::abort();
  }
  return 0;
}
