#!/usr/bin/env python3
"""Feeds the flight-stack relay (launch/flight_stack.launch flight_stack:=mavros setpoints:=both,
camera 20 deg down) hand-made messages in the MAVROS convention and checks what comes out
(test/ros/flight_stack.sh):
- no plan yet: no setpoint;
- local_position/odom (frame map, child base_link, body twist) -> /odometry: frames map/map, the twist
  rotated into the world frame, the camera axis' heading = the body yaw and pitch -20 deg;
- the same with child_frame_id odom: refused, nothing published, named on /diagnostics;
- a plan: setpoints at the relay's rate, on the plan (position, velocity, yaw rate, gimbal pitch/heading);
- past the plan's end: its last point held, zero velocity;
- a plan in another frame or of another UAV: refused on /diagnostics, the held plan kept.
Exit code = number of failures."""
import math
import sys
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Point, PoseStamped, TwistStamped, Vector3, Vector3Stamped
from gesture_formation.msg import PlannedTrajectory
from nav_msgs.msg import Odometry

FAILS = [0]


def check(ok, text):
    print("%s: %s" % ("PASS" if ok else "FAIL", text))
    FAILS[0] += 0 if ok else 1


def yaw_quaternion(yaw):
    return (math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0))  # w, x, y, z


def axis_of(q):
    """The x axis of orientation q (geometry_msgs/Quaternion) in the world frame."""
    w, x, y, z = q.w, q.x, q.y, q.z
    return (1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y))


class Recorder:
    def __init__(self):
        self.odom, self.pose, self.twist, self.gimbal, self.status, self.history = [], [], [], [], {}, []
        rospy.Subscriber("/odometry", Odometry, self.odom.append)
        rospy.Subscriber("/mavros/setpoint_position/local", PoseStamped, self.pose.append)
        rospy.Subscriber("/mavros/setpoint_velocity/cmd_vel", TwistStamped, self.twist.append)
        rospy.Subscriber("/gimbal/target", Vector3Stamped, self.gimbal.append)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics)

    def on_diagnostics(self, array):
        for s in array.status:
            self.status[s.name] = s
            self.history.append(s)

    def messages(self, name_prefix):
        return [s.message for s in self.history if s.name.startswith(name_prefix)]

    def value(self, name_prefix, key):
        for name, s in self.status.items():
            if name.startswith(name_prefix):
                for kv in s.values:
                    if kv.key == key:
                        return s, kv.value
        return None, None


def mavros_odometry(child="base_link"):
    o = Odometry()
    o.header.stamp = rospy.Time.now()
    o.header.frame_id = "map"
    o.child_frame_id = child
    o.pose.pose.position = Point(1.0, 2.0, 3.0)
    w, x, y, z = yaw_quaternion(math.pi / 2)  # nose north (ENU +y)
    o.pose.pose.orientation.w, o.pose.pose.orientation.x = w, x
    o.pose.pose.orientation.y, o.pose.pose.orientation.z = y, z
    o.twist.twist.linear = Vector3(1.0, 0.0, 0.5)  # body frame: 1 m/s forward, 0.5 m/s up
    return o


def plan(t0, frame="map", uav=0, sequence=1):
    p = PlannedTrajectory()
    p.header.stamp, p.header.frame_id = t0, frame
    p.uav_index, p.sequence, p.dt_s, p.status = uav, sequence, 0.2, "optimized"
    for k in range(6):  # x = 0.2 k m: 1 m/s east; heading 0.1 k rad: 0.5 rad/s; camera 0.3 rad down
        p.positions.append(Point(0.2 * k, 0.0, 5.0))
        p.velocities.append(Vector3(1.0, 0.0, 0.0))
        p.accelerations.append(Vector3())
        p.heading_rad.append(0.1 * k)
        p.pitch_rad.append(-0.3)
    return p


def publish_for(pub, make, seconds, rate_hz=20.0):
    end = time.time() + seconds
    while time.time() < end and not rospy.is_shutdown():
        pub.publish(make())
        time.sleep(1.0 / rate_hz)


def main():
    rospy.init_node("flight_stack_check")
    rec = Recorder()
    odom_pub = rospy.Publisher("/mavros/local_position/odom", Odometry, queue_size=10)
    plan_pub = rospy.Publisher("/plan", PlannedTrajectory, queue_size=5)
    end = time.time() + 20.0  # both nodelets subscribed (a cold start on a loaded machine takes a while)
    while time.time() < end and (odom_pub.get_num_connections() == 0 or plan_pub.get_num_connections() == 0):
        time.sleep(0.1)
    check(odom_pub.get_num_connections() > 0 and plan_pub.get_num_connections() > 0,
          "the OdometryAdapter and the SetpointRelay subscribed")
    time.sleep(1.5)  # the relay runs without a plan meanwhile
    check(not rec.pose and not rec.twist and not rec.gimbal,
          "no plan yet: no setpoint (%d poses, %d twists, %d gimbal)" % (len(rec.pose), len(rec.twist), len(rec.gimbal)))

    # --- the odometry adapter, MAVROS convention --------------------------------------------------
    publish_for(odom_pub, mavros_odometry, 1.0)
    time.sleep(0.2)
    check(len(rec.odom) >= 10, "%d adapted odometry messages from 20 (>= 10 expected)" % len(rec.odom))
    if rec.odom:
        o = rec.odom[-1]
        v = o.twist.twist.linear
        ax = axis_of(o.pose.pose.orientation)
        heading, pitch = math.atan2(ax[1], ax[0]), math.asin(max(-1.0, min(1.0, ax[2])))
        p = o.pose.pose.position
        check(o.header.frame_id == "map" and o.child_frame_id == "map",
              "adapted frames '%s' / '%s' (map / map: twist in the world frame)" % (o.header.frame_id, o.child_frame_id))
        check(abs(v.x) < 1e-9 and abs(v.y - 1.0) < 1e-9 and abs(v.z - 0.5) < 1e-9,
              "body twist (1, 0, 0.5) at yaw 90 deg -> world (%.6f, %.6f, %.6f) (expected (0, 1, 0.5))" % (v.x, v.y, v.z))
        check(abs(heading - math.pi / 2) < 1e-6 and abs(pitch + math.radians(20)) < 1e-6,
              "camera axis heading %.4f deg, pitch %.4f deg (expected 90, -20: the mount 20 deg down)"
              % (math.degrees(heading), math.degrees(pitch)))
        check((p.x, p.y, p.z) == (1.0, 2.0, 3.0), "position (%g, %g, %g) passed as is" % (p.x, p.y, p.z))
    n_before = len(rec.odom)
    publish_for(odom_pub, lambda: mavros_odometry(child="odom"), 1.5)
    time.sleep(1.2)  # a diagnostics report (1 s of wall time)
    check(len(rec.odom) == n_before, "child_frame_id 'odom': %d messages published (0 expected)" % (len(rec.odom) - n_before))
    s, refused = rec.value("OdometryAdapter", "refused_frames")
    named = [m for m in rec.messages("OdometryAdapter") if "child_frame_id: expected 'base_link', received 'odom'" in m]
    check(refused is not None and int(refused) >= 20 and named,
          "/diagnostics: %s refused, '%s'" % (refused, named[-1] if named else rec.messages("OdometryAdapter")))

    # --- the relay ---------------------------------------------------------------------------------
    t0 = rospy.Time.now()
    plan_pub.publish(plan(t0))
    time.sleep(0.7)
    poses = [m for m in rec.pose if m.header.stamp >= t0]
    twists = [m for m in rec.twist if m.header.stamp >= t0]
    gimbals = [m for m in rec.gimbal if m.header.stamp >= t0]
    check(len(poses) >= 15 and len(twists) >= 15 and len(gimbals) >= 15,
          "in 0.7 s at 50 Hz: %d poses, %d twists, %d gimbal targets (>= 15 each)" % (len(poses), len(twists), len(gimbals)))
    on_plan = all(abs(m.pose.position.x - (m.header.stamp - t0).to_sec()) < 1e-6 and m.header.frame_id == "map"
                  for m in poses if (m.header.stamp - t0).to_sec() <= 1.0)
    check(on_plan and poses, "every pose setpoint on the plan: x = 1 m/s x (t - t0), frame map")
    tw_ok = all(abs(m.twist.linear.x - 1.0) < 1e-9 and abs(m.twist.angular.z - 0.5) < 1e-9 for m in twists)
    check(tw_ok and twists, "velocity setpoints (1, 0, 0) m/s, yaw rate 0.5 rad/s")
    g_ok = all(abs(m.vector.y + 0.3) < 1e-9 and abs(m.vector.z - 0.5 * (m.header.stamp - t0).to_sec()) < 1e-6 for m in gimbals)
    check(g_ok and gimbals, "gimbal targets: pitch -0.3 rad, heading 0.5 rad/s x (t - t0)")
    if poses:
        ax = axis_of(poses[-1].pose.orientation)
        check(abs(math.atan2(ax[1], ax[0]) - 0.5 * (poses[-1].header.stamp - t0).to_sec()) < 1e-6 and abs(ax[2]) < 1e-9,
              "pose setpoint orientation: level, yaw = the camera heading")

    # --- past the plan's end (1.0 s): its last point, held ---------------------------------------
    time.sleep(1.0)
    late = [m for m in rec.pose if (m.header.stamp - t0).to_sec() > 1.05]
    late_tw = [m for m in rec.twist if (m.header.stamp - t0).to_sec() > 1.05]
    held = late and all(abs(m.pose.position.x - 1.0) < 1e-9 for m in late)
    still = late_tw and all(abs(m.twist.linear.x) < 1e-12 and abs(m.twist.angular.z) < 1e-12 for m in late_tw)
    check(bool(held and still), "after the plan's end: %d setpoints hold x = 1.0 (its last point) with zero velocity" % len(late))
    end = time.time() + 2.5  # the next report (1 s of wall time) after the plan's end
    mode = None
    while time.time() < end and mode != "holding_end":
        time.sleep(0.1)
        s, mode = rec.value("SetpointRelay uav0", "mode")
    check(mode == "holding_end", "/diagnostics SetpointRelay mode '%s' (holding_end)" % mode)

    # --- refused plans: another frame, another UAV ------------------------------------------------
    plan_pub.publish(plan(rospy.Time.now(), frame="world", sequence=2))
    time.sleep(0.3)
    plan_pub.publish(plan(rospy.Time.now(), uav=1, sequence=3))
    time.sleep(1.3)
    recent = [m for m in rec.pose if m.header.stamp > rospy.Time.now() - rospy.Duration(0.3)]
    check(recent and all(abs(m.pose.position.x - 1.0) < 1e-9 for m in recent),
          "after the refused plans: still holding the verified plan's last point")
    s, refused = rec.value("SetpointRelay uav0", "plans_refused")
    check(refused == "2", "/diagnostics: %s plans refused (2 expected)" % refused)
    return FAILS[0]


if __name__ == "__main__":
    sys.exit(main())
