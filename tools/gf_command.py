#!/usr/bin/env python3
"""Sends one view-adaptation command to the formation through the OperatorInterface's service
(gesture_formation/SendCommand; docs/ros.md).

  tools/gf_command.py TARGET PARAMETER AMOUNT [--set] [--service /operator/send_command]
    TARGET     all | leader | followers | follower<i> | "[0, 2]"
    PARAMETER  beta_deg | gamma_deg | distance_m
    AMOUNT     increment (default) or, with --set, the new value ([deg] or [m])

  e.g. tools/gf_command.py followers distance_m 1      tools/gf_command.py leader beta_deg 120 --set
Exit 0 when the command was sent, 1 when refused (the reason is printed), 2 on bad arguments
or when the service is unreachable."""
import argparse
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("target")
    ap.add_argument("parameter", choices=["beta_deg", "gamma_deg", "distance_m"])
    ap.add_argument("amount", type=float)
    ap.add_argument("--set", action="store_true", help="set the value instead of incrementing it")
    ap.add_argument("--service", default="/operator/send_command")
    ap.add_argument("--timeout", type=float, default=5.0, help="wait this long for the service [s]")
    a = ap.parse_args()
    try:
        import rospy
        from gesture_formation.srv import SendCommand
    except ImportError as e:
        print(f"gf_command: {e} (source the workspace's devel/setup.bash)", file=sys.stderr)
        return 2
    try:
        rospy.wait_for_service(a.service, timeout=a.timeout)
        res = rospy.ServiceProxy(a.service, SendCommand)(a.target, a.parameter, "set" if a.set else "increment", a.amount)
    except (rospy.ROSException, rospy.ServiceException) as e:
        print(f"gf_command: {a.service}: {e}", file=sys.stderr)
        return 2
    if res.accepted:
        print(f"sent #{res.sequence}: {a.target}.{a.parameter} {'=' if a.set else '+='} {a.amount:g}")
        return 0
    print(f"refused: {res.message}", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
