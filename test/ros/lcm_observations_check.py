#!/usr/bin/env python3
"""test/ros/lcm_observations.sh: publishes GestureObservations at the follower's bridge (sender 1)
and checks what the leader's bridge (sender 0) publishes. Exit code = number of failures."""
import sys
import time

import rospy
from gesture_formation.msg import GestureObservation


def main():
    rospy.init_node("lcm_observations_check")
    got = []
    rospy.Subscriber("/leader/gesture_observations", GestureObservation, got.append)
    pub = rospy.Publisher("/follower/gesture_observation", GestureObservation, queue_size=10)
    time.sleep(2.0)  # connections, and the bridges' first heartbeats
    fails = 0

    def send(uav, gesture_id, distance=8.25, elevation=11.5, known=True):
        o = GestureObservation(uav_index=uav, gesture_id=gesture_id, probabilities=[0.1, 0.1, 0.6, 0.1, 0.1],
                               geometry_known=known, distance_m=distance, elevation_deg=elevation)
        o.header.stamp = rospy.Time.now()
        pub.publish(o)
        time.sleep(0.5)
        return o

    sent = send(1, 2)
    ok = len(got) == 1 and got[0].uav_index == 1 and got[0].gesture_id == 2 and got[0].geometry_known and \
        got[0].distance_m == 8.25 and got[0].elevation_deg == 11.5 and \
        [round(p, 6) for p in got[0].probabilities] == [0.1, 0.1, 0.6, 0.1, 0.1] and \
        abs(got[0].header.stamp.to_sec() - sent.header.stamp.to_sec()) < 1e-6
    print("%s: follower 1's observation arrived at the leader with every field (%d message(s))" % (
        "PASS" if ok else "FAIL", len(got)))
    fails += 0 if ok else 1
    del got[:]
    send(2, 2)          # follower 1 claims to speak for UAV 2
    send(1, 16)         # outside the wire's gesture ids: not sent
    ok = not got
    print("%s: an observation claiming another UAV and one with gesture id 16: %d delivered (expected 0)" % (
        "PASS" if ok else "FAIL", len(got)))
    fails += 0 if ok else 1
    send(1, 0, known=False)
    ok = len(got) == 1 and not got[0].geometry_known and got[0].gesture_id == 0
    print("%s: an observation of unknown geometry still travels (marked unknown): %d delivered" % (
        "PASS" if ok else "FAIL", len(got)))
    fails += 0 if ok else 1
    return fails


if __name__ == "__main__":
    sys.exit(main())
