#!/usr/bin/env bash
# The worker's assistance request in gfctl simulate (docs/safety.md §2.10): the open-field mission
# with gesture 2 (performed at 13 s) mapped to {event: assist_requested}, gesture 4 (leader.gamma_deg
# +5) performed at 24 s and again at 38 s, and the operator's acknowledgement reaching the leader at
# 37 s (mission.assistance_acks_s). Run to 52 s, seed 1. Asserts: one request latched (metrics.json
# assistance) between the gesture's start (13 s) and 24 s, released at 37 s; every gesture command
# fired while it was pending rejected (events.csv) and at least one; the operator's request of 35 s
# applied while it was pending; a gesture command fired after 37 s applied; nothing pending at the end.
# Usage: gfctl_simulate_assistance.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
mkdir -p "$TMP/config/scenarios"
ln -s "$SRC/third_party_models" "$TMP/third_party_models"  # the scenario's gesture_model path is relative
python3 - "$SRC/config/scenarios/open_field.yaml" "$TMP/config/scenarios/assist.yaml" <<'PY'
import sys
text = open(sys.argv[1]).read()
edits = [("      2: {parameter: all.distance_m, increment: 1}\n", "      2: {event: assist_requested}\n"),
         ("      - {t_s: 22, gesture: 2}\n      - {t_s: 40, gesture: 4}\n",
          "      - {t_s: 13, gesture: 2}\n      - {t_s: 24, gesture: 4}\n      - {t_s: 38, gesture: 4}\n"),
         ("mission:\n", "mission:\n  assistance_acks_s: [37]\n")]
for old, new in edits:
    if text.count(old) != 1:
        sys.exit(f"FAIL: open_field.yaml changed: {old!r} found {text.count(old)} times")
    text = text.replace(old, new)
open(sys.argv[2], "w").write(text)
PY
"$GFCTL" simulate --scenario "$TMP/config/scenarios/assist.yaml" --out "$TMP/run" --seed 1 --duration 52 --threads 1 \
  --no-plot > "$TMP/run.log" 2>&1 || { echo "FAIL: gfctl exited $?"; cat "$TMP/run.log"; exit 1; }
python3 - "$TMP/run" <<'PY'
import csv, json, sys
d = sys.argv[1]
m = json.load(open(d + "/metrics.json"))
a = m.get("assistance")
if a is None:
    sys.exit("FAIL: metrics.json has no assistance section")
problems = []
req, ack = a["requested_s"], a["acknowledged_s"]
if len(req) != 1 or not 13.0 <= req[0] <= 24.0: problems.append(f"requests latched at {req}")
if ack != [37.0]: problems.append(f"acknowledged at {ack}")
if a["pending_at_end"]: problems.append("still pending at the end")
events = list(csv.DictReader(open(d + "/events.csv")))
gest = [e for e in events if e["source"] == "gesture" and "assist" not in e["description"]]
during = [e for e in gest if req and req[0] <= float(e["t"]) < 37.0]
after = [e for e in gest if float(e["t"]) >= 37.0]
if not during: problems.append("no gesture command fired while the request was pending")
if any(e["status"] != "rejected" for e in during): problems.append(f"gesture commands while pending: {[(e['t'], e['status']) for e in during]}")
if a["gesture_commands_refused"] != len(during): problems.append(f"refused {a['gesture_commands_refused']} != {len(during)}")
if not any(e["status"] == "applied" for e in after): problems.append(f"no gesture command applied after the acknowledgement: {[(e['t'], e['status']) for e in after]}")
op35 = [e for e in events if e["source"] == "operator" and float(e["t"]) == 35.0]
if len(op35) != 1 or op35[0]["status"] != "applied": problems.append(f"operator request of 35 s: {op35}")
if a["operator_commands_while_pending"] < 1: problems.append(f"operator commands while pending {a['operator_commands_while_pending']}")
if m["collisions"] != 0: problems.append(f"collisions {m['collisions']}")
print(("FAIL " if problems else "ok   ") + "assistance request: " + (", ".join(problems) if problems else
      f"requested at {req[0]:.2f} s, acknowledged at {ack[0]:.0f} s, {len(during)} gesture command(s) rejected while "
      f"pending, the operator's of 35 s applied, {sum(e['status'] == 'applied' for e in after)} applied after"))
sys.exit(1 if problems else 0)
PY
