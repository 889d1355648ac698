#!/usr/bin/env bash
# The simulated mission on separate "hosts": one network namespace per UAV and one for the
# world / ground station, each running its part of the real launch file
# (launch/simulation.launch part:=uavN | world) against one ROS master, joined by veth pairs to a
# switch namespace. Between the hosts LCM (the only inter-UAV channel) crosses a lossy radio:
# tools/radio_relay.py drops, delays, jitters (reorders) and duplicates the multicast datagrams
# (this kernel has no netem qdisc: docs/safety.md §5). The ROS connections to the simulated
# world (plant, sensors, /clock — the vehicle itself on real hardware) are routed by the kernel,
# loss-free. Nothing leaves the machine: the namespaces have no link to the host's network.
#   tools/run_multihost.sh [--out DIR] [--duration S] [--rtf X] [--seed N] [--mission FILE]
#                          [--loss P] [--delay-ms D] [--jitter-ms J] [--duplicate P]
# Defaults: --out results/multihost, --duration 120 (simulated s; -1: the whole mission),
# --rtf 1.5, --seed 1, --loss 0.2, --delay-ms 30, --jitter-ms 20, --duplicate 0.01.
# Writes OUT/metrics.json, events.csv, timeline.csv (SimWorld, as gfctl simulate), timeline.png,
# radio.json (relay counters), logs/. Needs root (network namespaces). Exit code: 0 when the mission finished
# without a collision; 1 when it did not finish or a UAV collided; 2 for bad arguments.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -eo pipefail  # not -u: devel/setup.bash reads unset variables
cd "$(dirname "$0")/.."
SRC=$PWD
source tools/lib/devel_dir.bash
OUT=results/multihost
DURATION=120
RTF=1.5
SEED=1
MISSION=$SRC/config/scenarios/power_towers.yaml
LOSS=0.2
DELAY=30
JITTER=20
DUP=0.01
usage="usage: $0 [--out DIR] [--duration S] [--rtf X] [--seed N] [--mission FILE] [--loss P] [--delay-ms D] [--jitter-ms J] [--duplicate P]"
while [ $# -gt 0 ]; do
  [ $# -ge 2 ] || { echo "$usage" >&2; exit 2; }
  case $1 in
    --out) OUT=$2 ;;
    --duration) DURATION=$2 ;;
    --rtf) RTF=$2 ;;
    --seed) SEED=$2 ;;
    --mission) MISSION=$(realpath "$2") ;;
    --loss) LOSS=$2 ;;
    --delay-ms) DELAY=$2 ;;
    --jitter-ms) JITTER=$2 ;;
    --duplicate) DUP=$2 ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
  shift 2
done
[ "$(id -u)" -eq 0 ] || { echo "$0: needs root for the network namespaces (sudo $0 ...)" >&2; exit 2; }
DEVEL=$(gf_devel_dir .) || exit 2
[ -f "$DEVEL/lib/libgesture_formation_nodelets.so" ] && [ -f "$DEVEL/lib/libgesture_formation_sim_nodelets.so" ] || { echo "$0: $DEVEL lacks the nodelet libraries: build first (tools/build.sh)" >&2; exit 2; }
# The relay validates its own arguments (and names the bad one) before anything is set up.
python3 tools/radio_relay.py --links 10.0.0.1,10.0.1.1 --loss "$LOSS" --delay-ms "$DELAY" --jitter-ms "$JITTER" \
  --duplicate "$DUP" --check-only || exit 2
mkdir -p "$OUT/logs"
OUT=$(realpath "$OUT")
rm -f "$OUT/metrics.json" "$OUT/radio.json"
T=$(mktemp -d)
P=gfmh$$
HOSTS=(uav0 uav1 uav2 world)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  sleep 2
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  # Whatever still runs inside a namespace (nodelet managers of an interrupted launch).
  for ns in "${HOSTS[@]}" sw; do
    for p in $(ip netns pids "${P}_$ns" 2>/dev/null); do kill "$p" 2>/dev/null || true; done
  done
  sleep 0.5
  for ns in "${HOSTS[@]}" sw; do ip netns del "${P}_$ns" 2>/dev/null || true; done
  rm -rf "$T"
}
trap cleanup EXIT
trap 'exit 1' INT TERM
# Per-sender Ed25519 keys (docs/security.md §5): each host's bridge gets its own file.
tools/make_fleet_keys.sh "$T/keys" 0 1 2 100 > /dev/null

# Switch namespace; host k = HOSTS[k] on 10.77.k.2/24, its switch port 10.77.k.1.
ip netns add "${P}_sw"
ip netns exec "${P}_sw" ip link set lo up
ip netns exec "${P}_sw" sysctl -qw net.ipv4.ip_forward=1
links=""
for k in "${!HOSTS[@]}"; do
  ns=${P}_${HOSTS[$k]}
  ip netns add "$ns"
  ip link add "${P}h$k" type veth peer name "${P}s$k"
  ip link set "${P}h$k" netns "$ns"
  ip link set "${P}s$k" netns "${P}_sw"
  ip netns exec "${P}_sw" ip addr add "10.77.$k.1/24" dev "${P}s$k"
  ip netns exec "${P}_sw" ip link set "${P}s$k" up
  ip netns exec "$ns" ip link set lo up
  ip netns exec "$ns" ip addr add "10.77.$k.2/24" dev "${P}h$k"
  ip netns exec "$ns" ip link set "${P}h$k" up
  ip netns exec "$ns" ip route add default via "10.77.$k.1"
  ip netns exec "$ns" ip route add 224.0.0.0/4 dev "${P}h$k"
  links="$links${links:+,}10.77.$k.1"
done
ip netns exec "${P}_sw" python3 tools/radio_relay.py --links "$links" --loss "$LOSS" --delay-ms "$DELAY" \
  --jitter-ms "$JITTER" --duplicate "$DUP" --seed "$SEED" --stats "$OUT/radio.json" > "$OUT/logs/radio.log" 2>&1 &
relay=$!
pids+=($relay)

WORLD=3
MASTER=http://10.77.$WORLD.2:11311
export PATH=/usr/bin:/bin:$PATH
in_host() {  # in_host K command...: run in host K's namespace with its ROS environment
  local k=$1; shift
  ip netns exec "${P}_${HOSTS[$k]}" env ROS_MASTER_URI=$MASTER ROS_IP=10.77.$k.2 ROS_HOME="$T/ros_${HOSTS[$k]}" \
    ROS_LOG_DIR="$OUT/logs/ros_${HOSTS[$k]}" bash -c "source '$DEVEL/setup.bash' && $*"
}
in_host $WORLD "exec roscore -p 11311" > "$OUT/logs/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do in_host 0 "rosparam list > /dev/null 2>&1" && break; sleep 0.2; done
in_host 0 "rosparam list > /dev/null 2>&1" || { echo "$0: uav0 cannot reach the master at $MASTER" >&2; exit 1; }
common="mission:=$MISSION seed:=$SEED key_dir:=$T/keys lcm_url:=udpm://239.255.76.67:7667?ttl=1"
for k in 0 1 2; do
  in_host $k "exec roslaunch gesture_formation simulation.launch part:=${HOSTS[$k]} $common" > "$OUT/logs/${HOSTS[$k]}.log" 2>&1 &
  pids+=($!)
done
sleep 3  # the UAVs' managers are up before the world starts the clock
start=$(date +%s)
echo "multi-host mission: 3 UAV namespaces + world, radio loss $LOSS, delay $DELAY ± $JITTER ms, duplicate $DUP (logs: $OUT/logs) ..."
in_host $WORLD "exec roslaunch gesture_formation simulation.launch part:=world $common real_time_factor:=$RTF \
  duration:=$DURATION output_dir:=$OUT" > "$OUT/logs/world.log" 2>&1 &
world=$!
pids+=($world)
while kill -0 $world 2>/dev/null && [ ! -f "$OUT/metrics.json" ]; do sleep 1; done
sleep 1
kill -INT $relay 2>/dev/null || true
wait $relay 2>/dev/null || true
[ -f "$OUT/metrics.json" ] || { echo "$0: the mission did not finish; see $OUT/logs/world.log" >&2; tail -20 "$OUT/logs/world.log" >&2; exit 1; }
tools/plot_mission.sh "$OUT" "$MISSION" "$DEVEL"
python3 - "$OUT" "$(( $(date +%s) - start ))" <<'PY'
import json, sys
out = sys.argv[1]
m = json.load(open(f"{out}/metrics.json"))
r = json.load(open(f"{out}/radio.json")) if __import__("os").path.exists(f"{out}/radio.json") else None
f = lambda k, u="": f"{m[k]:.2f}{u}" if isinstance(m.get(k), (int, float)) else "n/a"
print(f"multi-host: {f('sim_time_s', ' s')} simulated in {sys.argv[2]} s wall")
print(f"  min mutual {f('min_mutual_distance_m', ' m')}, min obstacle {f('min_obstacle_distance_m', ' m')}, "
      f"collisions {m['collisions']}, requests applied {m['requests_applied']}/{m['requests_total']}, "
      f"false adaptations {m['false_adaptations']}, plans {m['plans']}")
if r:
    fwd, drop = sum(r["forwarded"]), sum(r["dropped"])
    print(f"  radio: {sum(r['received'])} datagrams sent by the hosts, {fwd} delivered, {drop} dropped "
          f"({100.0 * drop / max(1, fwd + drop):.1f} %), {sum(r['duplicated'])} duplicated; per host sent "
          f"{r['received']}, delivered to {r['forwarded']}")
PY
collisions=$(python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['collisions'])" "$OUT/metrics.json")
[ "$collisions" = 0 ] || { echo "$0: FAILED: $collisions collision(s)" >&2; exit 1; }
