# Finds gesture_formation's devel (or install) space for the tools (sourced; bash).
#   gf_devel_dir SOURCE_DIR [PATH]   prints the space's absolute path, or returns 1 with a message
# A space is a prefix with setup.bash and lib/gesture_formation/ (gfctl, the benches). Order:
#   1. PATH when given: a space, or a build directory holding devel/ (tools/build.sh's layout);
#   2. $GF_DEVEL_DIR; then $GF_BUILD_DIR/devel when GF_BUILD_DIR is set;
#   3. SOURCE_DIR/build/devel (tools/build.sh);
#   4. the catkin workspace above SOURCE_DIR (a .catkin_tools or .catkin_workspace folder): its
#      devel space (`catkin locate --devel` for catkin_tools), else its install space.
gf_is_space() { [ -f "$1/setup.bash" ] && [ -d "$1/lib/gesture_formation" ]; }

gf_devel_dir() {
  local src=$1 given=${2:-} d space
  if [ -n "$given" ]; then
    if gf_is_space "$given"; then realpath "$given"; return 0; fi
    if gf_is_space "$given/devel"; then realpath "$given/devel"; return 0; fi
    echo "gf_devel_dir: $given is neither a devel/install space nor a build directory with devel/ (build first: tools/build.sh)" >&2
    return 1
  fi
  if [ -n "${GF_DEVEL_DIR:-}" ]; then
    gf_is_space "$GF_DEVEL_DIR" && { realpath "$GF_DEVEL_DIR"; return 0; }
    echo "gf_devel_dir: GF_DEVEL_DIR=$GF_DEVEL_DIR has no setup.bash and lib/gesture_formation/" >&2
    return 1
  fi
  if [ -n "${GF_BUILD_DIR:-}" ]; then
    gf_is_space "$GF_BUILD_DIR/devel" && { realpath "$GF_BUILD_DIR/devel"; return 0; }
    echo "gf_devel_dir: GF_BUILD_DIR=$GF_BUILD_DIR has no devel space (build first: tools/build.sh)" >&2
    return 1
  fi
  gf_is_space "$src/build/devel" && { realpath "$src/build/devel"; return 0; }
  d=$(realpath "$src")
  while [ "$d" != / ]; do
    if [ -d "$d/.catkin_tools" ] || [ -f "$d/.catkin_workspace" ]; then
      if [ -d "$d/.catkin_tools" ] && command -v catkin > /dev/null; then
        space=$(cd "$d" && catkin locate --devel 2> /dev/null) && gf_is_space "$space" && { echo "$space"; return 0; }
      fi
      for space in "$d/devel" "$d/install"; do
        gf_is_space "$space" && { realpath "$space"; return 0; }
      done
      echo "gf_devel_dir: catkin workspace $d has no built gesture_formation (catkin build)" >&2
      return 1
    fi
    d=$(dirname "$d")
  done
  echo "gf_devel_dir: no build found: run tools/build.sh (or catkin build), or set GF_DEVEL_DIR / GF_BUILD_DIR" >&2
  return 1
}
