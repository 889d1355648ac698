"""Checks of test/ros/assistance.sh (see there); prints PASS/FAIL lines, exits with the failures."""
import subprocess
import sys
import time

import rospy
from gesture_formation.msg import AssistanceState, CommandAck, FormationCommand
from visualization_msgs.msg import Marker, MarkerArray

SRC = sys.argv[1]
rospy.init_node("assistance_check", anonymous=True)
bad = 0


def check(ok, what):
    global bad
    print(("PASS: " if ok else "FAIL: ") + what, flush=True)
    bad += 0 if ok else 1


leader_state, ground_state, acks = [], [], {}
rospy.Subscriber("/uav0/assistance_state", AssistanceState, leader_state.append)
rospy.Subscriber("/operator/assistance", AssistanceState, ground_state.append)
rospy.Subscriber("/operator/command_ack", CommandAck, lambda m: acks.__setitem__((m.sender, m.sequence), m))
banners = []  # the Visualizer's assistance banner (rviz), per marker array
rospy.Subscriber("/visualization/markers", MarkerArray,
                 lambda a: banners.extend(m for m in a.markers if m.ns == "assistance"))
request_pub = rospy.Publisher("/uav0/assistance", AssistanceState, queue_size=5)
gesture_pub = rospy.Publisher("/uav0/formation_command", FormationCommand, queue_size=5)


def wait_for(pred, timeout_s):
    t0 = time.time()
    while time.time() - t0 < timeout_s:
        if pred():
            return True
        time.sleep(0.05)
    return pred()


def gesture_command(sequence):
    """A follower-distance increment as the leader's GestureCommander publishes a fired gesture."""
    c = FormationCommand()
    c.header.stamp = rospy.Time.now()
    c.sender, c.sequence, c.source = "gesture_test", sequence, "gesture"
    c.target, c.parameter, c.kind, c.amount = "followers", "distance_m", "increment", 0.5
    gesture_pub.publish(c)
    key = ("gesture_test", sequence)
    wait_for(lambda: key in acks, 8.0)  # the leader's acknowledgement over LCM
    return acks.get(key)


def phase(states):
    return states[-1].phase if states else None


# The planners are up (sim time runs) and the ground station heard the leader's initial state.
wait_for(lambda: rospy.get_time() > 4.0 and request_pub.get_num_connections() > 0 and gesture_pub.get_num_connections() > 0, 40)
check(phase(leader_state) == AssistanceState.PHASE_NONE, f"the leader's latched state starts at none: {phase(leader_state)}")
r = AssistanceState()
r.header.stamp = rospy.Time.now()
r.phase, r.requested_at, r.requested_by = AssistanceState.PHASE_REQUESTED, rospy.Time.now(), "gesture_commander"
request_pub.publish(r)
check(wait_for(lambda: phase(leader_state) == AssistanceState.PHASE_REQUESTED, 5),
      "the leader's planner latched the request")
check(wait_for(lambda: phase(ground_state) == AssistanceState.PHASE_REQUESTED, 5)
      and ground_state[-1].requested_at == r.requested_at,
      "the ground station's OperatorInterface got it over LCM (/operator/assistance)")
check(wait_for(lambda: banners and banners[-1].action == Marker.ADD and "ASSISTANCE REQUESTED" in banners[-1].text, 5),
      f"rviz: the Visualizer shows the banner: {banners[-1].text if banners else 'no marker'}")
a = gesture_command(1)
check(a is not None and a.status == "rejected" and "assistance requested" in a.outcome,
      f"a gesture command while it is pending is rejected: {a.outcome if a else 'no acknowledgement'}")
cli = subprocess.run([sys.executable, SRC + "/tools/gf_command.py", "followers", "distance_m", "1"], capture_output=True, text=True)
check(cli.returncode == 0 and "acknowledged by the leader: applied" in cli.stdout,
      f"the operator's command is applied meanwhile: {cli.stdout.strip()} {cli.stderr.strip()}")
cli = subprocess.run([sys.executable, SRC + "/tools/gf_command.py", "ack-assist"], capture_output=True, text=True)
check(cli.returncode == 0 and "acknowledged" in cli.stdout, f"gf_command.py ack-assist: {cli.stdout.strip()} {cli.stderr.strip()}")
check(wait_for(lambda: phase(leader_state) == AssistanceState.PHASE_ACKNOWLEDGED, 5)
      and leader_state[-1].acknowledged_by.startswith("operator"),
      f"the leader's planner took the acknowledgement over LCM: {leader_state[-1].acknowledged_by if leader_state else None}")
check(wait_for(lambda: phase(ground_state) == AssistanceState.PHASE_ACKNOWLEDGED, 5), "the ground station says acknowledged")
check(wait_for(lambda: banners and banners[-1].action == Marker.DELETE, 5), "rviz: the banner is removed")
a = gesture_command(2)
check(a is not None and a.status == "applied", f"a gesture command is applied again: {a.outcome if a else 'no acknowledgement'}")
cli = subprocess.run([sys.executable, SRC + "/tools/gf_command.py", "ack-assist"], capture_output=True, text=True)
check(cli.returncode == 1 and "no request" in cli.stderr, f"a second ack-assist is refused: {cli.stderr.strip()}")
sys.exit(bad)
