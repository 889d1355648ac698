#!/usr/bin/env bash
# Runs the power-tower mission headless through launch/simulation.launch (the real nodelets:
# 3 UAV manager processes + world/ground station, LCM between them), records a bag, writes
# metrics.json (the metrics of gfctl simulate, sim::MetricsAccumulator), timeline.csv, events.csv
# and timeline.png, prints a summary and exits (docs/ros.md). LCM stays on this machine:
# everything runs in a private network namespace (unshare -n) whose loopback carries the
# multicast route. Root runs it directly; another user needs sudo, used for that namespace only
# (the launch itself runs as the user, setpriv).
#   tools/run_ros_mission.sh [--out DIR] [--duration S] [--rtf X] [--seed N] [--mission FILE]
#                            [--faults FILE] [--leadership] [--rviz] [--manager-prefix CMD]
#                            [--rss-budget-mb MB] [--camera synthetic|rendered] [--camera-rate HZ]
#                            [--mapping] [--no-prior-map] [--mapping-config FILE]
# --faults: a fault profile (e.g. config/faults/worker_lost_5s.yaml) merged into the mission for
# every nodelet, as gfctl simulate --faults (simulation.launch faults:=).
# --leadership: simulation.launch leadership:=true (the leader hand-over, docs/ros.md; needed by the
# leader_dropout_for_good profile); SimWorld then also writes leadership.csv.
# --manager-prefix: a launch-prefix for each UAV's nodelet manager (simulation.launch manager_prefix:=),
# e.g. --manager-prefix "heaptrack -o /tmp/uav" to profile their memory.
# --rss-budget-mb: each UAV nodelet manager's peak resident set (VmHWM, read from /proc/PID/status
# at the mission's end) must stay within it (tools/run_demo.sh gives 150, the budget of
# docs/design.md §7; default 0: not checked); the summary prints every process's peak either way.
# --camera rendered: every UAV's camera rendered and seen by the Perception nodelet
# (simulation.launch camera:=rendered, frames at --camera-rate, default 5 per simulated second);
# --mapping (needs --camera rendered): every FormationPlanner plans on a live map of its rendered
# depth (simulation.launch mapping:=true), from the scenario's map unless --no-prior-map, with the
# live maps' settings of --mapping-config (default config/mapping.yaml; share.enabled: map sharing).
# Defaults: --out results/demo, the whole mission (451 s), --rtf 2 (sim seconds per wall second).
# Exit code: 0 when the mission finished without a collision and within the memory budget; 1 when
# it did not finish, a UAV collided or a UAV manager exceeded the budget; 2 for bad arguments or a
# missing build.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -eo pipefail  # not -u: devel/setup.bash reads unset variables
cd "$(dirname "$0")/.."
SRC=$PWD
source tools/lib/devel_dir.bash
OUT=results/demo
DURATION=-1
RTF=2.0
SEED=1
MISSION=$SRC/config/scenarios/power_towers.yaml
RVIZ=false
FAULTS=
LEADERSHIP=false
MANAGER_PREFIX=
RSS_BUDGET_MB=0
CAMERA=synthetic CAMERA_RATE=5.0 MAPPING=false MAPPING_PRIOR=true MAPPING_CONFIG=$SRC/config/mapping.yaml
while [ $# -gt 0 ]; do
  case $1 in
    --out) OUT=$2; shift 2 ;;
    --duration) DURATION=$2; shift 2 ;;
    --rtf) RTF=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --mission) MISSION=$(realpath "$2"); shift 2 ;;
    --faults) FAULTS=$(realpath "$2"); [ -f "$FAULTS" ] || { echo "$0: --faults: no file '$2'" >&2; exit 2; }; shift 2 ;;
    --rviz) RVIZ=true; shift ;;
    --leadership) LEADERSHIP=true; shift ;;
    --manager-prefix) MANAGER_PREFIX=$2; shift 2 ;;
    --camera) CAMERA=$2; [ "$2" = synthetic ] || [ "$2" = rendered ] || { echo "$0: --camera: expected synthetic or rendered, got '$2'" >&2; exit 2; }; shift 2 ;;
    --camera-rate) CAMERA_RATE=$2; shift 2 ;;
    --mapping) MAPPING=true; shift ;;
    --no-prior-map) MAPPING_PRIOR=false; shift ;;
    --mapping-config) MAPPING_CONFIG=$(realpath "$2"); [ -f "$MAPPING_CONFIG" ] || { echo "$0: --mapping-config: no file '$2'" >&2; exit 2; }; shift 2 ;;
    --rss-budget-mb) RSS_BUDGET_MB=$2; [[ "$2" =~ ^[0-9]+$ ]] || { echo "$0: --rss-budget-mb: expected whole megabytes (0: no check), got '$2'" >&2; exit 2; }; shift 2 ;;
    *) echo "usage: $0 [--out DIR] [--duration S] [--rtf X] [--seed N] [--mission FILE] [--faults FILE] [--leadership] [--rviz] [--manager-prefix CMD] [--rss-budget-mb MB] [--camera synthetic|rendered] [--camera-rate HZ] [--mapping] [--no-prior-map] [--mapping-config FILE]" >&2; exit 2 ;;
  esac
done
[ "$MAPPING" = false ] || [ "$CAMERA" = rendered ] || { echo "$0: --mapping needs --camera rendered (the live maps integrate the rendered depth)" >&2; exit 2; }
DEVEL=$(gf_devel_dir "$SRC") || exit 2
[ -f "$DEVEL/lib/libgesture_formation_nodelets.so" ] && [ -f "$DEVEL/lib/libgesture_formation_sim_nodelets.so" ] || { echo "$0: $DEVEL lacks the nodelet libraries: build first (tools/build.sh)" >&2; exit 2; }
NETNS=(unshare -n)
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo > /dev/null || { echo "$0: not root and no sudo: the private network namespace (unshare -n) that keeps LCM on this machine needs root" >&2; exit 2; }
  NETNS=(sudo unshare -n)
fi
mkdir -p "$OUT"
OUT=$(realpath "$OUT")
rm -f "$OUT/metrics.json" "$OUT/mission.bag" "$OUT/mission.bag.active"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# Fresh per-sender Ed25519 keys for this run: one owner-only file per bridge (UAVs 0-2, the
# ground station 100), each with its signing key and the others' verifying keys (docs/security.md §5).
tools/make_fleet_keys.sh "$T/keys" 0 1 2 100 > /dev/null
export PATH=/usr/bin:/bin:$PATH
# shellcheck disable=SC1091
source "$DEVEL/setup.bash"
# In the namespace: the loopback with the multicast route (root), then the launch as the caller.
if [ "$(id -u)" -eq 0 ]; then as_caller=""; else as_caller="setpriv --reuid=$(id -u) --regid=$(id -g) --init-groups"; fi
cat > "$T/netns.sh" <<NETNS
set -e
ip link set lo up
ip route add 224.0.0.0/4 dev lo
exec $as_caller bash "$T/inner.sh"
NETNS
# The launch (self-contained: sudo resets the environment).
cat > "$T/inner.sh" <<INNER
export PATH=/usr/bin:/bin:\$PATH
export ROS_MASTER_URI=http://127.0.0.1:11311 ROS_IP=127.0.0.1 ROS_HOME=$T/ros ROS_LOG_DIR=$T/log
export DISPLAY=${DISPLAY:-} XAUTHORITY=${XAUTHORITY:-${HOME:-/root}/.Xauthority}
source "$DEVEL/setup.bash"
roslaunch --screen -p 11311 gesture_formation simulation.launch mission:=$MISSION seed:=$SEED \
  real_time_factor:=$RTF duration:=$DURATION output_dir:=$OUT key_dir:=$T/keys record:=true \
  bag:=$OUT/mission.bag rviz:=$RVIZ faults:=$FAULTS leadership:=$LEADERSHIP manager_prefix:="$MANAGER_PREFIX" \
  camera:=$CAMERA camera_rate:=$CAMERA_RATE mapping:=$MAPPING mapping_prior:=$MAPPING_PRIOR mapping_config:=$MAPPING_CONFIG > "$T/launch.log" 2>&1 &
launch=\$!
# The world writes metrics.json when the mission ends; then stop everything (rosbag closes the bag).
while kill -0 \$launch 2>/dev/null && [ ! -f "$OUT/metrics.json" ]; do sleep 1; done
sleep 2
# CPU time and memory of every process of the launch (nodelet managers: one per UAV + world).
# Columns: pid, CPU time, resident KB now, peak resident KB (VmHWM of /proc/PID/status), args.
ps -eo pid,cputime,rss,args --sort=-cputime | grep -F "$T/log" | grep -E "nodelet manager|record|rosmaster|rviz" | grep -v grep |
  while read -r pid cpu rss args; do
    hwm=\$(awk '/^VmHWM:/ { print \$2 }' /proc/\$pid/status 2>/dev/null)
    echo "\$pid \$cpu \$rss \${hwm:-0} \$args"
  done > "$OUT/processes.txt" || true
kill -INT \$launch 2>/dev/null || true
wait \$launch || true
INNER
start=$(date +%s)
echo "running the mission through simulation.launch (real-time factor $RTF; log: $OUT/launch.log) ..."
"${NETNS[@]}" bash "$T/netns.sh"
cp "$T/launch.log" "$OUT/launch.log"
[ -f "$OUT/metrics.json" ] || { echo "$0: the mission did not finish; see $OUT/launch.log" >&2; tail -30 "$OUT/launch.log" >&2; exit 1; }
tools/plot_mission.sh "$OUT" "$MISSION" "$DEVEL"
# The summary, in the words of gfctl simulate's (same metric definitions: docs/simulation.md §4).
python3 - "$OUT/metrics.json" "$(( $(date +%s) - start ))" "$SEED" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
f = lambda k, u="": f"{m[k]:.2f}{u}" if isinstance(m.get(k), (int, float)) else "n/a"
print(f"seed {sys.argv[3]} through ROS: {f('sim_time_s', ' s')} simulated in {sys.argv[2]} s wall "
      f"(real-time factor {f('real_time_factor')}x after start-up)")
print(f"  min mutual {f('min_mutual_distance_m', ' m')}, min obstacle {f('min_obstacle_distance_m', ' m')}, "
      f"min human {f('min_human_distance_m', ' m')}, collisions {m['collisions']}")
n_operator = m['requests_total'] - m['gestures_performed']
print(f"  requests applied {m['requests_applied']}/{m['requests_total']} (operator {m['operator_requests_applied']}/{n_operator}, "
      f"gestures {m['gesture_requests_applied']}/{m['gestures_performed']}), gesture success {f('gesture_success_rate')}, "
      f"latency {f('gesture_mean_latency_s', ' s')}, false adaptations {m['false_adaptations']}")
print(f"  distance error rms {f('distance_error_rms_m', ' m')}, angle error rms {f('angle_error_rms_deg', ' deg')}, "
      f"estimate error rms {f('human_estimate_error_rms_m', ' m')}, planning median {f('planning_ms_median', ' ms')} "
      f"p99 {f('planning_ms_p99', ' ms')} (fallback previous {m['plans_fallback_previous']}, "
      f"brake {m['plans_fallback_brake']} of {m['plans']})")
PY
echo "  CPU time / memory per process (wall $(( $(date +%s) - start )) s):"
# Each UAV's nodelet manager against the memory budget (peak resident set, VmHWM; docs/design.md §7).
memory_ok=true
python3 - "$OUT/processes.txt" "$RSS_BUDGET_MB" <<'PY2' || memory_ok=false
import re, sys
budget_mb = float(sys.argv[2])
peaks = {}
for line in open(sys.argv[1]):
    f = line.split(None, 4)
    if len(f) < 5:
        continue
    log = re.search(r"__log:=\S*/([^/ ]+?)(-\d+)?\.log", f[4])
    name = log.group(1) if log else f[4].split()[0].split("/")[-1]
    rss_mb, hwm_mb = int(f[2]) / 1024, int(f[3]) / 1024
    if rss_mb < 8:
        continue  # a launch-prefix wrapper (e.g. heaptrack's shell), not the process itself
    print(f"    {name:<24} cpu {f[1]}  rss {rss_mb:.0f} MB  peak {hwm_mb:.0f} MB")
    if re.fullmatch(r"uav\d+-manager", name):
        peaks[name] = max(peaks.get(name, 0.0), hwm_mb)
if not peaks:
    print("  UAV managers' peak RSS: not measured (no UAV manager found)")
    sys.exit(1 if budget_mb > 0 else 0)
worst = max(peaks.values())
listing = ", ".join(f"{n.split('-')[0]} {v:.0f} MB" for n, v in sorted(peaks.items()))
if budget_mb <= 0:
    print(f"  UAV managers' peak RSS (VmHWM): {listing} (no budget checked)")
    sys.exit(0)
verdict = "within" if worst <= budget_mb else "EXCEEDS"
print(f"  UAV managers' peak RSS (VmHWM): {listing}: max {worst:.0f} MB {verdict} the budget of {budget_mb:.0f} MB")
sys.exit(0 if worst <= budget_mb else 1)
PY2
python3 tools/bag_latency.py "$OUT/mission.bag" 2>/dev/null || true
ls -la "$OUT/mission.bag" 2>/dev/null | awk '{print "  bag: " $NF " (" $5 " bytes)"}'
echo "replay: roslaunch gesture_formation replay.launch bag:=$OUT/mission.bag"
collisions=$(python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['collisions'])" "$OUT/metrics.json")
[ -s "$OUT/mission.bag" ] || { echo "$0: FAILED: no bag recorded ($OUT/mission.bag)" >&2; exit 1; }
[ "$collisions" = 0 ] || { echo "$0: FAILED: $collisions collision(s)" >&2; exit 1; }
$memory_ok || { echo "$0: FAILED: a UAV nodelet manager's peak RSS exceeds the budget of $RSS_BUDGET_MB MB (--rss-budget-mb)" >&2; exit 1; }
