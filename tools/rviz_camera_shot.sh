#!/bin/bash
# An rviz screenshot of the ROS simulation with rendered cameras (docs/ros.md "Rendered cameras";
# docs/images/rviz_rendered_camera.png): simulation.launch camera:=rendered rviz:=true under Xvfb,
# in a private network namespace (LCM stays on this machine; root), the screen taken WAIT seconds
# of wall time after the launch (the leader's camera image on the left, the 3-D view beside it).
#   tools/rviz_camera_shot.sh OUT.png [--wait S] [--rate HZ] [--rtf F] [--seed N] [--mission FILE] [--mapping]
# --mission: another scenario (default the power towers); --mapping: simulation.launch mapping:=true
# (every UAV's live map of its rendered depth, shown as the live_map_markers cube lists).
# Exit 2: bad arguments, no build, not root; 1: no screenshot.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
set -o pipefail
cd "$(dirname "$0")/.."
SRC=$PWD
source tools/lib/devel_dir.bash
OUT=${1:-}
[ -n "$OUT" ] && [ "${OUT#-}" = "$OUT" ] || { echo "usage: $0 OUT.png [--wait S] [--rate HZ] [--rtf F] [--seed N] [--mission FILE] [--mapping]" >&2; exit 2; }
shift
WAIT=70 RATE=15 RTF=0.33 SEED=1 MISSION= MAPPING=false
while [ $# -gt 0 ]; do
  case $1 in
    --wait) WAIT=$2; shift 2 ;;
    --rate) RATE=$2; shift 2 ;;
    --rtf) RTF=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --mission) MISSION=$(realpath "$2"); [ -f "$MISSION" ] || { echo "$0: --mission: no file '$2'" >&2; exit 2; }; shift 2 ;;
    --mapping) MAPPING=true; shift ;;
    *) echo "$0: unknown argument $1" >&2; exit 2 ;;
  esac
done
[[ $WAIT =~ ^[0-9]+$ ]] || { echo "$0: --wait: expected whole seconds, got '$WAIT'" >&2; exit 2; }
DEVEL=$(gf_devel_dir .) || exit 2
[ -f "$DEVEL/lib/libgesture_formation_sim_camera_nodelets.so" ] || { echo "$0: $DEVEL lacks the simulation nodelets: build first (tools/build.sh)" >&2; exit 2; }
[ "$(id -u)" -eq 0 ] || { echo "$0: needs root (unshare -n keeps LCM on this machine)" >&2; exit 2; }
OUT=$(realpath -m "$OUT")
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
export PATH=/usr/bin:/bin:$PATH
"$SRC/tools/make_fleet_keys.sh" "$T/keys" 0 1 2 100 > /dev/null
cat > "$T/inner.sh" <<INNER
export ROS_MASTER_URI=http://127.0.0.1:14411 ROS_IP=127.0.0.1 ROS_HOME=$T/ros ROS_LOG_DIR=$T/log
source "$DEVEL/setup.bash"
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
xvfb-run -a -s "-screen 0 1200x800x24" bash -c "
  roslaunch -p 14411 gesture_formation simulation.launch key_dir:=$T/keys output_dir:=$T/out duration:=-1 seed:=$SEED \
    real_time_factor:=$RTF camera:=rendered camera_rate:=$RATE rviz:=true mapping:=$MAPPING ${MISSION:+mission:=$MISSION} > $T/launch.log 2>&1 &
  l=\\\$!
  sleep $WAIT
  import -window root '$OUT'
  kill -INT \\\$l; wait \\\$l"
INNER
timeout $((WAIT + 90)) unshare -n bash "$T/inner.sh"
[ -s "$OUT" ] || { echo "$0: no screenshot; the launch said:" >&2; tail -20 "$T/launch.log" >&2; exit 1; }
echo "wrote $OUT"
