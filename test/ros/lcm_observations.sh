#!/bin/bash
# Gesture observations over LCM between two LcmBridges (private network namespace, udpm ttl=0):
# a follower's observation reaches the leader's gesture_observations_out with every field; one
# claiming another UAV's index (uav_index != envelope sender) is refused and counted; one with an
# id outside the wire's range is not sent (test/ros/lcm_observations_check.py).
set -o pipefail
source "$(dirname "$0")/common.bash"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }
make_key "$T/keys"
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roscore -p $PORT > "$T/roscore.log" 2>&1 &
for _ in \$(seq 50); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done
rosparam set /leader_bridge/known_senders "[0, 1, 2]"
rosparam set /follower_bridge/known_senders "[0, 1, 2]"
common="_lcm_url:=udpm://239.255.76.67:7667?ttl=0 _channel_prefix:=GFT_ _key_file:=$T/keys _max_age_s:=1.0 _heartbeat_rate_hz:=5.0 _world_frame:=world _command_repeats:=5 _command_repeat_period_s:=0.1"
rosrun nodelet nodelet standalone gesture_formation/LcmBridge __name:=leader_bridge _sender_id:=0 \$common \
  gesture_observations_out:=/leader/gesture_observations > "$T/leader.log" 2>&1 &
rosrun nodelet nodelet standalone gesture_formation/LcmBridge __name:=follower_bridge _sender_id:=1 \$common \
  gesture_observation_in:=/follower/gesture_observation > "$T/follower.log" 2>&1 &
for _ in \$(seq 100); do rostopic list 2>/dev/null | grep -q "^/leader/gesture_observations$" && \
  rostopic list 2>/dev/null | grep -q "^/follower/gesture_observation$" && break; sleep 0.2; done
timeout 40 python3 "$SRC/test/ros/lcm_observations_check.py"
rc=\$?
grep -q "gesture observation refused (1 so far): sender 1, uav_index 2" "$T/leader.log" \
  && echo "PASS: the leader's bridge counted the observation claiming UAV 2 from sender 1" \
  || { echo "FAIL: no refusal counted in the leader's bridge log"; rc=\$((rc+1)); }
grep -q "gesture observation not sent: GestureObservation.gesture_id 16" "$T/follower.log" \
  && echo "PASS: the follower's bridge did not send gesture id 16" \
  || { echo "FAIL: gesture id 16 not refused by the follower's bridge"; rc=\$((rc+1)); }
kill %1 %2 %3 2>/dev/null; wait
exit \$rc
INNER
timeout 80 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- leader.log"; tail -5 "$T/leader.log"; echo "--- follower.log"; tail -5 "$T/follower.log"; }
exit $rc
