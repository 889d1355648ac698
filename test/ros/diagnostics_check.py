#!/usr/bin/env python3
"""/diagnostics of a running simulation.launch (test/ros/simulation_launch.sh): every UAV's
FormationPlanner and ViewObserver, the leader's WorkerEstimator and GestureCommander and every LcmBridge report about once a second
(wall clock) with their values; the planners and the estimator are not in ERROR."""
import sys
import time
from collections import defaultdict

import rospy
from diagnostic_msgs.msg import DiagnosticArray

WALL_S = 5.0
WANT = ["FormationPlanner uav0", "FormationPlanner uav1", "FormationPlanner uav2", "WorkerEstimator", "GestureCommander",
        "ViewObserver uav0", "ViewObserver uav1", "ViewObserver uav2",
        "LcmBridge sender 0: link", "LcmBridge sender 1: link", "LcmBridge sender 2: link",
        "LcmBridge sender 100: link"]
KEYS = {"FormationPlanner": {"mode", "plans_per_s", "fallbacks", "last_planning_ms", "last_plan_age_s"},
        "WorkerEstimator": {"confirmed", "lost", "fused_per_s", "last_fused_age_s", "published_per_s"},
        "GestureCommander": {"frames", "observations", "rejected", "fired", "last_fired"},
        "ViewObserver": {"observations_per_s", "with_geometry", "with_skeleton", "odometry_refused", "odometry_age_s",
                         "worker_state_age_s"}}


def main():
    rospy.init_node("diagnostics_check", anonymous=True)
    seen = defaultdict(list)
    rospy.Subscriber("/diagnostics", DiagnosticArray,
                     lambda a: [seen[s.name].append(s) for s in a.status], queue_size=100)
    time.sleep(WALL_S)
    bad = 0
    for name in WANT:
        n = len(seen[name])
        ok = n >= int(WALL_S) - 2  # ~1 Hz, wall clock
        print("%s: /diagnostics %s: %d reports in %.0f s wall" % ("PASS" if ok else "FAIL", name, n, WALL_S))
        bad += 0 if ok else 1
        if not seen[name]:
            continue
        last = seen[name][-1]
        keys = KEYS.get(name.split(" ")[0], set())
        missing = keys - {kv.key for kv in last.values}
        if missing:
            print("FAIL: %s lacks values %s" % (name, sorted(missing)))
            bad += 1
        if keys and last.level >= 2:
            print("FAIL: %s in ERROR: %s" % (name, last.message))
            bad += 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
