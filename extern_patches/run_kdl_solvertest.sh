#!/usr/bin/env bash
# Acceptance test of the drop-in class (cpp/include/vereshchagin/kdl_compat.hpp): KDL 1.5.1's own
# CppUnit test orocos_kdl/tests/solvertest.cpp, from Debian's source package orocos-kdl 1.5.1-2,
# compiled against the drop-in with only the include and the class name changed (sed, on a copy
# under OUT_DIR; nothing of KDL's source is in this repository), and run.
#
# Usage: extern_patches/run_kdl_solvertest.sh [PREFIX] [OUT_DIR]
#   PREFIX:  an installed vereshchagin (cmake --install); default: build it (library only) into
#            OUT_DIR/prefix.
#   OUT_DIR: default build/kdl_solvertest.
#
# Edits of the copy, and nothing else:
#  * solvertest.hpp: #include <chainhdsolver_vereshchagin.hpp> -> #include <vereshchagin/kdl_compat.hpp>;
#  * solvertest.cpp/.hpp: ChainHdSolver_Vereshchagin -> vereshchagin::kdl_compat::ChainHdSolver_Vereshchagin;
#  * solvertest.hpp: the suite registers only the four tests that use the solver (VereshchaginTest,
#    FdAndVereshchaginSolversConsistencyTest, ExternalWrenchEstimatorTest, UpdateChainTest). The
#    other eleven test KDL's kinematic solvers (Debian's binary, unchanged) and stay compiled.
# Needs libcppunit-dev (.ci/setup), dpkg-dev, and network access for the source package (fetched
# as build_patched_kdl.sh does, through a private apt configuration; reused when present).
set -euo pipefail

HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(dirname "$HERE")"
PREFIX="${1:-}"
OUT="${2:-$ROOT/build/kdl_solvertest}"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
VERSION="1.5.1-2"
GEN=()
if command -v ninja > /dev/null; then GEN=(-G Ninja); fi

# ---- source package (private apt configuration; the machine's sources are not touched) ----
source "$HERE/kdl_source.sh"
unpack_kdl_source "$OUT" "$VERSION" kdl-solvertest "$ROOT/build/patched_kdl/download"

# ---- the copy, swapped to the drop-in ----
TESTS="$OUT/tests"
rm -rf "$TESTS" && mkdir -p "$TESTS"
for f in solvertest.cpp solvertest.hpp test-runner.cpp; do cp "$OUT/src/orocos_kdl/tests/$f" "$TESTS/"; done
sed -i 's|#include <chainhdsolver_vereshchagin.hpp>|#include <vereshchagin/kdl_compat.hpp>|' "$TESTS/solvertest.hpp"
sed -i 's/\bChainHdSolver_Vereshchagin\b/vereshchagin::kdl_compat::ChainHdSolver_Vereshchagin/g' \
  "$TESTS/solvertest.cpp" "$TESTS/solvertest.hpp"
sed -i -E '/CPPUNIT_TEST\( *(VereshchaginTest|FdAndVereshchaginSolversConsistencyTest|ExternalWrenchEstimatorTest|UpdateChainTest) *\)/b; /CPPUNIT_TEST\(/d' \
  "$TESTS/solvertest.hpp"
grep -q "vereshchagin/kdl_compat.hpp" "$TESTS/solvertest.hpp" || { echo "[kdl-solvertest] include not swapped" >&2; exit 1; }
if grep -n "chainhdsolver_vereshchagin.hpp" "$TESTS"/*; then echo "[kdl-solvertest] KDL's solver header still included" >&2; exit 1; fi
[ "$(grep -c "CPPUNIT_TEST(" "$TESTS/solvertest.hpp")" = 4 ] || { echo "[kdl-solvertest] expected 4 registered tests" >&2; exit 1; }

# ---- vereshchagin (library only) when no installed prefix is given ----
if [ -z "$PREFIX" ]; then
  PREFIX="$OUT/prefix"
  cmake -S "$ROOT" -B "$OUT/lib" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release -DVERESHCHAGIN_BUILD_TESTS=OFF \
    -DCMAKE_INSTALL_PREFIX="$PREFIX" > /dev/null
  cmake --build "$OUT/lib" --target vereshchagin -j "${KDL_BUILD_JOBS:-2}"
  cmake --install "$OUT/lib" > /dev/null
fi

cmake -S "$HERE/solvertest" -B "$OUT/build" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PREFIX" \
  -DKDL_TEST_SOURCES="$TESTS" > /dev/null
cmake --build "$OUT/build" -j "${KDL_BUILD_JOBS:-2}"
# KDL's runner prints dots and writes its report (every failed assertion) as XML into the working
# directory; its exit code is 1 on any failure.
rm -f "$OUT/build/"*-result.xml
rc=0
(cd "$OUT/build" && ./solvertest_dropin) || rc=$?
# Every assertion of the four tests must pass; the report is checked so that a missing report or
# a failure fails this stage. (UpdateChainTest's last solver call runs on KDL's massless test chain:
# KDL returns 0 with NaN outputs, the drop-in E_DEGRADED with the smallest q_dotdot, both >= 0.)
python3 - "$OUT/build" "$rc" <<'PY'
import glob
import sys
import xml.etree.ElementTree as ET

build, rc = sys.argv[1], int(sys.argv[2])
reports = glob.glob(build + "/*-result.xml")
if len(reports) != 1:
    sys.exit("[kdl-solvertest] no CppUnit report")
root = ET.parse(reports[0]).getroot()
failed = root.findall("./FailedTests/FailedTest")
passed = root.findall("./SuccessfulTests/Test")
for f in failed:
    line = f.findtext("Location/Line")
    print(f"[kdl-solvertest] FAILED {f.findtext('Name')} line {line}: {(f.findtext('Message') or '').strip()}")
print(f"[kdl-solvertest] passed: {', '.join(sorted(t.findtext('Name') for t in passed))}")
if failed or len(passed) != 4 or rc != 0:
    sys.exit("[kdl-solvertest] FAILED")
PY
echo "[kdl-solvertest] KDL 1.5.1 solvertest (4 Vereshchagin tests) against the drop-in: OK"
