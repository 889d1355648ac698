#!/usr/bin/env bash
# tools/campaign.py on a real Dask cluster on 127.0.0.1 (a `dask scheduler` and two `dask worker`
# processes) with short missions of config/scenarios/open_field.yaml (--duration 20):
#  1. one worker killed with kill -9 (by pid) while it runs a mission: the campaign ends with every
#     mission in the store exactly once, the killed worker's mission re-run on the other worker,
#     and no gfctl left behind;
#  2. the tool killed with kill -9 mid-campaign, then the same command again: it runs only the
#     missions not stored, rows stored before are unchanged, no duplicate, no loss;
#  3. a mission's row equals `gfctl simulate` run by hand (metrics.json, wall-clock keys aside);
#  4. a mission with a bad config value (gfctl exit 2) and one over its timeout are stored as
#     failures with their log tails and counted (exit 1), not dropped;
#  5. the default local cluster (started and stopped by the tool; killed with the tool and resumed),
#     and a worker whose gfctl differs from the client's (stored as a mismatch, the run stops);
#  6. a corrupt store, a foreign SQLite file and a non-SQLite file are refused (exit 2, a clear
#     error) and left byte-for-byte untouched.
# Skipped (exit 77) when gfctl is not built or the tools venv is missing.
# Usage: campaign_dask.sh GFCTL SRC
set -uo pipefail
GFCTL=$1
SRC=$2
PY=/opt/gesture_formation/venv/bin/python
DASK=/opt/gesture_formation/venv/bin/dask
[ -x "$GFCTL" ] || { echo "SKIP: gfctl not built ($GFCTL)"; exit 77; }
[ -x "$PY" ] || { echo "SKIP: no tools venv ($PY): tools/setup.sh"; exit 77; }
"$PY" -c "import distributed, yaml" 2>/dev/null || { echo "FAIL: the tools venv has no Dask: run tools/setup.sh"; exit 1; }
T=$(mktemp -d)
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null; done
  wait 2>/dev/null
  rm -rf "$T"
}
trap cleanup EXIT
fails=0
passes=0
pass() { echo "PASS: $*"; passes=$((passes + 1)); }
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
C="$PY $SRC/tools/campaign.py"
export GFCTL
q() {  # q STORE SQL: one value
  "$PY" - "$@" <<'P'
import sqlite3, sys
con = sqlite3.connect(f"file:{sys.argv[1]}?mode=ro", uri=True)
print(con.execute(sys.argv[2]).fetchone()[0])
P
}
campaign() {  # campaign FILE NAME SEEDS [extra yaml lines]
  { echo "name: $2"; echo "scenarios: [config/scenarios/open_field.yaml]"; echo "profiles: [nominal, loss30]"
    echo "seeds: $3"; echo "duration_s: 20"; echo "timeout_s: 300"; shift 3; for l in "$@"; do echo "$l"; done; } > "$T/$1"
}
wait_rows() {  # wait_rows STORE N SECONDS: until the store has >= N missions
  local end=$((SECONDS + $3))
  while [ $SECONDS -lt $end ]; do
    [ -f "$1" ] && [ "$(q "$1" 'SELECT COUNT(*) FROM missions' 2>/dev/null || echo 0)" -ge "$2" ] && return 0
    sleep 0.3
  done
  return 1
}

# ---- a scheduler and two workers on 127.0.0.1 -------------------------------------------
PORT=$("$PY" -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
SCHED=tcp://127.0.0.1:$PORT
"$DASK" scheduler --host 127.0.0.1 --port "$PORT" --no-dashboard > "$T/scheduler.log" 2>&1 &
PIDS+=($!)
start_worker() {  # start_worker NAME -> WPID
  "$DASK" worker "$SCHED" --host 127.0.0.1 --nthreads 1 --no-nanny --no-dashboard --name "$1" \
    --local-directory "$T/$1" > "$T/$1.log" 2>&1 &
  WPID=$!
  PIDS+=("$WPID")
}
start_worker w1
W1=$WPID
start_worker w2
W2=$WPID
"$PY" - "$SCHED" <<'P' || { echo "FAIL: the cluster did not come up"; cat "$T"/*.log; exit 1; }
import sys
from distributed import Client
with Client(sys.argv[1], timeout=60) as c:
    c.wait_for_workers(2, timeout=60)
P
echo "cluster: scheduler $SCHED, workers w1 pid $W1, w2 pid $W2"

# ---- 1. a worker killed with kill -9 mid-run ----------------------------------------------
campaign kill_worker.yaml kill_worker 1..5
S1=$T/s1.sqlite
(cd "$SRC" && $C --store "$S1" run "$T/kill_worker.yaml" --scheduler "$SCHED" --work-dir "$T/work" > "$T/run1.log" 2>&1; echo $? > "$T/run1.rc") &
TOOL=$!
PIDS+=("$TOOL")
victim=""
end=$((SECONDS + 120))
while [ $SECONDS -lt $end ] && [ -z "$victim" ]; do  # w1 busy with a mission, one mission stored
  g=$(pgrep -P "$W1" -f "gfctl simulate" | head -1)
  if [ -n "$g" ] && [ -f "$S1" ] && [ "$(q "$S1" 'SELECT COUNT(*) FROM missions' 2>/dev/null || echo 0)" -ge 1 ]; then
    args=$(tr '\0' ' ' < "/proc/$g/cmdline" 2>/dev/null)
    vdir=$(dirname "$(sed -E 's/.*--scenario ([^ ]+).*/\1/' <<<"$args")")
    vprofile=nominal
    cmp -s "$vdir/faults.yaml" "$SRC/config/faults/loss30.yaml" 2>/dev/null && vprofile=loss30
    if [ -n "$args" ] && kill -0 "$g" 2>/dev/null; then  # still running: kill its worker now
      kill -9 "$W1"
      victim=$g
      vseed=$(sed -E 's/.*--seed ([0-9]+).*/\1/' <<<"$args")
    fi
  else
    sleep 0.2
  fi
done
if [ -z "$victim" ]; then
  fail "worker w1 never ran a mission after the first was stored"; cat "$T/run1.log"
else
  echo "killed worker w1 (pid $W1) while it ran $vprofile seed $vseed (gfctl pid $victim)"
  wait "$TOOL"
  rc=$(cat "$T/run1.rc")
  n=$(q "$S1" 'SELECT COUNT(*) FROM missions')
  distinct=$(q "$S1" "SELECT COUNT(DISTINCT profile || ':' || seed) FROM missions")
  [ "$rc" = 0 ] && [ "$n" = 10 ] && [ "$distinct" = 10 ] && pass "worker killed: exit 0, 10 missions stored, each once" \
    || { fail "worker killed: exit $rc, $n rows, $distinct distinct (want 0, 10, 10)"; tail -20 "$T/run1.log"; }
  by=$(q "$S1" "SELECT worker FROM missions WHERE profile = '$vprofile' AND seed = $vseed")
  [ "${by##*:}" = "$W2" ] && pass "the killed worker's mission ($vprofile seed $vseed) re-ran on w2" \
    || fail "the killed worker's mission was stored from '$by', not w2 (pid $W2)"
  sleep 1
  kill -0 "$victim" 2>/dev/null && fail "the killed worker's gfctl (pid $victim) still runs" \
    || pass "the killed worker's gfctl did not outlive it"
  [ "$(q "$S1" 'SELECT COUNT(*) FROM failures')" = 0 ] && pass "a lost task is re-run, not stored as a failure" \
    || fail "failures recorded: $(q "$S1" 'SELECT group_concat(status) FROM failures')"
fi
start_worker w3  # two workers again

# ---- 2. the tool killed with kill -9, then resumed ---------------------------------------
campaign resume.yaml resume 1..6
S2=$T/s2.sqlite
(cd "$SRC" && exec $C --store "$S2" run "$T/resume.yaml" --scheduler "$SCHED" --work-dir "$T/work" > "$T/run2.log" 2>&1) &
TOOL=$!
PIDS+=("$TOOL")
if wait_rows "$S2" 3 180; then
  kill -9 "$TOOL"
  wait "$TOOL" 2>/dev/null
  before=$(q "$S2" 'SELECT COUNT(*) FROM missions')
  dump() { "$PY" - "$S2" <<'P'
import json, sqlite3, sys
con = sqlite3.connect(f"file:{sys.argv[1]}?mode=ro", uri=True)
con.row_factory = sqlite3.Row
print(json.dumps({f"{r['profile']}:{r['seed']}": dict(r) for r in con.execute("SELECT * FROM missions")}, sort_keys=True))
P
  }
  dump > "$T/before.json"
  echo "tool killed with $before of 12 missions stored"
  (cd "$SRC" && $C --store "$S2" run "$T/resume.yaml" --scheduler "$SCHED" --work-dir "$T/work" > "$T/run3.log" 2>&1)
  rc=$?
  n=$(q "$S2" 'SELECT COUNT(*) FROM missions')
  distinct=$(q "$S2" "SELECT COUNT(DISTINCT profile || ':' || seed) FROM missions")
  [ "$rc" = 0 ] && [ "$n" = 12 ] && [ "$distinct" = 12 ] && pass "resumed: exit 0, 12 missions, each once" \
    || { fail "resumed: exit $rc, $n rows, $distinct distinct (want 0, 12, 12)"; tail -20 "$T/run3.log"; }
  grep -q "12 missions, $before already in" "$T/run3.log" && pass "the resumed run skipped the $before stored missions" \
    || { fail "the resumed run did not report $before already stored"; head -3 "$T/run3.log"; }
  dump > "$T/after.json"
  "$PY" - "$T/before.json" "$T/after.json" <<'P' && pass "the $before rows stored before the kill are unchanged" || fail "rows stored before the kill changed"
import json, sys
before, after = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
sys.exit(0 if before and all(after.get(k) == v for k, v in before.items()) else 1)
P
  again=$(cd "$SRC" && $C --store "$S2" run "$T/resume.yaml" --scheduler "$SCHED" --work-dir "$T/work" 2>&1)
  grep -q "12 already in .* 0 to run" <<<"$again" && pass "a third run runs nothing" || fail "third run: $again"
else
  fail "no 3 missions stored within 180 s"; tail -5 "$T/run2.log"
fi

# ---- 3. a stored mission equals gfctl simulate by hand ------------------------------------
(cd "$SRC" && "$GFCTL" simulate --scenario config/scenarios/open_field.yaml --fault-profile loss30 --seed 2 \
  --duration 20 --no-plot --threads 1 --out "$T/by_hand" > "$T/by_hand.log" 2>&1)
"$PY" - "$S2" "$T/by_hand/metrics.json" <<'P' && pass "the stored loss30 seed 2 equals gfctl simulate by hand" || fail "stored metrics differ from gfctl simulate by hand"
import json, sqlite3, sys
con = sqlite3.connect(f"file:{sys.argv[1]}?mode=ro", uri=True)
stored = json.loads(con.execute("SELECT metrics_json FROM missions WHERE profile = 'loss30' AND seed = 2").fetchone()[0])
hand = json.load(open(sys.argv[2]))
skip = set(hand["wall_clock_keys"]) | {"wall_clock_keys"}
diff = {k: (stored.get(k), hand[k]) for k in hand if k not in skip and stored.get(k) != hand[k]}
print("compared", len(hand) - len(skip), "keys; differing:", diff)
sys.exit(1 if diff or len(hand) - len(skip) < 30 else 0)
P

# ---- 4. failures are stored and counted ---------------------------------------------------
campaign bad.yaml bad "[1]" "variants: {mission.links.uav.delay_s: [-1]}"
S4=$T/s4.sqlite
(cd "$SRC" && $C --store "$S4" run "$T/bad.yaml" --scheduler "$SCHED" --work-dir "$T/work" > "$T/run4.log" 2>&1)
rc=$?
nf=$(q "$S4" "SELECT COUNT(*) FROM failures WHERE status = 'failed' AND exit_code = 2 AND log_tail LIKE '%delay_s%out of range%'")
[ "$rc" = 1 ] && [ "$nf" = 2 ] && [ "$(q "$S4" 'SELECT COUNT(*) FROM missions')" = 0 ] && grep -q "2 failed" "$T/run4.log" \
  && pass "bad config: exit 1, 2 failures stored with gfctl's error, counted" || { fail "bad config: exit $rc, $nf failures"; tail -5 "$T/run4.log"; }
campaign slow.yaml slow "[1]"
sed -i 's/^timeout_s: .*/timeout_s: 0.2/' "$T/slow.yaml"
(cd "$SRC" && $C --store "$S4" run "$T/slow.yaml" --scheduler "$SCHED" --work-dir "$T/work" > "$T/run5.log" 2>&1)
rc=$?
nt=$(q "$S4" "SELECT COUNT(*) FROM failures WHERE status = 'timeout' AND log_tail LIKE '%per-mission timeout%'")
[ "$rc" = 1 ] && [ "$nt" = 2 ] && pass "timeout: exit 1, 2 timeouts stored with their log tails" || { fail "timeout: exit $rc, $nt stored"; tail -5 "$T/run5.log"; }
(cd "$SRC" && $C --store "$S4" failures) | grep "4 failed attempts" > /dev/null && pass "campaign.py failures lists them" || fail "campaign.py failures"

# ---- 5. the default local cluster --------------------------------------------------------
campaign local.yaml local "[7]"
(cd "$SRC" && $C --store "$T/s5.sqlite" run "$T/local.yaml" --workers 2 --work-dir "$T/work" > "$T/run6.log" 2>&1)
rc=$?
[ "$rc" = 0 ] && [ "$(q "$T/s5.sqlite" 'SELECT COUNT(*) FROM missions')" = 2 ] && grep -q "local, 127.0.0.1" "$T/run6.log" \
  && grep -q "missions/hour" "$T/run6.log" && pass "local cluster: 2 missions, missions/hour printed" \
  || { fail "local cluster: exit $rc"; tail -5 "$T/run6.log"; }

# The whole tool killed with kill -9 while its local cluster runs missions: its worker processes
# and their gfctl stop with it; the same command then finishes the campaign, each mission once.
campaign local_kill.yaml local_kill 1..3
S6=$T/s6.sqlite
(cd "$SRC" && exec $C --store "$S6" run "$T/local_kill.yaml" --workers 2 --work-dir "$T/work" > "$T/run8.log" 2>&1) &
TOOL=$!
PIDS+=("$TOOL")
if wait_rows "$S6" 1 120; then
  kids=$(pgrep -P "$TOOL" | tr '\n' ' ')
  kill -9 "$TOOL"
  wait "$TOOL" 2>/dev/null
  left=""
  for _ in $(seq 1 60); do
    left=$(for k in $kids; do kill -0 "$k" 2>/dev/null && echo "$k"; done; pgrep -f "$T/work/missions")
    [ -z "$left" ] && break
    sleep 0.5
  done
  [ -z "$left" ] && pass "tool killed: its local workers ($kids) and missions stopped within 30 s" \
    || fail "tool killed: still running after 30 s: $left"
  before=$(q "$S6" 'SELECT COUNT(*) FROM missions')
  (cd "$SRC" && $C --store "$S6" run "$T/local_kill.yaml" --workers 2 --work-dir "$T/work" > "$T/run9.log" 2>&1)
  rc=$?
  [ "$rc" = 0 ] && [ "$(q "$S6" 'SELECT COUNT(*) FROM missions')" = 6 ] && grep -q "6 missions, $before already in" "$T/run9.log" \
    && pass "local cluster resumed after kill -9 of the tool: 6 missions, each once" || { fail "local resume: exit $rc"; tail -3 "$T/run9.log"; }
else
  fail "local_kill: no mission stored within 120 s"; tail -5 "$T/run8.log"
fi

# A worker whose gfctl is another binary than the client's: stored as a mismatch, the run stops.
campaign mismatch.yaml mismatch "[8]"
(cd "$SRC" && GF_CAMPAIGN_GFCTL=/bin/true $C --store "$T/s5.sqlite" run "$T/mismatch.yaml" --workers 1 --work-dir "$T/work" \
  > "$T/run7.log" 2>&1)
rc=$?
nm=$(q "$T/s5.sqlite" "SELECT COUNT(*) FROM failures WHERE status = 'mismatch' AND log_tail LIKE '%/bin/true has sha256%'")
[ "$rc" = 1 ] && [ "$nm" -ge 1 ] && grep -q "stopping: a worker's gfctl or model differs" "$T/run7.log" \
  && [ "$(q "$T/s5.sqlite" 'SELECT COUNT(*) FROM missions')" = 2 ] \
  && pass "a worker with another gfctl: mismatch stored, the run stops, no row" || { fail "mismatch: exit $rc, $nm"; tail -3 "$T/run7.log"; }

# ---- 6. corrupt, foreign and non-SQLite stores are refused, untouched ----------------------
"$PY" - "$S1" "$T/corrupt.sqlite" "$T/foreign.sqlite" "$T/text.sqlite" <<'P'
import shutil, sqlite3, sys
good, corrupt, foreign, text = sys.argv[1:5]
shutil.copy(good, corrupt)
with open(corrupt, "r+b") as f:  # garbage over the pages after the first: the header stays valid
    f.seek(4096)
    f.write(b"\xa5" * 8192)
con = sqlite3.connect(foreign)
con.execute("CREATE TABLE missions (x)")
con.execute("INSERT INTO missions VALUES (1)")
con.commit()
con.close()
open(text, "w").write("profile,seed\nnominal,1\n" * 10)
P
for kind in corrupt foreign text; do
  f=$T/$kind.sqlite
  h0=$(sha256sum < "$f")
  out=$(cd "$SRC" && $C --store "$f" run "$T/local.yaml" --workers 1 --work-dir "$T/work" 2>&1)
  rc=$?
  out2=$(cd "$SRC" && $C --store "$f" report "$T/local.yaml" --out "$T/r.md" 2>&1)
  rc2=$?
  h1=$(sha256sum < "$f")
  case $kind in corrupt) want="corrupt" ;; foreign) want="foreign SQLite database" ;; text) want="not an SQLite database" ;; esac
  [ "$rc" = 2 ] && [ "$rc2" = 2 ] && grep -q "$want" <<<"$out" && [ "$h0" = "$h1" ] \
    && pass "$kind store refused ($(head -1 <<<"$out" | cut -c1-110)...), untouched" \
    || fail "$kind store: run exit $rc, report exit $rc2, '$out', sha256 $([ "$h0" = "$h1" ] && echo same || echo CHANGED)"
done
pgrep -f "$T/work" > /dev/null && fail "gfctl processes of this test still run: $(pgrep -af "$T/work")" || pass "no mission left running"
echo "campaign_dask: $passes passed, $fails failed"
exit $((fails > 0))
