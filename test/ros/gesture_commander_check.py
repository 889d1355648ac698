#!/usr/bin/env python3
"""Feeds three GestureCommanders (test/ros/gesture_commander.sh: /single with min_agreeing_views 1,
/voted with the shipped 2 and confirm_3d off, /confirm3d with 2 and view_fusion.confirm_3d on) GestureObservation
messages of gesture 2 at 15 Hz for 2 s (30 frames: 20 agreeing ones fill the filter's window,
f_d = 1 > 0.8) and checks which fire. For the 3-D confirmation the observations carry the skeleton
of a worker projected through three calibrated cameras (pinhole, the commander's pose convention:
optical frame in the world): the one view that reads "extend" fires only when the skeleton's arm
is extended in 3-D, not when it points forward. A slow link: /nolag (fusion_lag_s 0), /voted (the shipped 0.4 s) and
/lagged (0.8 s) get the leader's observations at once and follower 1's 0.47 s late (7 frames;
stamped with their frame): /voted and /lagged fire, /nolag does not.
Exit code = number of failures."""
import math
import sys
import time

from geometry_msgs.msg import Pose
from sensor_msgs.msg import CameraInfo

import rospy
from gesture_formation.msg import FormationCommand, GestureObservation, GestureStatus, LeadershipState

IN_ENVELOPE = (10.0, 11.0)    # distance [m], elevation [deg]: the leader's Table II geometry
OUTSIDE = (30.0, 11.0)        # beyond the classifier's validated 5..20 m


# A worker 1.75 m tall at the origin facing +x (COCO-17 keypoints, world [m]); the left arm either
# extended to the side (gesture 2 in 3-D) or pointing forward (what a single view can take for it).
BODY = [(0.10, 0.00, 1.65), (0.08, 0.03, 1.68), (0.08, -0.03, 1.68), (0.0, 0.07, 1.66), (0.0, -0.07, 1.66),
        (0.0, 0.20, 1.45), (0.0, -0.20, 1.45), None, (0.0, -0.22, 1.17), None, (0.0, -0.22, 0.90),
        (0.0, 0.10, 0.95), (0.0, -0.10, 0.95), (0.0, 0.10, 0.50), (0.0, -0.10, 0.50), (0.0, 0.10, 0.05),
        (0.0, -0.10, 0.05)]
LEFT_ARM = {"extended": ((0.0, 0.50, 1.45), (0.0, 0.80, 1.45)), "forward": ((0.30, 0.20, 1.45), (0.60, 0.20, 1.45))}
FX, CX, CY, W, H = 615.0, 320.0, 240.0, 640, 480


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def camera(azimuth_deg, distance=10.0, elevation_deg=11.0, aim=(0.0, 0.0, 0.95)):
    """Optical centre and axes (x right, y down, z forward) of a camera looking at `aim`."""
    e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
    c = [aim[0] + distance * math.cos(e) * math.cos(a), aim[1] + distance * math.cos(e) * math.sin(a),
         aim[2] + distance * math.sin(e)]
    z = unit(sub(aim, c))
    x = unit(cross(z, [0.0, 0.0, 1.0]))
    return c, (x, cross(z, x), z)


def quaternion(axes):
    """(w, x, y, z) of the rotation whose columns are `axes` (world <- optical)."""
    (r00, r10, r20), (r01, r11, r21), (r02, r12, r22) = axes
    w = math.sqrt(max(0.0, 1.0 + r00 + r11 + r22)) / 2.0
    x = math.copysign(math.sqrt(max(0.0, 1.0 + r00 - r11 - r22)) / 2.0, r21 - r12)
    y = math.copysign(math.sqrt(max(0.0, 1.0 - r00 + r11 - r22)) / 2.0, r02 - r20)
    z = math.copysign(math.sqrt(max(0.0, 1.0 - r00 - r11 + r22)) / 2.0, r10 - r01)
    return w, x, y, z


def skeleton_fields(azimuth_deg, arm):
    """keypoints, CameraInfo and Pose of the worker seen from `azimuth_deg`."""
    c, axes = camera(azimuth_deg)
    points = list(BODY)
    points[7], points[9] = LEFT_ARM[arm]
    keypoints = []
    for p in points:
        d = sub(p, c)
        xc, yc, zc = (sum(axes[k][i] * d[i] for i in range(3)) for k in range(3))
        keypoints += [FX * xc / zc + CX, FX * yc / zc + CY, 0.9]
    info = CameraInfo(width=W, height=H, distortion_model="plumb_bob", D=[0.0] * 5,
                      K=[FX, 0, CX, 0, FX, CY, 0, 0, 1])
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = c
    q = quaternion(axes)
    pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z = q
    return keypoints, info, pose


def main():
    rospy.init_node("gesture_commander_check")
    pubs, commands, statuses = {}, {}, {}
    for name in ("single", "voted", "confirm3d", "lagged", "nolag", "lead"):
        pubs[name] = (rospy.Publisher("/%s/observation" % name, GestureObservation, queue_size=50),
                      rospy.Publisher("/%s/peer_observations" % name, GestureObservation, queue_size=50))
        commands[name], statuses[name] = [], []
        rospy.Subscriber("/%s/formation_command" % name, FormationCommand, commands[name].append)
        rospy.Subscriber("/%s/gesture_status" % name, GestureStatus, statuses[name].append, queue_size=200)
    time.sleep(1.5)  # connections

    def inject(name, views, geometry, arm=None):
        """views: the UAVs that read gesture 2; with `arm`, all three report, the others "none",
        each with the skeleton seen from its azimuth (0, 120, -120 deg)."""
        rate = rospy.Rate(15)
        for _ in range(30):
            stamp = rospy.Time.now()
            for uav in (views if arm is None else [1, 2, 0]):  # the leader's last: it closes the frame
                g = 2 if uav in views else 0
                o = GestureObservation(uav_index=uav, gesture_id=g, probabilities=[1.0 if i == g else 0.0 for i in range(5)],
                                       geometry_known=True, distance_m=geometry[0], elevation_deg=geometry[1])
                if arm is not None:
                    o.keypoints, o.camera, o.camera_pose = skeleton_fields((0.0, 120.0, -120.0)[uav], arm)
                o.header.stamp = stamp
                pubs[name][0 if uav == 0 else 1].publish(o)
            rate.sleep()
        time.sleep(0.5)

    def idle(name, views, geometry, frames=38):
        """views read "none" for `frames` frames at 15 Hz (~2.5 s): the worker seen not gesturing."""
        rate = rospy.Rate(15)
        for _ in range(frames):
            stamp = rospy.Time.now()
            for uav in sorted(views, reverse=True):  # the leader's last: it closes the frame
                o = GestureObservation(uav_index=uav, gesture_id=0, probabilities=[1.0, 0.0, 0.0, 0.0, 0.0],
                                       geometry_known=True, distance_m=geometry[0], elevation_deg=geometry[1])
                o.header.stamp = stamp
                pubs[name][0 if uav == 0 else 1].publish(o)
            rate.sleep()
        time.sleep(0.5)

    def inject_late_follower(names, delay_frames=7):
        """The leader reads gesture 2 at once; follower 1 reads it too, its observations published
        delay_frames frames (at 15 Hz) after their stamp."""
        rate = rospy.Rate(15)
        stamps = []
        for k in range(40 + delay_frames):
            stamps.append(rospy.Time.now())
            for name in names:
                if k < 40:
                    o = GestureObservation(uav_index=0, gesture_id=2, probabilities=[0, 0, 1.0, 0, 0], geometry_known=True,
                                           distance_m=IN_ENVELOPE[0], elevation_deg=IN_ENVELOPE[1])
                    o.header.stamp = stamps[-1]
                    pubs[name][0].publish(o)
                if k >= delay_frames:
                    o = GestureObservation(uav_index=1, gesture_id=2, probabilities=[0, 0, 1.0, 0, 0], geometry_known=True,
                                           distance_m=IN_ENVELOPE[0], elevation_deg=IN_ENVELOPE[1])
                    o.header.stamp = stamps[k - delay_frames]
                    pubs[name][1].publish(o)
            rate.sleep()
        time.sleep(1.0)

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
    # One view of three reads "extend"; the other two see the same worker and read none.
    inject("voted", [0], IN_ENVELOPE, arm="extended")
    check(len(commands["voted"]) == 1,
          "confirm_3d off, 1 of 3 cameras with skeletons: %d command(s) in total (expected still 1)" % len(commands["voted"]))
    inject("confirm3d", [0], IN_ENVELOPE, arm="forward")
    confirmed = [m for m in statuses["confirm3d"] if m.confirmed_3d]
    check(not commands["confirm3d"] and not confirmed and len(statuses["confirm3d"]) >= 25,
          "confirm_3d on, 1 of 3 cameras, the arm pointing forward in 3-D: %d command(s), %d frames confirmed, %d frames "
          "(expected 0, 0, >= 25)" % (len(commands["confirm3d"]), len(confirmed), len(statuses["confirm3d"])))
    del statuses["confirm3d"][:]
    inject("confirm3d", [0], IN_ENVELOPE, arm="extended")
    fired = [m for m in statuses["confirm3d"] if m.fired]
    check(len(commands["confirm3d"]) == 1 and commands["confirm3d"][0].parameter == "beta_deg" and len(fired) == 1
          and fired[0].confirmed_3d and fired[0].agreeing_views == 1,
          "confirm_3d on, 1 of 3 cameras, the arm extended in 3-D: %d command(s)%s (expected 1, confirmed in 3-D, "
          "1 agreeing)" % (len(commands["confirm3d"]), ", fired confirmed_3d %s with %d agreeing" % (
              fired[0].confirmed_3d, fired[0].agreeing_views) if fired else ""))
    before = len(commands["voted"])
    del statuses["voted"][:]
    inject_late_follower(["nolag", "voted", "lagged"])
    agree = max([m.agreeing_views for m in statuses["nolag"]] or [0])
    check(not commands["nolag"] and agree == 1,
          "no lag, follower 1 0.47 s late: %d command(s), at most %d agreeing view(s) (expected 0, 1)" % (
              len(commands["nolag"]), agree))
    fired = [m for m in statuses["voted"] if m.fired]
    check(len(commands["voted"]) == before + 1 and len(fired) == 1 and fired[0].agreeing_views == 2,
          "shipped fusion_lag_s 0.4, follower 1 0.47 s late: %d new command(s)%s (expected 1, 2 agreeing)" % (
              len(commands["voted"]) - before, ", fired with %d agreeing" % fired[0].agreeing_views if fired else ""))
    fired = [m for m in statuses["lagged"] if m.fired]
    check(len(commands["lagged"]) == 1 and len(fired) == 1 and fired[0].agreeing_views == 2,
          "fusion_lag_s 0.8, follower 1 0.47 s late: %d command(s)%s (expected 1, 2 agreeing)" % (
              len(commands["lagged"]), ", fired with %d agreeing" % fired[0].agreeing_views if fired else ""))
    # ~leadership: acting in term 1, then its lease lapses (same term, still the term's leader): it
    # votes on (the FormationPlanner keeps what it sends until the lease is back); a newer term with
    # another leader: no vote; acting again in term 3: votes. A UAV that starts acting fires only
    # once it has seen the worker release the gesture in progress (its predecessor may have fired for
    # it): the worker is seen idle first, and a gesture already held when it took over does not fire.
    lead_pub = rospy.Publisher("/lead/leadership_state", LeadershipState, queue_size=5, latch=True)

    def lead_state(term, leader, role, acting):
        m = LeadershipState(uav_index=0, term=term, leader=leader, role=role, acting=acting)
        m.header.stamp = rospy.Time.now()
        lead_pub.publish(m)
        time.sleep(0.5)

    lead_state(1, 0, LeadershipState.ROLE_LEADER, True)
    lead_state(1, 0, LeadershipState.ROLE_LEADER, False)
    idle("lead", [0, 1], IN_ENVELOPE)
    inject("lead", [0, 1], IN_ENVELOPE)
    check(len(commands["lead"]) == 1, "~leadership, its lease lapsed in the term it acts in: %d command(s) (expected 1)" % len(commands["lead"]))
    lead_state(2, 1, LeadershipState.ROLE_FOLLOWER, False)
    inject("lead", [0, 1], IN_ENVELOPE)
    check(len(commands["lead"]) == 1, "~leadership, a newer term led by UAV 1: %d command(s) in total (expected still 1)" % len(commands["lead"]))
    lead_state(3, 0, LeadershipState.ROLE_LEADER, True)
    inject("lead", [0, 1], IN_ENVELOPE)
    check(len(commands["lead"]) == 1,
          "~leadership, acting again in term 3, the gesture held since before: %d command(s) in total (expected still 1)" % len(commands["lead"]))
    idle("lead", [0, 1], IN_ENVELOPE)
    inject("lead", [0, 1], IN_ENVELOPE)
    check(len(commands["lead"]) == 2,
          "~leadership, acting in term 3, released and performed again: %d command(s) in total (expected 2)" % len(commands["lead"]))
    return fails


if __name__ == "__main__":
    sys.exit(main())
