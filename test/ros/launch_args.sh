#!/bin/bash
# Every launch file answers `roslaunch --ros-args` (exit 0; a file whose arguments cannot even be
# listed is broken for a user), documents every argument (no "undocumented") and resolves with its
# defaults (`--dump-params`; a file that needs arguments may stop at the first unset). onboard.launch
# then resolves with a non-default world_frame and puts it into every nodelet that has one.
set -o pipefail
source "$(dirname "$0")/common.bash"
n=0
for f in "$SRC"/launch/*.launch; do
  n=$((n + 1))
  name=$(basename "$f")
  if ! out=$(timeout 30 roslaunch --ros-args "$f" 2>&1); then
    fail "$name: roslaunch --ros-args failed: $(echo "$out" | tail -3)"
    continue
  fi
  undocumented=$(echo "$out" | grep -E ': undocumented$' | sed 's/^ *//; s/:.*//' | tr '\n' ' ')
  [ -z "$undocumented" ] || fail "$name: arguments without a doc string: $undocumented"  # ... and resolves with its defaults (--ros-args does not evaluate $(eval): worker_estimator.launch
  # could not be launched at all, an $(eval) not a whole attribute); a file that needs arguments
  # stops at the first one unset (Debian's roslaunch says so as "no attribute 'ignore_unset_args'").
  # (roslaunch exits 0 when it cannot load the file: its message is what tells.)
  dump=$(timeout 30 roslaunch --dump-params "$f" 2>&1)
  if echo "$dump" | matches -E "Unable to load file|RLException" && ! echo "$dump" | matches -E "ignore_unset_args|arg to be set"; then
    fail "$name: does not resolve with its defaults: $(echo "$dump" | tail -2)"
  fi
done
[ "$n" -ge 5 ] || fail "only $n launch files found under $SRC/launch"
# world_frame:=map reaches every nodelet of onboard.launch that has a world frame.
params=$(timeout 30 roslaunch --dump-params "$SRC/launch/onboard.launch" key_file:=/dev/null scenario_file:=/dev/null \
  world_frame:=map 2>&1) || fail "onboard.launch --dump-params failed: $(echo "$params" | tail -3)"
for node in formation_planner lcm_bridge view_observer worker_estimator; do
  echo "$params" | matches "^/$node/world_frame: map$" || fail "onboard.launch world_frame:=map not given to $node"
done
echo "$params" | grep -E "/world_frame: " | grep -vq ": map$" && fail "a world_frame other than map remains: $(echo "$params" | grep world_frame)"
# flight_stack:=mavros adds the OdometryAdapter and the SetpointRelay (world_frame given to both); the default adds neither.
args=(key_file:=/dev/null scenario_file:=/dev/null world_frame:=map)
nodes=$(timeout 30 roslaunch --nodes "$SRC/launch/onboard.launch" "${args[@]}" flight_stack:=mavros 2>&1)
for node in odometry_adapter setpoint_relay; do
  echo "$nodes" | matches "^/$node$" || fail "onboard.launch flight_stack:=mavros does not start $node"
done
timeout 30 roslaunch --nodes "$SRC/launch/onboard.launch" "${args[@]}" 2>&1 | matches -E "^/(odometry_adapter|setpoint_relay)$" \
  && fail "onboard.launch without flight_stack starts the flight-stack relay"
params=$(timeout 30 roslaunch --dump-params "$SRC/launch/onboard.launch" "${args[@]}" flight_stack:=mavros 2>&1)
for key in odometry_adapter/world_frame setpoint_relay/world_frame; do
  echo "$params" | matches "^/$key: map$" || fail "onboard.launch flight_stack:=mavros: $key is not map"
done
echo "$params" | matches "^/odometry_adapter/body_frame: base_link$" || fail "flight_stack:=mavros: body_frame is not base_link"
[ "$fails" -eq 0 ] && echo "launch_args: $n launch files, all arguments documented, world_frame reaches every nodelet" \
  || echo "launch_args: $fails failures"
exit $((fails > 0))
