#!/usr/bin/env python3
"""Sends one command to the formation through the OperatorInterface's services (docs/ros.md):
a view adaptation (gesture_formation/SendCommand) or an abort (gesture_formation/SendAbort).

  tools/gf_command.py TARGET PARAMETER AMOUNT [--set] [--service /operator/send_command]
    TARGET     all | leader | followers | follower<i> | "[0, 2]"
    PARAMETER  beta_deg | gamma_deg | distance_m
    AMOUNT     increment (default) or, with --set, the new value ([deg] or [m])
  tools/gf_command.py abort [--service /operator/send_abort]
    every UAV that accepts it flies to its own retreat goal (docs/safety.md §2.8); the ground
    station sends it abort.repeats times

  e.g. tools/gf_command.py followers distance_m 1      tools/gf_command.py leader beta_deg 120 --set
       tools/gf_command.py abort
Exit 0 when the command was sent, 1 when refused (the reason is printed), 2 on bad arguments
or when the service is unreachable."""
import argparse
import sys


def call(service, srv_type, timeout, *args):
    """The service's response, or None after printing why it could not be called."""
    import rospy
    try:
        rospy.wait_for_service(service, timeout=timeout)
        return rospy.ServiceProxy(service, srv_type)(*args)
    except (rospy.ROSException, rospy.ServiceException) as e:
        print(f"gf_command: {service}: {e}", file=sys.stderr)
        return None


def main():
    abort = len(sys.argv) > 1 and sys.argv[1] == "abort"
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    if abort:
        ap.add_argument("abort", choices=["abort"])
        ap.add_argument("--service", default="/operator/send_abort")
    else:
        ap.add_argument("target")
        ap.add_argument("parameter", choices=["beta_deg", "gamma_deg", "distance_m"])
        ap.add_argument("amount", type=float)
        ap.add_argument("--set", action="store_true", help="set the value instead of incrementing it")
        ap.add_argument("--service", default="/operator/send_command")
    ap.add_argument("--timeout", type=float, default=5.0, help="wait this long for the service [s]")
    a = ap.parse_args()
    try:
        from gesture_formation.srv import SendAbort, SendCommand
    except ImportError as e:
        print(f"gf_command: {e} (source the workspace's devel/setup.bash)", file=sys.stderr)
        return 2
    if abort:
        res = call(a.service, SendAbort, a.timeout)
        if res is None:
            return 2
        if res.accepted:
            print(f"abort sent #{res.sequence} ({res.copies} copies)")
            return 0
    else:
        res = call(a.service, SendCommand, a.timeout, a.target, a.parameter, "set" if a.set else "increment", a.amount)
        if res is None:
            return 2
        if res.accepted:
            print(f"sent #{res.sequence}: {a.target}.{a.parameter} {'=' if a.set else '+='} {a.amount:g}")
            return 0
    print(f"refused: {res.message}", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
