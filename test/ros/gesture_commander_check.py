#!/usr/bin/env python3
"""Feeds two GestureCommanders (test/ros/gesture_commander.sh: /single with min_agreeing_views 1,
/voted with the shipped 2) GestureObservation messages of gesture 2 at 15 Hz for 2 s (30 frames:
20 agreeing ones fill the filter's window, f_d = 1 > 0.8) and checks which fire.
Exit code = number of failures."""
import sys
import time

import rospy
from gesture_formation.msg import FormationCommand, GestureObservation, GestureStatus

IN_ENVELOPE = (10.0, 11.0)    # distance [m], elevation [deg]: the leader's Table II geometry
OUTSIDE = (30.0, 11.0)        # beyond the classifier's validated 5..20 m


def main():
    rospy.init_node("gesture_commander_check")
    pubs, commands, statuses = {}, {}, {}
    for name in ("single", "voted"):
        pubs[name] = (rospy.Publisher("/%s/observation" % name, GestureObservation, queue_size=50),
                      rospy.Publisher("/%s/peer_observations" % name, GestureObservation, queue_size=50))
        commands[name], statuses[name] = [], []
        rospy.Subscriber("/%s/formation_command" % name, FormationCommand, commands[name].append)
        rospy.Subscriber("/%s/gesture_status" % name, GestureStatus, statuses[name].append, queue_size=200)
    time.sleep(1.5)  # connections

    def inject(name, views, geometry):
        rate = rospy.Rate(15)
        for _ in range(30):
            stamp = rospy.Time.now()
            for uav in views:
                o = GestureObservation(uav_index=uav, gesture_id=2, probabilities=[0, 0, 1, 0, 0],
                                       geometry_known=True, distance_m=geometry[0], elevation_deg=geometry[1])
                o.header.stamp = stamp
                pubs[name][0 if uav == 0 else 1].publish(o)
            rate.sleep()
        time.sleep(0.5)

    fails = 0

    def check(ok, text):
        nonlocal fails
        print("%s: %s" % ("PASS" if ok else "FAIL", text))
        fails += 0 if ok else 1

    inject("single", [0], IN_ENVELOPE)
    check(len(commands["single"]) == 1 and commands["single"][0].parameter == "beta_deg",
          "min_agreeing_views 1, the leader's camera alone: %d command(s) (expected 1, leader.beta_deg)" % len(commands["single"]))
    inject("voted", [0], IN_ENVELOPE)
    agree = max([m.agreeing_views for m in statuses["voted"]] or [0])
    check(not commands["voted"] and len(statuses["voted"]) >= 25 and agree == 1,
          "min_agreeing_views 2, 1 camera: %d command(s), %d frames, at most %d agreeing (expected 0, >= 25, 1)" % (
              len(commands["voted"]), len(statuses["voted"]), agree))
    del statuses["voted"][:]
    inject("voted", [0, 1], OUTSIDE)
    voting = max([m.voting_views for m in statuses["voted"]] or [-1])
    check(not commands["voted"] and voting == 0,
          "2 cameras at 30 m (outside the envelope): %d command(s), at most %d voting views (expected 0, 0)" % (
              len(commands["voted"]), voting))
    del statuses["voted"][:]
    inject("voted", [0, 1], IN_ENVELOPE)
    fired = [m for m in statuses["voted"] if m.fired]
    check(len(commands["voted"]) == 1 and len(fired) == 1 and fired[0].agreeing_views == 2 and fired[0].reported_views == 2,
          "2 cameras inside the envelope: %d command(s)%s (expected 1, 2 reported, 2 agreeing)" % (
              len(commands["voted"]), ", fired with %d reported, %d agreeing" % (fired[0].reported_views, fired[0].agreeing_views)
              if fired else ""))
    return fails


if __name__ == "__main__":
    sys.exit(main())
