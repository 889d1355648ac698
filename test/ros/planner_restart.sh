#!/bin/bash
# A follower's onboard planner restarts (docs/safety.md §2.4; the reboot of gfctl simulate's
# follower_dropout, here in the ROS system): simulation.launch, follower 2's FormationPlanner
# nodelet unloaded at 10 s (sim time) and loaded again at 16 s into the same manager. While it is
# gone its SimUav flies the last plan to its end and holds there, the others avoid that plan;
# loaded again, it knows no plan of the others and must listen before it moves — hold with the
# listening reason at its first replanning, then track — and Γ_dis and no collision hold
# throughout (SimWorld's modes.csv and metrics.json).
set -o pipefail
source "$(dirname "$0")/common.bash"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }
make_key "$T/keys"
mkdir -p "$T/out"
cat > "$T/restart.py" <<'PY'
"""At sim time 10 s unloads /uav2/formation_planner, at 16 s loads it again (test/ros/planner_reload.py).
Prints what it did with the sim times."""
import os
import sys
import time

import rospy

sys.path.insert(0, os.path.join(sys.argv[1], "test/ros"))
import planner_reload  # noqa: E402

rospy.init_node("planner_restart", anonymous=True)
while not rospy.is_shutdown() and rospy.get_time() < 10.0:
    time.sleep(0.02)
failure = planner_reload.unload("/uav2")
if failure is not None:
    print("FAIL: no pid of /uav2/formation_planner:", failure)
    sys.exit(1)
print("unloaded /uav2/formation_planner at %.2f s" % rospy.get_time(), flush=True)
while not rospy.is_shutdown() and rospy.get_time() < 16.0:
    time.sleep(0.02)
planner_reload.load("/uav2", os.path.join(os.path.dirname(os.path.abspath(__file__)), "reload.log"))
print("loaded /uav2/formation_planner again at %.2f s" % rospy.get_time(), flush=True)
rospy.spin()
PY
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p $PORT gesture_formation simulation.launch key_file:=$T/keys output_dir:=$T/out duration:=36 \
  real_time_factor:=1.5 > "$T/launch.log" 2>&1 &
launch=\$!
for _ in \$(seq 50); do rosparam get /use_sim_time > /dev/null 2>&1 && break; sleep 0.2; done
python3 "$T/restart.py" "$SRC" > "$T/restart.log" 2>&1 &
restart=\$!
for _ in \$(seq 140); do [ -f "$T/out/metrics.json" ] && break; sleep 0.5; done
sleep 0.5
cat "$T/restart.log"
python3 - "$T/out" <<'PY'
import csv
import json
import sys

out = sys.argv[1]
bad = 0


def check(ok, what):
    global bad
    print(("PASS: " if ok else "FAIL: ") + what)
    bad += 0 if ok else 1


m = json.load(open(out + "/metrics.json"))
rows = [(float(r["t"]), r["mode"], r["reason"]) for r in csv.DictReader(open(out + "/modes.csv")) if r["uav"] == "2"]
again = [r for r in rows if r[0] >= 16.0]
# Loading takes a few seconds (the map's distance field: ~2.3-2.7 s of sim time here, alone or beside
# two unit-test binaries; up to 10 s allowed for a machine busier than that).
check(len(again) >= 2 and again[0][1] == "hold" and again[0][2].startswith("listening:") and again[0][0] < 26.0,
      "follower 2 listens at its first plan after the restart: %s" % again[:1])
check(len(again) >= 2 and again[1][1] == "track" and again[1][0] - again[0][0] <= 0.85,
      "then tracks within 2 replanning periods: %s" % again[1:2])
# Before the restart: the start's listening (its first plan comes later on a loaded machine), then
# tracking until 16 s — nothing else.
first_track = next((t for t, mode, _ in rows if mode == "track"), None)
check(first_track is not None and first_track < 16.0 and
      all(mode == "hold" and reason.startswith("listening:") for t, mode, reason in rows if t < first_track) and
      not [r for r in rows if first_track < r[0] < 16.0 and r[1] != "track"],
      "no other mode change before the restart (the start's listening, then tracking): %s" % rows)
check(m["sim_time_s"] > 35.0, "the mission ran to its end (%.1f s)" % m["sim_time_s"])
check(m["min_mutual_distance_m"] >= 2.5, "min mutual distance %.2f m >= 2.5" % m["min_mutual_distance_m"])
check(m["collisions"] == 0, "collisions %d" % m["collisions"])
sys.exit(bad)
PY
rc=\$?
kill \$restart 2>/dev/null
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 100 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- the reloading loader's output (reload.log)"; cat "$T/reload.log"
  echo "--- launch.log: errors, warnings and follower 2's planner, the last 40 (not the parameter dump)"
  grep -aE "ERROR|WARN|refuses|formation_planner|UAV 2" "$T/launch.log" | grep -avE '^ \* /' | tail -40; }
exit $rc
