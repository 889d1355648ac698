#!/usr/bin/env bash
# Configures and builds gesture_formation into build/ (plain CMake + Ninja; catkin's CMake
# macros work without a workspace). Extra arguments are passed to ninja (e.g. a target).
#   tools/build.sh            # everything: core, gfctl, nodelets, tests, benchmarks
#   tools/build.sh gfctl      # just the CLI
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -eo pipefail
cd "$(dirname "$0")/.."
# Debian's python3 first: a pyenv shim breaks catkin (docs/toolchain.md, trap 1).
export PATH=/usr/bin:/bin:$PATH
BUILD_DIR=${GF_BUILD_DIR:-build}
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
mkdir -p "$BUILD_DIR"
configure() {
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
    -DCATKIN_DEVEL_PREFIX="$PWD/$BUILD_DIR/devel" -DGF_WERROR=ON > "$BUILD_DIR/configure.log" 2>&1 \
    || { cat "$BUILD_DIR/configure.log"; exit 1; }
}
[ -f "$BUILD_DIR/build.ninja" ] || configure
# catkin's message targets stop with "Please rerun cmake" when a message's dependencies
# changed (e.g. after a pull): configure again once and retry.
if ! ninja -C "$BUILD_DIR" -j"${GF_JOBS:-$(nproc)}" "$@" 2>&1 | tee "$BUILD_DIR/ninja.log"; then  # pipefail: ninja's status
  if grep -q "Please rerun cmake" "$BUILD_DIR/ninja.log"; then
    echo "build.sh: message dependencies changed: configuring again" >&2
    configure
    ninja -C "$BUILD_DIR" -j"${GF_JOBS:-$(nproc)}" "$@"
  else
    exit 1
  fi
fi
