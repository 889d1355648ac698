#!/usr/bin/env bash
# gfctl simulate with the fault profile loss50 (every inter-UAV message lost with probability 0.5) on
# the power-tower mission shortened to 300 s, seed 26: the case the fault matrix found at 093ec9f.
# There, at 268-270 s the followers missed the leader's heartbeats long enough to elect follower 1,
# whose camera could not see the worker through the tower (the vote compared the followers' share
# ages, equal for both); the new leader searched from its back-off point, the worker stayed unseen
# for the rest of the mission (estimate error RMS 1.85 m at 300 s, the leader's camera saw him in 41 %
# of the frames after 250 s). A UAV now stands and votes with the fresher of its worker state and its
# own camera's last detection (docs/safety.md §1.2), so one that cannot see him does not take the lead
# from one that can. Asserts: the acting leader's camera sees the worker in >= 90 % of the frames
# from 250 s, the estimate error RMS <= 0.5 m, never two acting, no collision, mutual distance
# >= Gamma_dis 2.5 m, worker distance >= 2.5 m, obstacle distance >= 0.5 m.
# Then seed 23 to 45 s: an operator request arriving while the leader's lease has lapsed is applied
# when it acts again in the same term (below), and seed 2 to 90 s: so is a gesture command fired then.
# Usage: gfctl_simulate_lossy_leadership.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
simulate() {  # simulate SEED DURATION DIR: the power-tower mission under loss50
  "$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --fault-profile loss50 \
    --out "$3" --seed "$1" --duration "$2" --threads 1 --no-plot > "$3.log" 2>&1 \
    || { echo "FAIL: gfctl exited $? (seed $1)"; cat "$3.log"; exit 1; }
}
simulate 26 300 "$TMP/run"
python3 - "$TMP/run" <<'PY'
import csv, json, sys
d = sys.argv[1]
m = json.load(open(d + "/metrics.json"))
l = m["leadership"]
rows = list(csv.DictReader(open(d + "/timeline.csv")))
late = [r for r in rows if float(r["t"]) >= 250]
seen = sum(int(r["visible"]) for r in late) / max(len(late), 1)
problems = []
if seen < 0.9: problems.append(f"the acting leader's camera saw the worker in {100 * seen:.0f} % of the frames from 250 s")
if m["human_estimate_error_rms_m"] > 0.5: problems.append(f"estimate error RMS {m['human_estimate_error_rms_m']:.2f} m > 0.5")
if l["max_acting"] != 1 or l["steps_two_acting"] != 0:
    problems.append(f"max acting {l['max_acting']}, steps with two acting {l['steps_two_acting']}")
if m["collisions"] != 0: problems.append(f"collisions {m['collisions']}")
if m["min_mutual_distance_m"] < 2.5: problems.append(f"min mutual {m['min_mutual_distance_m']:.2f} < 2.5")
if m["min_human_distance_m"] < 2.5: problems.append(f"min worker distance {m['min_human_distance_m']:.2f} < 2.5")
if m["min_obstacle_distance_m"] < 0.5: problems.append(f"min obstacle {m['min_obstacle_distance_m']:.2f} < 0.5")
print(("FAIL " if problems else "ok   ") + "loss50 seed 26 to 300 s: " + (", ".join(problems) if problems else
      f"worker seen in {100 * seen:.1f} % of the frames from 250 s, estimate error RMS {m['human_estimate_error_rms_m']:.3f} m, "
      f"{l['elections_won']} election(s) won, never two acting, min mutual {m['min_mutual_distance_m']:.2f} m"))
sys.exit(1 if problems else 0)
PY
# Seed 23 to 45 s: the lease of UAV 0 lapses (no acting leader) just as the operator's request of 20 s
# arrives; it acts again in the same term a moment later. It keeps the request and applies it then
# (onboard::ParamsOwnership::keepsCommand): every operator request of the run applied (at 093ec9f the
# request of 20 s was lost).
simulate 23 45 "$TMP/run23"
python3 - "$TMP/run23" <<'PY'
import csv, json, sys
d = sys.argv[1]
ops = [e for e in csv.DictReader(open(d + "/events.csv")) if e["source"] == "operator"]
l = json.load(open(d + "/metrics.json"))["leadership"]
gaps = [x for x in l["leaders"] if x["uav"] == -1 and x["from_s"] <= 20.1 <= x["to_s"]]
problems = []
if not gaps: problems.append("no leaderless gap at 20.1 s: the case this checks did not occur (the mission changed?)")
lost = [f"{e['t']} {e['description']} {e['status']}" for e in ops if e["status"] != "applied"]
if len(ops) < 2 or lost: problems.append(f"operator requests not applied: {lost} of {len(ops)}")
if l["steps_two_acting"] != 0: problems.append(f"steps with two acting {l['steps_two_acting']}")
print(("FAIL " if problems else "ok   ") + "loss50 seed 23 to 45 s: " + (", ".join(problems) if problems else
      f"the request of 20 s arrived in the gap {gaps[0]['from_s']}-{gaps[0]['to_s']} s and was applied; {len(ops)}/{len(ops)} applied"))
sys.exit(1 if problems else 0)
PY
# Seed 2 to 90 s: the worker's first gesture fires at 75.33 s while UAV 0's lease has lapsed
# (75.14-76.82 s); the command waits and is applied when it acts again in the same term (at 093ec9f it
# was lost; the filter re-arms only after the gesture is released, so it never fired again).
simulate 2 90 "$TMP/run2"
python3 - "$TMP/run2" <<'PY'
import csv, json, sys
d = sys.argv[1]
g = [e for e in csv.DictReader(open(d + "/events.csv")) if e["source"] == "gesture"]
l = json.load(open(d + "/metrics.json"))["leadership"]
problems = []
if len(g) != 1: problems.append(f"{len(g)} gesture commands fired (expected the one of ~75 s)")
else:
    t = float(g[0]["t"])
    gap = [x for x in l["leaders"] if x["uav"] == -1 and x["from_s"] <= t <= x["to_s"]]
    if not gap: problems.append(f"the gesture fired at {t} s with a leader acting: the case this checks did not occur")
    if g[0]["status"] != "applied": problems.append(f"the gesture command fired at {t} s: {g[0]['status']}")
if l["steps_two_acting"] != 0: problems.append(f"steps with two acting {l['steps_two_acting']}")
print(("FAIL " if problems else "ok   ") + "loss50 seed 2 to 90 s: " + (", ".join(problems) if problems else
      f"the gesture command fired at {g[0]['t']} s in a lease gap, applied at {g[0]['applied_t']} s"))
sys.exit(1 if problems else 0)
PY
