#!/bin/bash
# The leader's onboard planner restarts (docs/safety.md §2.4; leadership off, the paper's fixed
# leader): simulation.launch; at 5 s (sim time) an operator request through the ground station and
# LCM (tools/gf_command.py followers distance_m 1), applied by the leader (version 1); at 10 s the
# leader's FormationPlanner nodelet is unloaded and at 13 s loaded again into the same manager. It
# must continue from the parameters it applied — its record of this ROS run (~params_state_file) —
# not from the config's at version 0, which the followers would take: the first parameters it
# publishes after the restart have the version and views it had, follower 1 never receives the
# config's again, and Γ_dis and no collision hold throughout (SimWorld's metrics.json).
set -o pipefail
source "$(dirname "$0")/common.bash"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }
make_key "$T/keys"
mkdir -p "$T/out"
cat > "$T/restart.py" <<'PY'
"""Sends the request at 5 s, unloads /uav0/formation_planner at 10 s and loads it again at 13 s with
the remaps of launch/sim_uav.launch; then checks what the leader publishes and follower 1 receives."""
import os
import subprocess
import sys
import time

import rospy
from gesture_formation.msg import FormationParams

src = sys.argv[1]
sys.path.insert(0, os.path.join(src, "test/ros"))
import planner_reload  # noqa: E402
rospy.init_node("leader_restart", anonymous=True)
leader, follower = [], []
rospy.Subscriber("/uav0/formation_params", FormationParams, lambda m: leader.append((rospy.get_time(), m)))
rospy.Subscriber("/uav1/formation_params", FormationParams, lambda m: follower.append((rospy.get_time(), m)))
bad = 0


def check(ok, what):
    global bad
    print(("PASS: " if ok else "FAIL: ") + what, flush=True)
    bad += 0 if ok else 1


def views(m):
    return [(round(u.beta_deg, 9), round(u.gamma_deg, 9), round(u.distance_m, 9)) for u in m.uavs]


def wait_until(t):
    while not rospy.is_shutdown() and rospy.get_time() < t:
        time.sleep(0.02)


wait_until(5.0)
cli = subprocess.run([sys.executable, os.path.join(src, "tools/gf_command.py"), "followers", "distance_m", "1"],
                     capture_output=True, text=True, timeout=30)
check(cli.returncode == 0 and "applied" in cli.stdout, "the request acknowledged as applied: " + cli.stdout.strip()[:160])
wait_until(10.0)
before = leader[-1][1] if leader else None
check(before is not None and before.version >= 1, "the leader's parameters before the restart: version %s" % (before.version if before else None))
config_views = views(next(m for _, m in leader if m.version == 0)) if any(m.version == 0 for _, m in leader) else None
failure = planner_reload.unload("/uav0")
if failure is not None:
    print("FAIL: no pid of /uav0/formation_planner:", failure)
    sys.exit(1)
t_unload = rospy.get_time()
print("unloaded /uav0/formation_planner at %.2f s" % t_unload, flush=True)
wait_until(13.0)
planner_reload.load("/uav0", os.path.join(os.path.dirname(os.path.abspath(__file__)), "reload.log"))
t_load = rospy.get_time()
print("loaded /uav0/formation_planner again at %.2f s" % t_load, flush=True)
deadline = time.time() + 20
while time.time() < deadline and not [m for t, m in leader if t > t_load]:
    time.sleep(0.1)
wait_until(t_load + 5.0)
after = [m for t, m in leader if t > t_load]
check(bool(after) and before is not None and after[0].version == before.version and views(after[0]) == views(before),
      "the first parameters after the restart: version %s, views %s (before: version %s, views %s)"
      % (after[0].version if after else None, views(after[0]) if after else None,
         before.version if before else None, views(before) if before else None))
received = [m for t, m in follower if t > t_unload]
check(bool(received) and before is not None and all(views(m) == views(before) for m in received),
      "follower 1 received %d parameter messages after the unload, all with the leader's views before it%s"
      % (len(received), "" if config_views is None else " (never the config's %s)" % config_views[1:]))
sys.exit(bad)
PY
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p $PORT gesture_formation simulation.launch key_file:=$T/keys output_dir:=$T/out duration:=26 \
  real_time_factor:=1.5 > "$T/launch.log" 2>&1 &
launch=\$!
for _ in \$(seq 50); do rosparam get /use_sim_time > /dev/null 2>&1 && break; sleep 0.2; done
python3 "$T/restart.py" "$SRC" > "$T/restart.log" 2>&1
rc=\$?
cat "$T/restart.log"
for _ in \$(seq 60); do [ -f "$T/out/metrics.json" ] && break; sleep 0.5; done
python3 - "$T/out" <<'PY' || rc=1
import json
import sys
m = json.load(open(sys.argv[1] + "/metrics.json"))
bad = 0
for ok, what in [(m["min_mutual_distance_m"] >= 2.5, "min mutual distance %.2f m >= 2.5" % m["min_mutual_distance_m"]),
                 (m["collisions"] == 0, "collisions %d" % m["collisions"])]:
    print(("PASS: " if ok else "FAIL: ") + what)
    bad += 0 if ok else 1
sys.exit(bad)
PY
grep -a "continues from parameters version" "$T/launch.log" "$T/reload.log" > /dev/null \
  && echo "PASS: the reloaded planner says it continues from its record" \
  || { echo "FAIL: the reloaded planner did not say it continues from its record"; rc=1; }
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 85 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- the reloading loader's output (reload.log)"; cat "$T/reload.log"
  echo "--- launch.log: errors, warnings and the leader's planner, the last 40 (not the parameter dump)"
  grep -aE "ERROR|WARN|refuses|formation_planner|FormationPlanner" "$T/launch.log" | grep -avE '^ \* /' | tail -40; }
exit $rc
