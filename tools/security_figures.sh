#!/usr/bin/env bash
# Measures the link figures of docs/security.md and writes docs/results/security.md:
# the cost per message of HMAC-SHA256 and Ed25519 envelopes (gf_bench_comm) and the legitimate
# messages delivered while a keyless flood saturates the loopback inside a private network
# namespace (tools/link_flood.py: two LcmBridges, 20 Hz worker states, flood processes).
#   tools/security_figures.sh [BUILD_DIR or DEVEL_DIR]     (default: the build tools/lib/devel_dir.bash finds; root: unshare -n; FLOOD_SECONDS (10), FLOOD_PROCS ("2 4"): one run per count of flood processes;
#   FLOOD_IMPLS ("python c"): Python flood processes, then the compiled tools/link_flood_sender.c (sendmmsg))
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
set -eo pipefail
cd "$(dirname "$0")/.."
SRC=$PWD
source tools/lib/devel_dir.bash
DEVEL=$(gf_devel_dir "$SRC" "${1:-}") || exit 2
[ "$(id -u)" -eq 0 ] || { echo "security_figures.sh: needs root (unshare -n keeps the flood on this machine)" >&2; exit 1; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
export PATH=/usr/bin:/bin:$PATH ROS_IP=127.0.0.1 ROS_HOME=$T/ros ROS_LOG_DIR=$T/log
PORT=$((14000 + RANDOM % 1000))
export ROS_MASTER_URI=http://127.0.0.1:$PORT
# shellcheck disable=SC1091
source "$DEVEL/setup.bash"
tools/make_fleet_keys.sh "$T/keys" 0 1 2 > /dev/null
bench=$("$DEVEL/lib/gesture_formation/gf_bench_comm" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true 2>/dev/null | grep -E "_median|^Benchmark|^-" || true)
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roscore -p $PORT > "$T/roscore.log" 2>&1 &
for _ in \$(seq 50); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done
T="$T" SRC="$SRC" /usr/bin/python3 "$SRC/tools/link_flood.py"
rc=\$?
kill %1 2>/dev/null; wait
exit \$rc
INNER
gcc -O2 -Wall -o "$T/flood_sender" tools/link_flood_sender.c
flood=""
for impl in ${FLOOD_IMPLS:-python c}; do
  for n in ${FLOOD_PROCS:-2 4}; do
    flood+="$n flood processes ($impl):"$'\n'"$(FLOOD_IMPL=$impl FLOOD_SENDER=$T/flood_sender FLOODERS=$n unshare -n bash "$T/inner.sh")"$'\n\n'
  done
done
rmem=$(cat /proc/sys/net/core/rmem_max)
out=docs/results/security.md
{
  echo "# Link security figures"
  echo
  echo "Written by \`tools/security_figures.sh\` on $(date -u '+%Y-%m-%d %H:%M UTC'); $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')), load average before the runs $load_before (the machine is shared)."
  echo
  echo "## Cost per message (gf_bench_comm, median of 3; time = wall, CPU = this thread)"
  echo
  echo "Payloads: 113 B (worker state) and 4 424 B (a 50-sample plan). Seal = encode + tag; verify ="
  echo "the whole Verifier path of an accepted envelope; RejectForged = a keyless forgery of a known"
  echo "sender refused at the tag check; RejectUnknownSender = refused before any cryptography."
  echo
  echo '```'
  echo "$bench"
  echo '```'
  echo
  echo "## Legitimate messages delivered under a keyless flood (tools/link_flood.py)"
  echo
  echo "Private network namespace, loopback multicast (ttl 0); leader bridge (sender 0) forwards worker"
  echo "states at 20 Hz for ${FLOOD_SECONDS:-10} s to the follower bridge (sender 2), per-sender Ed25519 keys;"
  echo "flood processes (Python sendto, or C sendmmsg: tools/link_flood_sender.c; one socket each) send as fast as they can on the same channel; they share the"
  echo "2 cores with the bridges, so more of them also means less CPU for the receiver. net.core.rmem_max = $rmem"
  echo "bytes; the bridge reads the group on its own socket (recvmmsg, docs/security.md §7) and asks for a 4 MiB receive buffer."
  echo
  echo '```'
  printf '%s' "$flood"
  echo '```'
  echo
  echo "Columns: flood datagrams sent (as counted by the senders: the Python ones count ENOBUFS drops, the C one only what the kernel took), and the"
  echo "receiving bridge's counters over the same interval. When the counters add up to the datagrams"
  echo "sent, the receiver kept up with the flood and nothing was lost in its socket."
} > "$out"
echo "security_figures.sh: wrote $out"
cat "$out"
