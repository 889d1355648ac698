#!/bin/bash
# The install space works on its own (issue 39, docs/toolchain.md "Install space"): `cmake --install`
# of this build into a private DESTDIR, then — in a clean environment that sources only the
# installed setup.bash — the package resolves to the install space, the installed gfctl finds its
# models in the package's share directory (the source tree's models hidden behind GF_MODELS_DIR
# being unset and a working directory without third_party_models), the operator CLI and the plot
# tools run, and two ROS tests run against the install space instead of the devel space:
# onboard_launch (onboard.launch: every nodelet, plans, diagnostics) and flight_stack (the
# OdometryAdapter and the SetpointRelay).
set -o pipefail
source "$(dirname "$0")/common.bash"
ROOT=$T/root
DESTDIR=$ROOT cmake --install "$BUILD" > "$T/install.log" 2>&1 || { echo "FAIL: cmake --install: $(tail -3 "$T/install.log")"; exit 1; }
SETUP=$(find "$ROOT" -maxdepth 4 -name setup.bash -path '*/setup.bash' | head -1)
[ -n "$SETUP" ] || { echo "FAIL: no setup.bash in the install space ($(ls -R "$ROOT" | head -5))"; exit 1; }
PREFIX=$(dirname "$SETUP")
echo "install space: $PREFIX ($(du -sh "$PREFIX" | cut -f1))"
clean_env() {  # a shell that knows only the install space (no devel space, no source tree)
  env -i HOME="$T" PATH=/usr/bin:/bin ROS_HOME="$T/ros" ROS_LOG_DIR="$T/log" bash -c "source '$SETUP' && cd '$T' && $1"
}
pkg=$(clean_env "rospack find gesture_formation" 2>&1)
[ "$pkg" = "$PREFIX/share/gesture_formation" ] || fail "the package resolves to '$pkg', not the install space"
clean_env "rospack plugins --attrib=plugin nodelet" 2>&1 | matches "^gesture_formation $PREFIX/share/gesture_formation/nodelet_plugins.xml$" \
  || fail "the nodelet plugins are not the installed ones"
for f in launch/onboard.launch launch/flight_stack.launch config/ros/nodelets.yaml third_party_models/MODELS.md \
         third_party_models/movenet_lightning/movenet_lightning.onnx; do
  [ -s "$PREFIX/share/gesture_formation/$f" ] || fail "not installed: share/gesture_formation/$f"
done
# gfctl from the install space: the models from its share directory
GFCTL=$PREFIX/lib/gesture_formation/gfctl
[ -x "$GFCTL" ] || fail "no installed gfctl at $GFCTL"
out=$(clean_env "'$GFCTL' detect --image '$SRC/test/data/perception/astronaut.png' --out '$T/a.png' --csv '$T/a.csv'" 2>&1)
echo "$out" | matches "models $PREFIX/share/gesture_formation/third_party_models)" \
  || fail "the installed gfctl does not use the installed models: $(echo "$out" | tail -2)"
# the installed tools (rosrun finds them in the package's lib directory)
for tool in gf_command.py gf_worker.py plot_timeline.py plot_corridors.py plot_search.py bag_latency.py summarize_estimate.py; do
  [ -x "$PREFIX/lib/gesture_formation/$tool" ] || { fail "not installed: lib/gesture_formation/$tool"; continue; }
  [ "$tool" = bag_latency.py ] && continue  # no --help: it reads a bag given as its argument
  clean_env "rosrun gesture_formation $tool --help" > "$T/$tool.help" 2>&1 || fail "rosrun gesture_formation $tool --help: $(tail -2 "$T/$tool.help")"
done
# two ROS tests against the install space (each sources the setup.bash given as its devel space)
for t in onboard_launch flight_stack; do
  if env -i HOME="$T" PATH=/usr/bin:/bin bash "$SRC/test/ros/$t.sh" "$SRC" "$BUILD" "$PREFIX" > "$T/$t.log" 2>&1; then
    echo "PASS: $t on the install space"
  else
    fail "$t on the install space: $(grep -a FAIL "$T/$t.log" | head -5)"
  fi
done
exit $fails
