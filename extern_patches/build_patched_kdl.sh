#!/usr/bin/env bash
# Builds Orocos KDL 1.5.1 with the patch series in extern_patches/orocos_kdl/ applied: the Debian
# source package orocos-kdl 1.5.1-2 (bookworm), library only (no Python bindings, tests, examples or
# docs), Release, into a private prefix.
#
# Usage: extern_patches/build_patched_kdl.sh [OUT_DIR]      (default: build/patched_kdl)
# Result: OUT_DIR/prefix/include/kdl/*.hpp and OUT_DIR/prefix/lib/liborocos-kdl.so*
#         OUT_DIR/src: the patched source tree; OUT_DIR/build: the CMake build tree.
# Environment: KDL_BUILD_JOBS (default 2).
#
# The source package is fetched with `apt-get source --download-only` through a private apt
# configuration (one deb-src line for bookworm main, private lists and cache under OUT_DIR/apt), so
# the machine's apt sources are left untouched; apt checks the files against the signed archive
# index. Needs dpkg-dev (dpkg-source), cmake, a C++ compiler, Eigen 3 (installed when missing and
# running as root or with sudo). A rerun with an unchanged series reuses the previous build.
set -euo pipefail

HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(dirname "$HERE")"
OUT="${1:-$ROOT/build/patched_kdl}"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
JOBS="${KDL_BUILD_JOBS:-2}"
VERSION="1.5.1-2"
PATCHES=("$HERE"/orocos_kdl/[0-9][0-9][0-9][0-9]-*.patch)
PREFIX="$OUT/prefix"
STAMP="$PREFIX/.series.sha256"

series_hash() { cat "${PATCHES[@]}" | sha256sum | cut -d' ' -f1; }

if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$(series_hash)" ] && [ -e "$PREFIX/include/kdl/chainhdsolver_vereshchagin.hpp" ]; then
  echo "[patched-kdl] up to date: $PREFIX"
  exit 0
fi

# ---- tools ----
SUDO=""
if [ "$(id -u)" != "0" ]; then SUDO="sudo"; fi
missing=""
for p in dpkg-dev cmake g++ libeigen3-dev patch; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "[patched-kdl] apt-get install:$missing"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing > /dev/null
fi

# ---- source package (unpacked with Debian's own build-system patches) ----
source "$HERE/kdl_source.sh"
unpack_kdl_source "$OUT" "$VERSION" patched-kdl

# ---- the series ----
for p in "${PATCHES[@]}"; do
  echo "[patched-kdl] applying $(basename "$p")"
  patch -d "$OUT/src" -p1 --forward --no-backup-if-mismatch -s < "$p"
done

# ---- library only ----
GEN=()
if command -v ninja > /dev/null; then GEN=(-G Ninja); fi
rm -rf "$OUT/build" "$PREFIX"
cmake -S "$OUT/src/orocos_kdl" -B "$OUT/build" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DENABLE_TESTS=OFF -DENABLE_EXAMPLES=OFF -DCMAKE_INSTALL_PREFIX="$PREFIX" -DCMAKE_INSTALL_LIBDIR=lib \
  -DCMAKE_POLICY_VERSION_MINIMUM=3.5 > "$OUT/configure.log" 2>&1 || { cat "$OUT/configure.log"; exit 1; }
echo "[patched-kdl] building the orocos-kdl library (-j$JOBS)"
start=$(date +%s)
cmake --build "$OUT/build" --target orocos-kdl -j "$JOBS" > "$OUT/build.log" 2>&1 || { tail -50 "$OUT/build.log"; exit 1; }
echo "[patched-kdl] built in $(( $(date +%s) - start )) s"
# Install the library and its headers only (the project's install rules also cover docs and models).
cmake --install "$OUT/build/src" > "$OUT/install.log" 2>&1 || { cat "$OUT/install.log"; exit 1; }
series_hash > "$STAMP"
echo "[patched-kdl] installed into $PREFIX"
