#!/usr/bin/env python3
"""Drives the SetpointRelay (launch/flight_stack.launch) under simulated time across a jump of
ROS time back (test/ros/relay_clock_jump.sh): publishes /clock itself (wall rate, from 100 s),
a plan at 100.5 s (y = 0), then the clock from 5 s, a plan at 5.2 s (y = 10) and a plan of the old
timeline at 100.7 s (y = 20). Checks the position setpoints: on the first plan, then on the new
timeline's plan within 1 s of sim time, never on a plan of the old timeline (100.6 s right
after the jump, 100.7 s later).
Exit code = number of failures."""
import threading
import time

import rospy
from geometry_msgs.msg import Point, PoseStamped, Vector3
from gesture_formation.msg import PlannedTrajectory
from rosgraph_msgs.msg import Clock

FAILS = [0]


def check(ok, text):
    print("%s: %s" % ("PASS" if ok else "FAIL", text), flush=True)
    FAILS[0] += 0 if ok else 1


class SimClock:
    """/clock at 200 Hz, advancing with the wall clock from `start_s`; set() jumps it."""

    def __init__(self, start_s):
        self.pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self.lock = threading.Lock()
        self.base_sim, self.base_wall = start_s, time.time()
        threading.Thread(target=self.run, daemon=True).start()

    def now(self):
        with self.lock:
            return self.base_sim + (time.time() - self.base_wall)

    def set(self, t_s):
        with self.lock:
            self.base_sim, self.base_wall = t_s, time.time()

    def run(self):
        while not rospy.is_shutdown():
            self.pub.publish(Clock(clock=rospy.Time.from_sec(self.now())))
            time.sleep(0.005)


def plan(t0, y, sequence):
    p = PlannedTrajectory()
    p.header.stamp, p.header.frame_id = rospy.Time.from_sec(t0), "map"
    p.uav_index, p.sequence, p.dt_s, p.status = 0, sequence, 0.2, "optimized"
    for k in range(50):  # 10 s, 0.5 m/s east at height 5 m, the given y
        p.positions.append(Point(0.1 * k, y, 5.0))
        p.velocities.append(Vector3(0.5, 0.0, 0.0))
        p.accelerations.append(Vector3())
        p.heading_rad.append(0.0)
        p.pitch_rad.append(-0.3)
    return p


def wait_for(predicate, seconds):
    end = time.time() + seconds
    while time.time() < end and not predicate():
        time.sleep(0.02)
    return predicate()


def main():
    rospy.init_node("relay_clock_jump_check", disable_signals=True)
    clock = SimClock(100.0)
    poses = []
    rospy.Subscriber("/mavros/setpoint_position/local", PoseStamped, poses.append)
    plan_pub = rospy.Publisher("/plan", PlannedTrajectory, queue_size=5)
    check(wait_for(lambda: plan_pub.get_num_connections() > 0, 30.0), "the SetpointRelay subscribed")
    time.sleep(0.5)

    plan_pub.publish(plan(100.5, 0.0, 1))
    check(wait_for(lambda: any(abs(p.pose.position.y) < 1e-9 for p in poses), 5.0),
          "setpoints on the plan made at 100.5 s (%d setpoints)" % len(poses))

    clock.set(5.0)  # ROS time goes back
    time.sleep(0.3)
    # A plan of the old timeline still queued from before the jump: refused while the held plan is
    # ahead too (the relay must not log it as replacing the held plan).
    plan_pub.publish(plan(100.6, 30.0, 2))
    time.sleep(0.3)
    before = len(poses)
    plan_pub.publish(plan(5.2, 10.0, 1))
    got = wait_for(lambda: any(abs(p.pose.position.y - 10.0) < 1e-9 for p in poses[before:]), 5.0)
    first = next((p for p in poses[before:] if abs(p.pose.position.y - 10.0) < 1e-9), None)
    check(got, "after the jump the new timeline's plan is flown (first setpoint on it at %s s sim time)"
          % (round(first.header.stamp.to_sec(), 2) if first else None))
    check(first is not None and first.header.stamp.to_sec() < 6.5,
          "within about a second of sim time, not when the clock caught up with 100.5 s")

    time.sleep(2.2)  # past the relay's 2 s log throttle, so that this refusal is logged too
    plan_pub.publish(plan(100.7, 20.0, 2))  # the old timeline's plan, still queued somewhere
    mark = len(poses)
    time.sleep(1.5)
    after = poses[mark:]
    check(not any(abs(p.pose.position.y - 30.0) < 1e-9 for p in poses), "the 100.6 s plan never flown")
    check(after and all(abs(p.pose.position.y - 10.0) < 1e-9 for p in after),
          "the old timeline's late plan does not swap back in (%d setpoints after it, all on y = 10)" % len(after))
    return FAILS[0]


if __name__ == "__main__":
    code = main()
    rospy.signal_shutdown("done")
    raise SystemExit(code)
