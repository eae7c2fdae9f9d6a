// The one main() of every doctest test executable in this directory (linked from the object
// library doctest_main, cpp/tests/CMakeLists.txt). Command line: doctest's own (--help).
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
