#!/bin/bash
# simulation.launch end to end (3 UAV managers + world, LCM inside a private network namespace):
# every stream publishes at its rate (sim time); a gesture injected at 1 of the 3 UAVs' classifiers
# changes nothing, injected at 2 of 3 (the followers: votes over LCM) it changes the followers'
# formation parameters and planned references through LCM (test/ros/sim_check.py);
# every planner, the estimator and every bridge report on /diagnostics at ~1 Hz (diagnostics_check.py);
# at the end (40 s) SimWorld's metrics.json / events.csv / timeline.csv carry gfctl simulate's
# metrics, with the requests followed to their adaptation (test/ros/check_sim_metrics.py).
set -o pipefail
source "$(dirname "$0")/common.bash"
need_netns
sim_inner_start duration:=40 gesture_prefix:=/world/unused
cat >> "$T/inner.sh" <<INNER
timeout 80 python3 "$SRC/test/ros/sim_check.py"
rc=\$?
timeout 20 python3 "$SRC/test/ros/diagnostics_check.py" || rc=\$((rc+1))
# The operator's CLI: a valid command is sent (reaches follower 2 over LCM and is acknowledged by
# the leader), a bad one refused.
# The mission's own request at t = 20 s (all.distance_m -1) changes the distances too: the command
# is sent once that request has been applied (sim time >= 21 s; the next request is at 40 s), and
# follower 2's distance must go from its value then (8 = 8 + 1 (gesture) - 1 (request)) up by 1.
timeout 40 python3 -c "
import rospy, time
from gesture_formation.msg import FormationParams as F
rospy.init_node('d2', anonymous=True)
seen = []
sub = rospy.Subscriber('/uav2/formation_params', F, lambda m: seen.append(m.uavs[2].distance_m))
t0 = time.time()
while (rospy.get_time() < 21.0 or not seen) and time.time() - t0 < 30:
    time.sleep(0.05)
before = seen[-1] if seen else None
n = len(seen)
open('$T/d2.ready', 'w').write(repr(before))
t1 = time.time()
while time.time() - t1 < 10 and not any(d != before for d in seen[n:]):
    time.sleep(0.05)
after = [d for d in seen[n:] if d != before]
print(before, after[0] if after else None)" > "$T/d2.txt" 2>/dev/null &
watch=\$!
for _ in \$(seq 400); do [ -f "$T/d2.ready" ] && break; sleep 0.1; done
python3 "$SRC/tools/gf_command.py" followers distance_m 1 > "$T/ack.txt" 2>&1 || { echo "FAIL: gf_command.py followers distance_m 1: \$(cat "$T/ack.txt")"; rc=\$((rc+1)); }
# ... and the leader acknowledges it over LCM (docs/safety.md §2.9): gf_command.py prints the outcome.
grep -q "^acknowledged by the leader: applied (parameters version [0-9]*)$" "$T/ack.txt" \
  && echo "PASS: the leader acknowledged the operator's command: \$(tail -1 "$T/ack.txt")" \
  || { echo "FAIL: no acknowledgement of the operator's command: \$(cat "$T/ack.txt")"; rc=\$((rc+1)); }
wait \$watch
d2=\$(cat "$T/d2.txt")
[ "\$d2" = "8.0 9.0" ] && echo "PASS: operator command via tools/gf_command.py at sim t >= 21 s: follower 2 d 8.0 -> 9.0 m over LCM" \
  || { echo "FAIL: follower 2 d not 8.0 -> 9.0 after the operator command (got '\$d2': before, after)"; rc=\$((rc+1)); }
python3 "$SRC/tools/gf_command.py" follower7 distance_m 1 2>&1 | grep -q "refused" && echo "PASS: bad target refused by the OperatorInterface" \
  || { echo "FAIL: follower7 not refused"; rc=\$((rc+1)); }
# SimWorld writes its files when the 40 s are over.
for _ in \$(seq 80); do [ -f "$T/out/metrics.json" ] && break; sleep 0.5; done
sleep 0.5
python3 "$SRC/test/ros/check_sim_metrics.py" "$T/out" || rc=\$((rc+1))
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 85 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- launch.log (errors, commands)"; grep -aE "ERROR|refuses|FAIL|command" "$T/launch.log" | grep -v "^ \*\|_command" | head -20; }
exit $rc
