# Sourced by build_patched_kdl.sh and run_kdl_solvertest.sh: the shared download of Debian's
# orocos-kdl source package.
#
#   unpack_kdl_source OUT VERSION LABEL [CACHED_DOWNLOAD_DIR]
#
# Downloads orocos-kdl=VERSION's source package into OUT/download (with a private apt
# configuration under OUT/apt: the machine's sources are not touched), unless it is there already
# or CACHED_DOWNLOAD_DIR holds it, then unpacks it into OUT/src (the upstream tarball with Debian's
# own build-system patches applied). LABEL prefixes the messages.
unpack_kdl_source() {
  local out="$1" version="$2" label="$3" cached="${4:-}"
  local dsc="$out/download/orocos-kdl_$version.dsc"
  mkdir -p "$out/download"
  if [ ! -f "$dsc" ] && [ -n "$cached" ] && [ -f "$cached/orocos-kdl_$version.dsc" ]; then
    cp "$cached"/orocos-kdl_* "$out/download/"
  fi
  if [ ! -f "$dsc" ]; then
    local apt="$out/apt"
    mkdir -p "$apt/lists/partial" "$apt/cache/archives/partial" "$apt/sources.list.d" "$apt/preferences.d"
    echo "deb-src http://deb.debian.org/debian bookworm main" > "$apt/sources.list"
    local opts=(-o "Dir::Etc::SourceList=$apt/sources.list" -o "Dir::Etc::SourceParts=$apt/sources.list.d"
                -o "Dir::Etc::PreferencesParts=$apt/preferences.d" -o "Dir::State::Lists=$apt/lists"
                -o "Dir::Cache=$apt/cache" -o "APT::Sandbox::User=$(id -un)")
    echo "[$label] apt-get source --download-only orocos-kdl=$version"
    apt-get "${opts[@]}" -qq update
    (cd "$out/download" && apt-get "${opts[@]}" -qq source --download-only "orocos-kdl=$version")
  fi
  rm -rf "$out/src"
  dpkg-source --no-check -x "$dsc" "$out/src" > /dev/null
}
