#!/bin/bash
# Multi-host: tools/run_multihost.sh runs the real launch file split over one network namespace
# per UAV plus one for the world, LCM only through the lossy radio (tools/radio_relay.py: 20 %
# loss per datagram and destination, 30 ± 20 ms delay, 1 % duplicated) — 40 simulated seconds
# with the mission's operator request at 20 s. The formation stays safe (Γ_dis 2.5 m, 0.5 m
# obstacle clearance, no collision), the request crosses the radio and is adapted to by all three
# UAVs, and the radio really was lossy (its counters).
set -o pipefail
SRC=$1
BUILD=$2
DEVEL=${3:-$BUILD/devel}
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (network namespaces)"; exit 77; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
GF_DEVEL_DIR=$DEVEL timeout 130 "$SRC/tools/run_multihost.sh" --out "$T/out" --duration 40 --rtf 1.5 \
  --loss 0.2 --delay-ms 30 --jitter-ms 20 --duplicate 0.01 --seed 3
rc=$?
[ -f "$T/out/metrics.json" ] || { echo "FAIL: no metrics.json (run_multihost.sh rc $rc)"; tail -20 "$T/out/logs/world.log" 2>/dev/null; exit 1; }
python3 - "$T/out" <<'PY'
import csv, json, sys
out = sys.argv[1]
m = json.load(open(f"{out}/metrics.json"))
r = json.load(open(f"{out}/radio.json"))
fails = 0
def check(ok, what):
    global fails
    print(("PASS: " if ok else "FAIL: ") + what)
    fails += 0 if ok else 1
check(abs(m["sim_time_s"] - 40.0) < 0.05, f"the mission ran its 40 s ({m['sim_time_s']})")
check(m["collisions"] == 0, f"no collision ({m['collisions']})")
check(m["min_mutual_distance_m"] >= 2.5, f"min mutual distance {m['min_mutual_distance_m']:.2f} m >= Γ_dis 2.5 m")
check(m["min_obstacle_distance_m"] >= 0.5, f"min obstacle distance {m['min_obstacle_distance_m']:.2f} m >= 0.5 m")
check(m["plans"] > 3 * 2.5 * 30, f"{m['plans']} plans (3 UAVs at 2.5 Hz)")
rows = [x for x in csv.DictReader(open(f"{out}/events.csv")) if x["source"] == "operator" and float(x["t"]) == 20.0]
ok = len(rows) == 1 and rows[0]["status"] == "applied" and rows[0]["uavs"] == "L;1;2" and \
    float(rows[0]["adaptation_start_t"]) < float(rows[0]["applied_t"]) + 2.0
check(ok, "the operator request at 20 s crossed the radio, was applied by the leader and adapted to by all UAVs "
      + (str({k: rows[0][k] for k in ('status', 'applied_t', 'adaptation_start_t', 'uavs')}) if rows else "(no row)"))
sent, fwd, drop = sum(r["received"]), sum(r["forwarded"]), sum(r["dropped"])
frac = drop / max(1, fwd + drop)
check(all(n > 100 for n in r["received"]), f"every host sent over the radio: {r['received']} datagrams")
check(0.15 <= frac <= 0.25, f"the radio dropped {100 * frac:.1f} % of {fwd + drop} deliveries (20 % configured)")
check(sum(r["duplicated"]) > 0, f"{sum(r['duplicated'])} duplicated")
sys.exit(fails)
PY
