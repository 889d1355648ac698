#!/bin/bash
# tools/lib/devel_dir.bash finds the build the tools use, in each layout a user has: an explicit
# path (devel space or build directory), GF_DEVEL_DIR, GF_BUILD_DIR, tools/build.sh's build/devel,
# a catkin workspace's devel space, else its install space; and says what is missing otherwise.
set -uo pipefail
SRC=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# shellcheck disable=SC1091
source "$SRC/tools/lib/devel_dir.bash"
fails=0
space() { mkdir -p "$1/lib/gesture_formation" && touch "$1/setup.bash"; }
expect() {  # expect WHAT EXPECTED_PATH ACTUAL
  if [ "$3" = "$2" ]; then echo "ok: $1"; else echo "FAIL: $1: expected '$2', got '$3'"; fails=$((fails + 1)); fi
}
# A source tree with tools/build.sh's layout.
space "$T/repo/build/devel"
expect "build/devel of the source tree" "$T/repo/build/devel" "$(unset GF_DEVEL_DIR GF_BUILD_DIR; gf_devel_dir "$T/repo")"
expect "explicit build directory" "$T/repo/build/devel" "$(gf_devel_dir "$T/elsewhere" "$T/repo/build")"
expect "explicit devel space" "$T/repo/build/devel" "$(gf_devel_dir "$T/elsewhere" "$T/repo/build/devel")"
space "$T/other/devel"
expect "GF_BUILD_DIR" "$T/other/devel" "$(GF_BUILD_DIR=$T/other gf_devel_dir "$T/repo")"
expect "GF_DEVEL_DIR" "$T/other/devel" "$(GF_DEVEL_DIR=$T/other/devel gf_devel_dir "$T/repo")"
# A catkin workspace (catkin_make's marker file; catkin_tools' folder is tried with `catkin locate`).
mkdir -p "$T/ws/src/gesture_formation" && touch "$T/ws/.catkin_workspace"
space "$T/ws/install"
expect "workspace install space" "$T/ws/install" "$(unset GF_DEVEL_DIR GF_BUILD_DIR; gf_devel_dir "$T/ws/src/gesture_formation")"
space "$T/ws/devel"
expect "workspace devel space first" "$T/ws/devel" "$(unset GF_DEVEL_DIR GF_BUILD_DIR; gf_devel_dir "$T/ws/src/gesture_formation")"
# Nothing built: exit 1 and a message naming what to do.
mkdir -p "$T/bare"
msg=$( (unset GF_DEVEL_DIR GF_BUILD_DIR; gf_devel_dir "$T/bare") 2>&1 >/dev/null); rc=$?
[ $rc -ne 0 ] && grep -q "tools/build.sh" <<< "$msg" && echo "ok: nothing built -> $msg" || { echo "FAIL: nothing built: rc $rc, '$msg'"; fails=$((fails + 1)); }
msg=$(GF_BUILD_DIR=$T/bare gf_devel_dir "$T/repo" 2>&1 >/dev/null); rc=$?
[ $rc -ne 0 ] && grep -q "GF_BUILD_DIR=$T/bare" <<< "$msg" && echo "ok: a wrong GF_BUILD_DIR is named" || { echo "FAIL: wrong GF_BUILD_DIR: rc $rc, '$msg'"; fails=$((fails + 1)); }
msg=$(gf_devel_dir "$T/repo" "$T/bare" 2>&1 >/dev/null); rc=$?
[ $rc -ne 0 ] && grep -q "$T/bare" <<< "$msg" && echo "ok: a wrong explicit path is named" || { echo "FAIL: wrong path: rc $rc, '$msg'"; fails=$((fails + 1)); }
exit $fails
