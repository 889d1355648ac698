#!/usr/bin/env python3
"""Latency from each fired gesture command to the followers' new parameters (received over
LCM) and to their first plan made with them, read from a mission bag of simulation.launch
(tools/run_ros_mission.sh). Times are sim time (the bag's /clock domain).
usage: bag_latency.py mission.bag"""
import statistics
import sys

import rosbag


def main():
    bag = rosbag.Bag(sys.argv[1])
    fired, params, plans, leader = [], {1: [], 2: []}, {1: [], 2: []}, []
    for topic, msg, t in bag.read_messages(topics=["/uav0/formation_command", "/uav0/formation_params", "/uav1/formation_params",
                                                   "/uav2/formation_params", "/uav1/plan", "/uav2/plan"]):
        if topic == "/uav0/formation_command":
            if msg.source == "gesture":
                fired.append(msg.header.stamp.to_sec())
        elif topic == "/uav0/formation_params":
            leader.append((t.to_sec(), msg.version, tuple((u.beta_deg, u.gamma_deg, u.distance_m) for u in msg.uavs)))
        elif topic.endswith("formation_params"):
            params[int(topic[4])].append((t.to_sec(), tuple((u.beta_deg, u.gamma_deg, u.distance_m) for u in msg.uavs)))
        else:
            plans[int(topic[4])].append((msg.header.stamp.to_sec(), tuple((p.x, p.y, p.z) for p in msg.reference[:1])))
    to_params, to_plan = [], []
    for tf in fired:
        # the leader's parameters right after the command (its version increments on apply)
        v0 = max([ver for (t, ver, _) in leader if t < tf], default=0)
        new = next((v for (t, ver, v) in leader if t >= tf and ver > v0), None)
        if new is None:
            continue
        for i in (1, 2):
            change = next((t for (t, v) in params[i] if t >= tf and v == new), None)
            if change is None:
                continue
            to_params.append(change - tf)
            plan = next((t for (t, _) in plans[i] if t >= change), None)
            if plan is not None:
                to_plan.append(plan - tf)
    if not to_params:
        print("  gesture latency: no gesture command in the bag")
        return 0
    print(f"  gesture command -> followers' parameters over LCM: median {statistics.median(to_params):.3f} s, "
          f"max {max(to_params):.3f} s; -> their first plan with them: median {statistics.median(to_plan):.3f} s, "
          f"max {max(to_plan):.3f} s ({len(fired)} gesture commands, sim time)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
