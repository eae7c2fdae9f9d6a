// Replays the fuzzers' committed inputs (seed corpora and regressions of past findings) through the
// same property checks as the libFuzzer targets, with any compiler: cpp/fuzz/corpus/urdf/* and
// cpp/fuzz/regressions/urdf-* through checkUrdf, cpp/fuzz/corpus/solver/* and
// cpp/fuzz/regressions/solver-* through checkSolver, cpp/fuzz/corpus/floating/* and
// cpp/fuzz/regressions/floating-* through checkFloating. Arguments: the cpp/fuzz directory and
// doctest's options (this file has its own main(), to take the directory).
#define DOCTEST_CONFIG_IMPLEMENT
#include <dirent.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "../fuzz/fuzz_checks.hpp"

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

std::string g_root;  // the cpp/fuzz directory (first command-line argument)

// Every committed input of one target (its seed corpus, then its regressions) through `check`.
void replay(const std::string& kind, std::string (*check)(const std::uint8_t*, std::size_t)) {
  REQUIRE_MESSAGE(!g_root.empty(), "usage: test_fuzz_corpus <cpp/fuzz directory> [doctest options]");
  std::vector<std::string> files = filesIn(g_root + "/corpus/" + kind, "");
  const std::vector<std::string> regressions = filesIn(g_root + "/regressions", kind + "-");
  files.insert(files.end(), regressions.begin(), regressions.end());
  CHECK_MESSAGE(files.size() >= 4, "fewer than 4 committed inputs for " << kind);
  for (const std::string& f : files) {
    const std::string bytes = readFile(f);
    const std::string bad = check(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    CHECK_MESSAGE(bad.empty(), f << ": " << bad);
  }
  MESSAGE(files.size() << " " << kind << " inputs");
}

}  // namespace

TEST_CASE("URDF corpus and regressions replay through checkUrdf") {
  replay("urdf", fuzzutil::checkUrdf);
}

TEST_CASE("solver corpus and regressions replay through checkSolver") {
  replay("solver", fuzzutil::checkSolver);
}

TEST_CASE("floating corpus and regressions replay through checkFloating") {
  replay("floating", fuzzutil::checkFloating);
}

// The first argument that is not an option is the cpp/fuzz directory (ctest passes it after
// --test-case=<name>); doctest ignores it and reads the options.
int main(int argc, char** argv) {
  for (int i = 1; i < argc && g_root.empty(); ++i)
    if (argv[i][0] != '-') g_root = argv[i];
  doctest::Context context(argc, argv);
  return context.run();
}
