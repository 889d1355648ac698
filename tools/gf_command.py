#!/usr/bin/env python3
"""Sends one command to the formation through the OperatorInterface's services (docs/ros.md):
a view adaptation (gesture_formation/SendCommand) or an abort (gesture_formation/SendAbort).

  tools/gf_command.py TARGET PARAMETER AMOUNT [--set] [--service /operator/send_command]
    TARGET     all | leader | followers | follower<i> | "[0, 2]"
    PARAMETER  beta_deg | gamma_deg | distance_m
    AMOUNT     increment (default) or, with --set, the new value ([deg] or [m])
  tools/gf_command.py abort [--service /operator/send_abort]
    every UAV that accepts it flies to its own retreat goal (docs/safety.md §2.8); the ground
    station sends it abort.repeats times, then once every abort.resend_period_s while it runs
  tools/gf_command.py ack-assist [--service /operator/acknowledge_assistance]
    acknowledges the worker's pending request for assistance (docs/safety.md §2.10): the leader
    then accepts the worker's gesture commands again

  e.g. tools/gf_command.py followers distance_m 1      tools/gf_command.py leader beta_deg 120 --set
       tools/gf_command.py abort
A view adaptation then waits (--ack-timeout, 5 s; 0: do not wait) for the leader's acknowledgement
(docs/safety.md §2.9), which the OperatorInterface republishes on --ack-topic (default: the
service's namespace + /command_ack), and prints what became of the command.
Exit 0 when the command was sent (and acknowledged as applied or duplicate), 1 when refused by the
interface or rejected by the leader (the reason is printed), 2 on bad arguments or when the service
is unreachable, 3 when no acknowledgement came in time."""
import argparse
import sys
import threading
import time


def call(service, srv_type, timeout, *args):
    """The service's response, or None after printing why it could not be called."""
    import rospy
    try:
        rospy.wait_for_service(service, timeout=timeout)
        return rospy.ServiceProxy(service, srv_type)(*args)
    except (rospy.ROSException, rospy.ServiceException) as e:
        print(f"gf_command: {service}: {e}", file=sys.stderr)
        return None


class AckWaiter:
    """Subscribes (before the command is sent) to the acknowledgements the OperatorInterface
    republishes and hands out the one of a sequence number."""

    def __init__(self, topic):
        import rospy
        from gesture_formation.msg import CommandAck
        rospy.init_node("gf_command", anonymous=True, disable_signals=True)
        self._acks = {}
        self._cond = threading.Condition()
        self._sub = rospy.Subscriber(topic, CommandAck, self._on_ack, queue_size=50)
        deadline = time.monotonic() + 2.0  # the connection to the interface's publisher
        while self._sub.get_num_connections() == 0 and time.monotonic() < deadline:
            time.sleep(0.02)

    def _on_ack(self, m):
        if m.source != "operator":
            return
        with self._cond:
            self._acks[m.sequence] = m
            self._cond.notify_all()

    def wait(self, sequence, timeout_s):
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while sequence not in self._acks and time.monotonic() < deadline:
                self._cond.wait(timeout=max(0.0, deadline - time.monotonic()))
            return self._acks.get(sequence)


SERVICES = {"command": "/operator/send_command", "abort": "/operator/send_abort",
            "ack-assist": "/operator/acknowledge_assistance"}


def parse_args(kind):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    if kind == "command":
        ap.add_argument("target")
        ap.add_argument("parameter", choices=["beta_deg", "gamma_deg", "distance_m"])
        ap.add_argument("amount", type=float)
        ap.add_argument("--set", action="store_true", help="set the value instead of incrementing it")
        ap.add_argument("--ack-timeout", type=float, default=5.0,
                        help="wait this long for the leader's acknowledgement [s, wall]; 0: do not wait")
        ap.add_argument("--ack-topic", default=None, help="the OperatorInterface's command_ack_out topic")
    else:
        ap.add_argument("kind", choices=[kind])
    ap.add_argument("--service", default=SERVICES[kind])
    ap.add_argument("--timeout", type=float, default=5.0, help="wait this long for the service [s]")
    return ap.parse_args()


def main():
    kind = sys.argv[1] if len(sys.argv) > 1 and sys.argv[1] in ("abort", "ack-assist") else "command"
    a = parse_args(kind)
    try:
        from gesture_formation.srv import AcknowledgeAssistance, SendAbort, SendCommand
    except ImportError as e:
        print(f"gf_command: {e} (source the workspace's devel/setup.bash)", file=sys.stderr)
        return 2
    # Per kind: the service type, its request's arguments, what to print when it was accepted.
    if kind == "command":
        op = "=" if a.set else "+="
        spec = (SendCommand, (a.target, a.parameter, "set" if a.set else "increment", a.amount),
                lambda r: f"sent #{r.sequence}: {a.target}.{a.parameter} {op} {a.amount:g}")
    elif kind == "abort":
        spec = (SendAbort, (), lambda r: f"abort sent #{r.sequence} ({r.copies} copies, then resent until the ground station restarts)")
    else:
        spec = (AcknowledgeAssistance, (), lambda r: f"assistance request of {r.requested_at.to_sec():.2f} s acknowledged")
    srv_type, args, accepted = spec
    waits = kind == "command" and a.ack_timeout > 0
    acks = AckWaiter(a.ack_topic or a.service.rsplit("/", 1)[0] + "/command_ack") if waits else None
    res = call(a.service, srv_type, a.timeout, *args)
    if res is None:
        return 2
    if not res.accepted:
        print(f"refused: {res.message}", file=sys.stderr)
        return 1
    print(accepted(res), flush=True)
    if acks is None:
        return 0
    ack = acks.wait(res.sequence, a.ack_timeout)
    if ack is None:
        print(f"no acknowledgement from the leader within {a.ack_timeout:g} s (lost on the link, or no leader)",
              file=sys.stderr)
        return 3
    print(f"acknowledged by the leader: {ack.outcome} (parameters version {ack.params_version})")
    return 1 if ack.status == "rejected" else 0


if __name__ == "__main__":
    sys.exit(main())
