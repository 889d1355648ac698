#!/usr/bin/env python3
"""Checks the leader hand-over in a running simulation.launch leadership:=true (test/ros/leader_handover.sh).
usage: leader_handover_check.py SOURCE_DIR
Watches every UAV's latched leadership_state (gesture_formation/LeadershipState). Until SILENCE_AT_S
UAV 0 must be the only one acting (term 1). Then it unloads /uav0/lcm_bridge (SIGINT to its loader: UAV 0 neither sends
nor receives on the link) and checks: UAV 0 stops acting within lease_s (+ one tick) of the silence; a
follower acts within HANDOVER_LIMIT_S; at no instant do two UAVs act (each UAV's acting intervals run
from the stamp of an acting state to the stamp of its next state, or to the end; a lapsed lease is
stamped with its end by the nodelet); the new leader's term is newer than 1 and the other follower
names it as leader. Then an operator request (`tools/gf_command.py followers distance_m 1`, through the
ground station and LCM) is applied by the new leader — acknowledged as applied, its parameters
published with a newer version than it took over — and reaches the other follower over LCM with that version; UAV 0,
which no longer acts, publishes no parameters after its lease. The estimator follows too: the new
leader's WorkerEstimator fuses its own camera's detections after the take-over (SimWorld's leader
camera moves to the acting UAV; last_fused later than the take-over, not lost) and the other follower
receives that estimate over LCM. Prints one line per check; exit code = number of failures."""
import os
import re
import signal
import subprocess
import sys
import time

import rospy
from gesture_formation.msg import FormationParams, LeadershipState, WorkerState

UAVS = 3
SILENCE_AT_S = 8.0
# config/ros/nodelets.yaml `leadership` (gfctl simulate's defaults): a follower stands silence_limit_s
# after the last heartbeat, the second in rank candidacy_stagger_s later; an election that fails is
# retried after election_timeout_s — the bound of docs/safety.md §1.2: 2 + 0.5 + 2 × 1 = 4.5 s.
LEASE_S, TICK_S = 1.0, 0.05
HANDOVER_LIMIT_S = 4.5
WATCH_AFTER_S = 4.0  # after the first follower acts, keep watching this long
fails = 0


def check(ok, what):
    global fails
    print(("PASS: " if ok else "FAIL: ") + what, flush=True)
    fails += 0 if ok else 1


def intervals(states, t_end):
    """[(from, to)] during which the UAV acted, from its states in order of arrival."""
    out = []
    for k, s in enumerate(states):
        if not s.acting:
            continue
        to = states[k + 1].header.stamp.to_sec() if k + 1 < len(states) else t_end
        out.append((s.header.stamp.to_sec(), to))
    return out


def same_views(a, b):
    """Two FormationParams with the same views."""
    return len(a.uavs) == len(b.uavs) and all(
        abs(x.beta_deg - y.beta_deg) < 1e-9 and abs(x.gamma_deg - y.gamma_deg) < 1e-9 and abs(x.distance_m - y.distance_m) < 1e-9
        for x, y in zip(a.uavs, b.uavs))


def check_request(src, new, other, published, received, t_silence):
    """The operator's request after the hand-over: applied by the new leader, on to the other follower."""
    taken = [m for m in published[new]]
    check(bool(taken), f"UAV {new} publishes the parameters it took over (version {taken[-1].version if taken else None})")
    before = taken[-1].version if taken else 0
    cli = subprocess.run([sys.executable, os.path.join(src, "tools/gf_command.py"), "followers", "distance_m", "1"],
                         capture_output=True, text=True, timeout=30)
    out = (cli.stdout + cli.stderr).strip().replace("\n", " | ")
    check(cli.returncode == 0 and "applied" in cli.stdout, f"tools/gf_command.py: the request acknowledged as applied ('{out[:200]}')")
    t1 = time.time()
    while time.time() - t1 < 10:
        done = [m for m in published[new] if m.version > before and m.last_command_status == "applied"]
        if done and any(same_views(m, done[0]) for m in received[other]):
            break
        time.sleep(0.05)
    applied = [m for m in published[new] if m.version > before and m.last_command_status == "applied"]
    check(bool(applied), f"UAV {new} applied it: version {applied[0].version if applied else None} > {before}, "
          f"'{applied[0].last_command if applied else ''}'")
    check(bool(applied) and not same_views(applied[0], taken[-1]) and any(same_views(m, applied[0]) for m in received[other]),
          f"UAV {other} received the new parameters over LCM (followers' distances "
          f"{[round(u.distance_m, 2) for u in received[other][-1].uavs] if received[other] else None})")
    got = [m.version for m in received[other] if applied and same_views(m, applied[0])]
    check(bool(got) and got[-1] == applied[0].version,
          f"UAV {other} received them with their version over LCM ({got[-1] if got else None}, "
          f"UAV {new} published {applied[0].version if applied else None})")
    late = [m for m in published[0] if m.header.stamp.to_sec() > t_silence + LEASE_S + 0.5]
    check(not late, f"UAV 0 published no parameters after its lease ({len(late)} did)")


def check_estimate(new, other, t_new, estimates, shared):
    """The new leader's estimator fuses its own camera after the take-over; the other follower gets it."""
    t1 = time.time()
    while time.time() - t1 < 10:
        fused = [m for m in estimates[new] if m.last_fused.to_sec() > t_new + 0.5 and not m.lost]
        got = [m for m in shared[other] if m.last_fused.to_sec() > t_new + 0.5]
        if fused and got:
            break
        time.sleep(0.1)
    last = estimates[new][-1] if estimates[new] else None
    seen = f"last estimate: last_fused {last.last_fused.to_sec():.2f} s, lost {last.lost}" if last else "no estimate at all"
    check(bool(fused), f"UAV {new}'s estimator fuses its own camera after the take-over at {t_new:.2f} s ({seen})")
    check(bool(got), f"UAV {other} receives UAV {new}'s estimate over LCM ({len(got)} fused after the take-over)")


def main():
    src = sys.argv[1]
    rospy.init_node("leader_handover_check", anonymous=True)
    states = {i: [] for i in range(UAVS)}
    published = {i: [] for i in range(UAVS)}  # each planner's own parameters (formation_params)
    received = {i: [] for i in range(UAVS)}   # the parameters each LcmBridge received (lcm/formation_params)
    for i in range(UAVS):
        rospy.Subscriber(f"/uav{i}/formation_params", FormationParams, lambda m, i=i: published[i].append(m))
        rospy.Subscriber(f"/uav{i}/lcm/formation_params", FormationParams, lambda m, i=i: received[i].append(m))
    for i in range(UAVS):
        rospy.Subscriber(f"/uav{i}/leadership_state", LeadershipState, lambda m, i=i: states[i].append(m))
    estimates = {i: [] for i in range(UAVS)}  # each UAV's worker_state (its own estimate or the relayed share)
    shared = {i: [] for i in range(UAVS)}     # the estimates each LcmBridge received (lcm/worker_state)
    for i in range(UAVS):
        rospy.Subscriber(f"/uav{i}/worker_state", WorkerState, lambda m, i=i: estimates[i].append(m))
        rospy.Subscriber(f"/uav{i}/lcm/worker_state", WorkerState, lambda m, i=i: shared[i].append(m))
    t0 = time.time()
    while rospy.get_time() < SILENCE_AT_S and time.time() - t0 < 60:
        time.sleep(0.05)
    check(rospy.get_time() >= SILENCE_AT_S, f"sim time reached {SILENCE_AT_S} s (now {rospy.get_time():.1f})")
    last = {i: states[i][-1] if states[i] else None for i in range(UAVS)}
    check(last[0] is not None and last[0].acting and last[0].term == 1,
          "before the silence UAV 0 acts in term 1" +
          (f" (acting {last[0].acting}, term {last[0].term})" if last[0] is not None else " (no state)"))
    check(all(last[i] is not None and not last[i].acting and last[i].leader == 0 for i in range(1, UAVS)),
          "before the silence the followers do not act and name UAV 0 as leader")
    # The loader process of /uav0/lcm_bridge gets SIGINT: it unloads the nodelet from UAV 0's manager
    # (as ros_planner_restart does); UAV 0's Leadership nodelet runs on without a link.
    info = subprocess.run(["rosnode", "info", "/uav0/lcm_bridge"], capture_output=True, text=True).stdout
    pid = re.search(r"Pid: (\d+)", info)
    t_silence = rospy.get_time()
    if pid:
        os.kill(int(pid.group(1)), signal.SIGINT)
    check(pid is not None, f"unloaded UAV 0's LcmBridge at sim t = {t_silence:.2f} s")
    t_new = None
    new = None
    t1 = time.time()
    while time.time() - t1 < 40:
        for i in range(1, UAVS):
            acting = [s for s in states[i] if s.acting]
            if acting and (t_new is None or acting[0].header.stamp.to_sec() < t_new):
                t_new, new = acting[0].header.stamp.to_sec(), i
        if t_new is not None and rospy.get_time() > t_new + WATCH_AFTER_S:
            break
        time.sleep(0.05)
    t_end = rospy.get_time()
    check(new is not None, "a follower acts as leader after the silence")
    if new is not None:
        check(t_new - t_silence <= HANDOVER_LIMIT_S,
              f"UAV {new} acts {t_new - t_silence:.2f} s after the silence (limit {HANDOVER_LIMIT_S} s)")
    stopped = [s for s in states[0] if not s.acting and s.header.stamp.to_sec() >= t_silence - LEASE_S]
    check(bool(stopped) and stopped[0].header.stamp.to_sec() <= t_silence + LEASE_S + TICK_S,
          "UAV 0 stops acting within its lease of the silence" +
          (f" (at {stopped[0].header.stamp.to_sec():.2f} s)" if stopped else " (it never stopped)"))
    iv = {i: intervals(states[i], t_end) for i in range(UAVS)}
    overlaps = [(i, j, a, b) for i in range(UAVS) for j in range(i + 1, UAVS)
                for a in iv[i] for b in iv[j] if max(a[0], b[0]) < min(a[1], b[1])]
    check(not overlaps, f"never two acting ({sum(len(v) for v in iv.values())} acting intervals; overlaps {overlaps[:3]})")
    if new is not None:
        term = [s for s in states[new] if s.acting][0].term
        other = [i for i in range(1, UAVS) if i != new][0]
        check(term > 1, f"the new leader's term {term} is newer than 1")
        check(bool(states[other]) and states[other][-1].leader == new and states[other][-1].term == term,
              f"UAV {other} follows UAV {new} in term {term} (its last state: leader "
              f"{states[other][-1].leader if states[other] else None}, term {states[other][-1].term if states[other] else None})")
    if new is not None:
        check_request(src, new, [i for i in range(1, UAVS) if i != new][0], published, received, t_silence)
    if new is not None:
        check_estimate(new, [i for i in range(1, UAVS) if i != new][0], t_new, estimates, shared)
    print(f"acting intervals: {iv}", flush=True)
    return fails


if __name__ == "__main__":
    sys.exit(main())
