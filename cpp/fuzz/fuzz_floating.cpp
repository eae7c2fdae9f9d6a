// libFuzzer target: bytes -> a tree on a floating base (free-flyer or planar) and its inputs ->
// solve, the steps and the companions. Properties in fuzz_checks.hpp.
#include <cstdio>
#include <cstdlib>

#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bad = fuzzutil::checkFloating(data, size);
  if (!bad.empty()) {
    std::fprintf(stderr, "fuzz_floating: property violated: %s\n", bad.c_str());
    std::abort();
  }
  return 0;
}
