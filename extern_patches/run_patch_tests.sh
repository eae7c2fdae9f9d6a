#!/usr/bin/env bash
# Builds the patched KDL (build_patched_kdl.sh, reused when up to date), then builds and runs
#  * test_patched_kdl:   the patched ChainHdSolver_Vereshchagin against our solver (every patch);
#  * test_unpatched_kdl: Debian's unpatched KDL, to show the defects are really there.
#
# Usage: extern_patches/run_patch_tests.sh [OUT_DIR [VERESHCHAGIN_PREFIX]]   (default: build/patched_kdl)
# VERESHCHAGIN_PREFIX: an installed copy of our library (built against Debian's KDL) that
# test_unpatched_kdl links instead of compiling our sources once more.
set -euo pipefail

HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(dirname "$HERE")"
OUT="${1:-$ROOT/build/patched_kdl}"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"

bash "$HERE/build_patched_kdl.sh" "$OUT"

GEN=()
if command -v ninja > /dev/null; then GEN=(-G Ninja); fi
cmake -S "$HERE/tests" -B "$OUT/tests" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release -DPATCHED_KDL_PREFIX="$OUT/prefix" \
  -DVERESHCHAGIN_PREFIX="${2:-}" > /dev/null
cmake --build "$OUT/tests" -j "${KDL_BUILD_JOBS:-2}"

# One KDL per process: the patched test must load the patched library, not Debian's.
# (ldd's output is captured first: `ldd | grep -q` can fail under pipefail when grep exits early.)
LIBS="$(ldd "$OUT/tests/test_patched_kdl")"
if ! grep -q "liborocos-kdl.so.* => $OUT/prefix/" <<< "$LIBS"; then
  echo "[patch-tests] test_patched_kdl does not load the patched KDL:" >&2
  grep orocos <<< "$LIBS" >&2
  exit 1
fi
"$OUT/tests/test_patched_kdl"
"$OUT/tests/test_unpatched_kdl"
