#!/bin/bash
# Real-time figures of simulation.launch camera:=rendered (docs/ros.md "Rendered cameras"): for
# each camera rate x real-time factor, runs the power-tower mission (seed 1) for WALL seconds of
# wall time after sim time starts, in a private network namespace (LCM stays on this machine;
# root), and measures the sim seconds per wall second reached, each UAV's frames delivered
# against its rate, the frames the leader's Perception processed, how late (sim time) its
# detections come after the instant they show, and SimCamera's wall time per frame (its log).
# A setting "synthetic:RTF" runs camera:=synthetic instead (the sim rate reached without rendering).
# --gestures also flies test/data/sim/rendered_gestures.yaml (58 s: near-misses, then the four
# gestures; seed 1) to its end at 15 Hz, 0.33x and reports its metrics.json: the gestures that
# fired through the rendered cameras, the Perception nodelets and the vote, and the safety figures.
# Appends a dated section to docs/results/ros_camera.md.
#   tools/measure_ros_camera.sh [--wall S] [--configs "RATE:RTF RATE:RTF ..."] [--gestures] [--no-write]
#   (--configs "" --gestures: the gesture mission only)
# Build first (tools/build.sh). Exit 2: bad arguments / no build / not root.
set -o pipefail
cd "$(dirname "$0")/.."
SRC=$PWD
source tools/lib/devel_dir.bash
WALL=40
CONFIGS="synthetic:1.0 3:0.5 5:1.0 10:1.0 15:0.33"
WRITE=1
GESTURES=0
while [ $# -gt 0 ]; do
  case $1 in
    --wall) WALL=$2; shift 2 ;;
    --configs) CONFIGS=$2; shift 2 ;;
    --no-write) WRITE=0; shift ;;
    --gestures) GESTURES=1; shift ;;
    -h | --help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "$0: unknown argument $1" >&2; exit 2 ;;
  esac
done
[[ $WALL =~ ^[0-9]+$ ]] && [ "$WALL" -ge 10 ] || { echo "$0: --wall: expected whole seconds >= 10, got '$WALL'" >&2; exit 2; }
DEVEL=$(gf_devel_dir .) || exit 2
[ -f "$DEVEL/lib/libgesture_formation_sim_camera_nodelets.so" ] || { echo "$0: $DEVEL lacks the simulation nodelets: build first (tools/build.sh)" >&2; exit 2; }
[ "$(id -u)" -eq 0 ] || { echo "$0: needs root (unshare -n keeps LCM on this machine)" >&2; exit 2; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
export PATH=/usr/bin:/bin:$PATH
"$SRC/tools/make_fleet_keys.sh" "$T/keys" 0 1 2 100 > /dev/null
cat > "$T/record.py" <<'PY'
import sys, time
import numpy as np
import rospy
from gesture_formation.msg import WorkerDetection, WorkerState
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Image
wall_s, rate_hz, rtf = float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
rospy.init_node("measure_ros_camera", anonymous=True)
frames = {i: [] for i in range(3)}
dets, est, truth = [], [], []
subs = [rospy.Subscriber("/uav%d/camera/color/image_raw" % i, Image, lambda m, i=i: frames[i].append(m.header.stamp.to_sec()),
                         queue_size=50) for i in range(3)]
subs.append(rospy.Subscriber("/uav0/perception/worker_detection", WorkerDetection,
                             lambda m: dets.append((m.header.stamp.to_sec(), rospy.get_time(), m.detected)), queue_size=50))
subs.append(rospy.Subscriber("/uav0/worker_state", WorkerState,
                             lambda m: est.append((m.header.stamp.to_sec(), m.position)), queue_size=50))
subs.append(rospy.Subscriber("/world/worker_truth", Odometry,
                             lambda m: truth.append((m.header.stamp.to_sec(), m.pose.pose.position)), queue_size=50))
while rospy.get_time() <= 0.0:
    time.sleep(0.05)
w0, s0 = time.time(), rospy.get_time()
time.sleep(wall_s)
w1, s1 = time.time(), rospy.get_time()
for s in subs:
    s.unregister()
span = s1 - s0
err = []  # the leader's estimate against the worker's truth (10 Hz) at the same instant
tt = np.array([t for t, _ in truth])
for t, p in est:
    if s0 <= t <= s1 and len(tt):
        k = int(np.argmin(np.abs(tt - t)))
        if abs(tt[k] - t) < 0.011:
            q = truth[k][1]
            err.append(((p.x - q.x) ** 2 + (p.y - q.y) ** 2 + (p.z - q.z) ** 2) ** 0.5)
errs = "%.2f / %.2f" % (np.median(err), np.max(err)) if err else "-"
got = [len([t for t in frames[i] if s0 <= t <= s1]) for i in range(3)]
d = [x for x in dets if s0 <= x[0] <= s1]
lag = np.median([b - a for a, b, _ in d]) if d else float("nan")
found = sum(1 for x in d if x[2])
if rate_hz <= 0:  # camera:=synthetic: the sim rate only
    print("| synthetic | %.2f | %.2f | - | - | - | - | %s |" % (rtf, span / (w1 - w0), errs))
    sys.exit(0)
print("| %.1f Hz | %.2f | %.2f | %s | %d / %d | %d | %.2f | %s |" % (
    rate_hz, rtf, span / (w1 - w0), " / ".join("%d%%" % round(100 * g / (span * rate_hz)) for g in got),
    len(d), got[0], found, lag, errs))
PY
rows=()
load0=$(cut -d' ' -f1-3 /proc/loadavg)
for c in $CONFIGS; do
  rate=${c%%:*}; rtf=${c##*:}
  camera=rendered
  if [ "$rate" = synthetic ]; then camera=synthetic; rate=0; fi
  rm -rf "$T/log" "$T/out"
  cat > "$T/inner.sh" <<INNER
export ROS_MASTER_URI=http://127.0.0.1:14311 ROS_IP=127.0.0.1 ROS_HOME=$T/ros ROS_LOG_DIR=$T/log
source "$DEVEL/setup.bash"
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p 14311 gesture_formation simulation.launch key_dir:=$T/keys output_dir:=$T/out duration:=-1 \
  real_time_factor:=$rtf camera:=$camera camera_rate:=\$([ $rate = 0 ] && echo 5 || echo $rate) > "$T/launch.log" 2>&1 &
launch=\$!
for _ in \$(seq 100); do rosparam get /use_sim_time > /dev/null 2>&1 && break; sleep 0.2; done
timeout $((WALL + 120)) python3 "$T/record.py" $WALL $rate $rtf
kill -INT \$launch; wait \$launch
INNER
  row=$(timeout $((WALL + 180)) unshare -n bash "$T/inner.sh" | grep '^|')
  ms=$(grep -rhoE "SimCamera uav[0-9]: [0-9]+ frames, mean [0-9.]+ ms" "$T/log" 2>/dev/null | sed -E 's/.*mean ([0-9.]+) ms/\1/' | sort -n |
       awk '{ a[NR] = $1 } END { if (NR) printf "%.0f", a[int((NR + 1) / 2)]; else printf "-" }')
  [ -n "$row" ] || row="| $rate Hz | $rtf | (no figures: see the launch) | | | | | |"
  rows+=("$row $ms |")
  echo "${rows[-1]}"
done
gesture_row=""
if [ "$GESTURES" -eq 1 ]; then
  rm -rf "$T/log" "$T/out"; mkdir -p "$T/out"
  cat > "$T/inner.sh" <<INNER
export ROS_MASTER_URI=http://127.0.0.1:14311 ROS_IP=127.0.0.1 ROS_HOME=$T/ros ROS_LOG_DIR=$T/log
source "$DEVEL/setup.bash"
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p 14311 gesture_formation simulation.launch key_dir:=$T/keys output_dir:=$T/out seed:=1 \
  mission:=$SRC/test/data/sim/rendered_gestures.yaml real_time_factor:=0.33 camera:=rendered camera_rate:=15 > "$T/launch.log" 2>&1 &
launch=\$!
for _ in \$(seq 600); do [ -f "$T/out/metrics.json" ] && break; sleep 1; done
sleep 1
kill -INT \$launch; wait \$launch
INNER
  timeout 700 unshare -n bash "$T/inner.sh"
  gesture_row=$(python3 - "$T/out" <<'PY'
import csv, json, sys
d = sys.argv[1]
try:
    m = json.load(open(d + "/metrics.json"))
    ev = list(csv.DictReader(open(d + "/events.csv")))
except OSError as e:
    print("(no metrics: %s)" % e)
    sys.exit(0)
fired = sorted({e["gesture_id"] for e in ev if e["source"] == "gesture" and e["status"] == "applied"})
print("| %d of %d (fired: %s) | %s | %d | %.2f m | %.2f m | %.2f m | %d |" % (
    m["gestures_successful"], m["gestures_performed"], ", ".join(fired) or "none",
    "%.2f s" % m["gesture_mean_latency_s"] if m["gesture_mean_latency_s"] is not None else "-", m["false_adaptations"],
    m["min_mutual_distance_m"], m["min_obstacle_distance_m"], m["min_human_distance_m"], m["collisions"]))
PY
)
  echo "$gesture_row"
fi
load1=$(cut -d' ' -f1-3 /proc/loadavg)
[ "$WRITE" -eq 1 ] || exit 0
OUT=$SRC/docs/results/ros_camera.md
if [ ! -f "$OUT" ]; then
  cat > "$OUT" <<'HEAD'
# Results: rendered cameras in the ROS simulation — dated measurements

Measurements behind [ros.md](../ros.md) "Rendered cameras", written by
`tools/measure_ros_camera.sh` (power-tower mission, seed 1, from its start; three UAVs, each
with its SimCamera and Perception nodelet; `simulation.launch camera:=rendered`). Columns: the
camera rate and real-time factor asked for; the sim seconds per wall second reached; each UAV's
frames delivered against its rate (leader / follower 1 / follower 2); the leader's Perception
outputs against its frames; the frames in which it found the worker; the median lateness of its
detections in sim time (arrival − the instant the frame shows); SimCamera's mean wall time per
frame (render + read-back + messages; the median over the UAVs' logged means); the leader's
worker estimate against the truth at the same instant (the truth's 10 Hz samples). Frames delivered
count the frames stamped inside the measured sim interval, both ends included (up to one frame over 100 %).
HEAD
fi
{
  echo
  echo "## $(date -u +%Y-%m-%d) — $([ ${#rows[@]} -gt 0 ] && echo "${WALL} s of wall time per setting" || echo "the gesture mission")"
  echo
  echo "$(nproc) cores, load average $load0 before, $load1 after ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'))."
  if [ ${#rows[@]} -gt 0 ]; then
    echo
    echo "| camera rate | RTF asked | sim s / wall s | frames delivered | leader Perception outputs / frames | found | detection lateness [sim s] | estimate error median / max [m] | SimCamera ms / frame |"
    echo "|---|---|---|---|---|---|---|---|---|"
    printf '%s\n' "${rows[@]}"
  fi
  if [ -n "$gesture_row" ]; then
    echo
    echo "test/data/sim/rendered_gestures.yaml to its end (58 s; seed 1; 15 Hz at 0.33x) — the gestures through"
    echo "the rendered cameras, each UAV's Perception nodelet, its ViewObserver and the leader's GestureCommander:"
    echo
    echo "| gestures successful | mean latency | false adaptations | min mutual | min obstacle | min human | collisions |"
    echo "|---|---|---|---|---|---|---|"
    echo "$gesture_row"
  fi
} >> "$OUT"
echo "wrote $OUT"
