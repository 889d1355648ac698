#!/usr/bin/env bash
# Installs everything gesture_formation needs on Debian 12 (bookworm): Debian packages,
# ProxQP headers from the `proxsuite` PyPI wheel, and the tools venv (matplotlib, numpy, osqp, mannequin-x).
# Idempotent: a second run checks and returns in seconds. Works as root or through sudo.
#
#   tools/setup.sh            # packages + proxsuite + tools venv
#
# Environment: GF_PREFIX (default /opt/gesture_formation) is where proxsuite and the tools
# venv live; CMakeLists.txt looks there by default.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -eo pipefail

GF_PREFIX="${GF_PREFIX:-/opt/gesture_formation}"
PROXSUITE_VERSION="0.7.2"

die() { echo "setup: $*" >&2; exit 1; }

# --- the OS --------------------------------------------------------------------------
OS_RELEASE=${GF_OS_RELEASE:-/etc/os-release}   # override only for testing this check
[ -r "$OS_RELEASE" ] || die "cannot read $OS_RELEASE; this project supports Debian 12 (bookworm) only"
# shellcheck disable=SC1090
. "$OS_RELEASE"
if [ "${ID:-}" != "debian" ] || [ "${VERSION_ID:-}" != "12" ]; then
  die "unsupported OS '${PRETTY_NAME:-unknown}': this project supports Debian 12 (bookworm) only (ROS 1 comes from Debian's packages)"
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || die "not root and no sudo: run as root or install sudo"
  SUDO="sudo"
fi

# --- Debian packages (list and traps: see docs/toolchain.md) -------------------------
PACKAGES=(
  build-essential cmake ninja-build pkg-config ccache git
  libgtest-dev googletest libbenchmark-dev
  catkin catkin-tools libroscpp-dev libnodeletlib-dev libnodeletlib-tools pluginlib-dev libtf2-ros-dev
  libstd-msgs-dev libsensor-msgs-dev libgeometry-msgs-dev libnav-msgs-dev libvisualization-msgs-dev
  libstd-srvs-dev libtrajectory-msgs-dev libros-rosgraph-msgs-dev
  ros-message-generation ros-message-runtime
  ros-std-msgs ros-geometry-msgs ros-sensor-msgs ros-nav-msgs ros-visualization-msgs ros-std-srvs ros-trajectory-msgs
  librostest-dev python3-rostest python3-roslaunch python3-rostopic python3-rosbag
  python3-rosnode python3-rosservice python3-rosmsg rosbash
  python3-tf2-ros python3-std-srvs python3-geometry-msgs python3-sensor-msgs python3-nav-msgs python3-visualization-msgs python3-tf2-msgs python3-trajectory-msgs
  libeigen3-dev libopencv-dev libopencv-contrib-dev libompl-dev liboctomap-dev libfcl-dev libceres-dev
  libegl-dev libgl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri libassimp-dev   # render/: headless OpenGL (EGL, Mesa llvmpipe), Assimp
  liblcm-dev liblcm-bin libyaml-cpp-dev libssl-dev
  libdiagnostic-msgs-dev ros-diagnostic-msgs python3-diagnostic-msgs   # /diagnostics of every nodelet (docs/ros.md)
  libimage-transport-dev                        # Perception subscribes through image_transport (Debian ships the raw transport only)
  python3-cryptography faketime                 # the attacker test (test/ros/link_attack.sh): its own Ed25519/HMAC envelope builder; a sender restarted with its clock set back
  libcereal-dev libsimde-dev
  python3-venv python3-pip python3-yaml python3-numpy
  python3-matplotlib                            # the installed review tools (plot_timeline.py …) outside the tools venv
  opencv-doc
  rviz xvfb xauth imagemagick graphviz iproute2
  clang libclang-rt-14-dev                      # libFuzzer + ASan/UBSan runtimes for fuzz/ (tools/fuzz/run_fuzzers.sh)
)

missing=()
installed=$(dpkg-query -W -f='${Package} ${Status}\n' 2>/dev/null | awk '$4=="installed"{print $1}' | sort -u)
for p in "${PACKAGES[@]}"; do
  grep -qx -- "$p" <<<"$installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "setup: all ${#PACKAGES[@]} Debian packages present"
fi

# --- tools venv: proxsuite (headers + CMake config), matplotlib, numpy, Dask -----------
# Debian's python3 (not a pyenv shim) so that the venv matches the system ROS Python.
VENV="$GF_PREFIX/venv"
STAMP="$VENV/.gf_requirements"
# dask[distributed] + dask-jobqueue: tools/campaign.py (docs/campaigns.md). osqp: the anchor of the
# trajectory QP's solve times (tools/bench_qp_osqp.py, docs/planning.md §10).
PY_REQS=(matplotlib==3.8.4 numpy==1.26.4 pyyaml==6.0.2 scipy==1.13.1 "dask[distributed]==2026.8.0" dask-jobqueue==0.9.0
         osqp==1.1.3)
MANNEQUIN_VERSION="0.3.0"   # the worker mesh (tools/models/convert_mannequin.py)
REQS="proxsuite==$PROXSUITE_VERSION ${PY_REQS[*]} mannequin-x==$MANNEQUIN_VERSION"
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$REQS" ]; then
  echo "setup: creating tools venv in $VENV ($REQS)"
  $SUDO mkdir -p "$GF_PREFIX"
  $SUDO /usr/bin/python3 -m venv "$VENV"
  $SUDO "$VENV/bin/pip" install -q --disable-pip-version-check --upgrade pip >/dev/null
  # --no-deps for proxsuite: we build against Debian's Eigen, not the cmeel-eigen wheel.
  $SUDO "$VENV/bin/pip" install -q --disable-pip-version-check --no-deps "proxsuite==$PROXSUITE_VERSION"
  $SUDO "$VENV/bin/pip" install -q --disable-pip-version-check "${PY_REQS[@]}"
  # --no-deps for mannequin-x: only its data file is read (its runtime wants numpy >= 2).
  $SUDO "$VENV/bin/pip" install -q --disable-pip-version-check --no-deps "mannequin-x==$MANNEQUIN_VERSION"
  echo "$REQS" | $SUDO tee "$STAMP" >/dev/null
else
  echo "setup: tools venv up to date ($VENV)"
fi
PROX_PREFIX=$("$VENV/bin/python" -c 'import sysconfig,os;print(os.path.join(sysconfig.get_paths()["purelib"],"cmeel.prefix"))')
[ -f "$PROX_PREFIX/lib/cmake/proxsuite/proxsuiteConfig.cmake" ] || die "proxsuite CMake config missing under $PROX_PREFIX"
echo "$PROX_PREFIX" | $SUDO tee "$GF_PREFIX/proxsuite_prefix" >/dev/null
echo "setup: done (proxsuite at $PROX_PREFIX)"
