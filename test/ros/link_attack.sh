#!/bin/bash
# Attacker test of the inter-UAV link (docs/security.md): two real LcmBridges (leader 0,
# follower 2) with per-sender Ed25519 keys (tools/make_fleet_keys.sh) inside a private network
# namespace (udpm ttl=0), sim time; test/ros/link_attack.py holds follower 1's key and its own
# envelope builder: impersonation, every rejection class on /diagnostics, a leader restarted with
# its clock 10 s behind (faketime), a command replayed after the receiver restarted.
# Exit 77 (skipped) without root or without faketime / python3-cryptography.
set -o pipefail
source "$(dirname "$0")/common.bash"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }
command -v faketime > /dev/null || { echo "SKIP: faketime missing (tools/setup.sh installs it)"; exit 77; }
/usr/bin/python3 -c "import cryptography.hazmat.primitives.asymmetric.ed25519" 2> /dev/null \
  || { echo "SKIP: python3-cryptography missing (tools/setup.sh installs it)"; exit 77; }
"$SRC/tools/make_fleet_keys.sh" "$T/keys" 0 1 2 > /dev/null || { echo "FAIL: make_fleet_keys.sh"; exit 1; }
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roscore -p $PORT > "$T/roscore.log" 2>&1 &
for _ in \$(seq 50); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done
rosparam set /use_sim_time true
T="$T" SRC="$SRC" timeout 150 /usr/bin/python3 "$SRC/test/ros/link_attack.py"
rc=\$?
kill %1 2>/dev/null; wait
exit \$rc
INNER
timeout 180 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || for f in r_bridge l_bridge; do echo "--- $f.log"; tail -8 "$T/$f.log"; done
exit $rc
