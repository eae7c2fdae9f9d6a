// Replays the fuzzers' committed inputs (seed corpora and regressions of past findings) through the
// same property checks as the libFuzzer targets, with any compiler: cpp/fuzz/corpus/urdf/* and
// cpp/fuzz/regressions/urdf-* through checkUrdf, cpp/fuzz/corpus/solver/* and
// cpp/fuzz/regressions/solver-* through checkSolver. Arguments: the cpp/fuzz directory.
#include <dirent.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../fuzz/fuzz_checks.hpp"
#include "test_common.hpp"

namespace {

std::vector<std::string> filesIn(const std::string& dir, const std::string& prefix) {
  std::vector<std::string> out;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      const std::string name = e->d_name;
      if (name[0] != '.' && name.compare(0, prefix.size(), prefix) == 0) out.push_back(dir + "/" + name);
    }
    closedir(d);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

int main(int argc, char** argv) {
  testutil::Checker ck("test_fuzz_corpus");
  if (!ck.check(argc == 2, "usage: test_fuzz_corpus <cpp/fuzz directory>")) return ck.finish("");
  const std::string root = argv[1];
  int counts[2] = {0, 0};
  for (int target = 0; target < 2; ++target) {
    const char* kind = target == 0 ? "urdf" : "solver";
    std::vector<std::string> files = filesIn(root + "/corpus/" + kind, "");
    const std::vector<std::string> regressions = filesIn(root + "/regressions", std::string(kind) + "-");
    files.insert(files.end(), regressions.begin(), regressions.end());
    ck.check(files.size() >= 4, std::string("fewer than 4 committed inputs for ") + kind);
    for (const std::string& f : files) {
      const std::string bytes = readFile(f);
      const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
      const std::string bad =
          target == 0 ? fuzzutil::checkUrdf(data, bytes.size()) : fuzzutil::checkSolver(data, bytes.size());
      ck.check(bad.empty(), f + ": " + bad);
      ++counts[target];
    }
  }
  return ck.finish(std::to_string(counts[0]) + " URDF inputs, " + std::to_string(counts[1]) + " solver inputs");
}
