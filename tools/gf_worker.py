#!/usr/bin/env python3
"""Choose the worker among the people the leader's camera sees (docs/perception.md "Choosing the
worker"): the ground station's view of the Perception nodelet's candidates and its ~select_worker.

  tools/gf_worker.py list [--ns /uav0/perception]         the people of the next detection round
  tools/gf_worker.py pick U V [--ns ...]                   the person whose box contains image point (U, V) [px]
                                                           (refused when two boxes do: pick by candidate)
  tools/gf_worker.py pick --candidate N [--ns ...]         candidate N of the next detection round
  tools/gf_worker.py unlock [--ns ...]                     end the choice (after a loss the tracker may
                                                           take the best-scoring person again)
--ns is the Perception nodelet's namespace: its candidates are on NS/candidates (onboard.launch and
sim_uav.launch remap them so) and its service is NS/select_worker. After a choice the tracker is
locked to that person: it keeps it through crossings by its colours and does not start another
identity by itself (after a loss it re-acquires by position or colour alone: a look-alike can be
taken; docs/perception.md, Known limits). Exit 0 when done, 1 when the nodelet refused (the reason is printed), 2 when it is
unreachable or no candidates arrived within --timeout."""
import argparse
import sys
import threading


def next_candidates(topic, timeout):
    """The next WorkerCandidates message on `topic`, or None."""
    import rospy
    from gesture_formation.msg import WorkerCandidates
    got, done = [], threading.Event()
    sub = rospy.Subscriber(topic, WorkerCandidates, lambda m: (got.append(m), done.set()), queue_size=1)
    done.wait(timeout)
    sub.unregister()
    return got[0] if got else None


def describe(c):
    lines = [f"detection round {c.header.seq} at {c.header.stamp.to_sec():.2f} s ({c.header.frame_id}): "
             f"{len(c.u)} person(s); worker: {'candidate %d' % c.worker if c.worker >= 0 else 'none of them'}"
             f" (id {c.worker_id}){', locked by the operator' if c.locked else ''}"]
    for i in range(len(c.u)):
        lines.append(f"  [{i}] box u {c.u[i]:.0f} v {c.v[i]:.0f} w {c.w[i]:.0f} h {c.h[i]:.0f} px, score {c.score[i]:.2f}"
                     f"{'  <- worker' if i == c.worker else ''}")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("action", choices=["list", "pick", "unlock"])
    ap.add_argument("point", nargs="*", type=float, help="pick: image point U V [px]")
    ap.add_argument("--candidate", type=int, default=None, help="pick: candidate index of the next detection round")
    ap.add_argument("--ns", default="/uav0/perception", help="the Perception nodelet's namespace")
    ap.add_argument("--timeout", type=float, default=5.0, help="wait this long for candidates / the service [s]")
    a = ap.parse_args()
    if a.action == "pick" and (a.candidate is None) == (len(a.point) != 2):
        ap.error("pick needs either U V or --candidate N")
    try:
        import rospy
        from gesture_formation.srv import SelectWorker
    except ImportError as e:
        print(f"gf_worker: {e} (source the workspace's devel/setup.bash)", file=sys.stderr)
        return 2
    rospy.init_node("gf_worker", anonymous=True, disable_signals=True)
    ns = a.ns.rstrip("/")
    seq = 0
    if a.action == "list" or a.candidate is not None:
        c = next_candidates(ns + "/candidates", a.timeout)
        if c is None:
            print(f"gf_worker: no WorkerCandidates on {ns}/candidates within {a.timeout:g} s", file=sys.stderr)
            return 2
        print(describe(c))
        if a.action == "list":
            return 0
        seq = c.header.seq
    try:
        rospy.wait_for_service(ns + "/select_worker", timeout=a.timeout)
        select = rospy.ServiceProxy(ns + "/select_worker", SelectWorker)
        u, v = (a.point + [0.0, 0.0])[:2]
        res = select(u=u, v=v, candidate=-1 if a.candidate is None else a.candidate, candidates_seq=seq,
                     unlock=a.action == "unlock")
    except (rospy.ROSException, rospy.ServiceException) as e:
        print(f"gf_worker: {ns}/select_worker: {e}", file=sys.stderr)
        return 2
    print(res.message if res.accepted else f"refused: {res.message}", file=sys.stdout if res.accepted else sys.stderr)
    return 0 if res.accepted else 1


if __name__ == "__main__":
    sys.exit(main())
