#!/usr/bin/env python3
"""A lossy radio between network namespaces: forwards UDP multicast (LCM) among links with
loss, delay, jitter (hence reordering) and duplication, from a seeded random generator.

The kernel of this machine has no netem qdisc (`tc qdisc add dev lo root netem ...` answers
"Specified qdisc kind is unknown"; docs/safety.md §5), so tools/run_multihost.sh
puts this relay in the switch namespace that joins the UAVs' namespaces: each host sends its
multicast (ttl=1) over its veth to the switch, where the kernel does not route multicast; this
relay receives it, and for every other link independently drops it with probability --loss or
sends it after --delay-ms ± --jitter-ms (uniform), a second copy with probability --duplicate.
Unicast (the ROS connections to the simulated world) is routed by the kernel, untouched.

    radio_relay.py --links 10.77.0.1,10.77.1.1,10.77.2.1 [--group 239.255.76.67 --port 7667]
                   [--loss 0.2] [--delay-ms 30] [--jitter-ms 20] [--duplicate 0.01] [--seed 1]
                   [--stats FILE]

--links: the switch-side address of each link (/24: the host on the link is the sender of
every datagram from that subnet). On SIGINT/SIGTERM it writes --stats (JSON: datagrams
received, per destination forwarded / dropped / duplicated, delay applied) and exits 0.
"""
import argparse
import heapq
import ipaddress
import json
import random
import select
import signal
import socket
import struct
import sys
import time


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--links", required=True, help="switch-side IPv4 address of each link, comma-separated")
    ap.add_argument("--group", default="239.255.76.67")
    ap.add_argument("--port", type=int, default=7667)
    ap.add_argument("--loss", type=float, default=0.0, help="probability a datagram is lost, per destination")
    ap.add_argument("--delay-ms", type=float, default=0.0)
    ap.add_argument("--jitter-ms", type=float, default=0.0, help="uniform ± around the delay (reorders)")
    ap.add_argument("--duplicate", type=float, default=0.0, help="probability of a second copy")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--stats", default=None)
    ap.add_argument("--check-only", action="store_true", help="validate the arguments and exit")
    a = ap.parse_args(argv)
    problems = []
    for name in ("loss", "duplicate"):
        v = getattr(a, name)
        if not 0.0 <= v <= 1.0:
            problems.append(f"--{name} {v}: must be in [0, 1]")
    if a.delay_ms < 0:
        problems.append(f"--delay-ms {a.delay_ms}: must be >= 0")
    if a.jitter_ms < 0 or a.jitter_ms > a.delay_ms:
        problems.append(f"--jitter-ms {a.jitter_ms}: must be in [0, --delay-ms {a.delay_ms}]")
    links = []
    for s in a.links.split(","):
        try:
            links.append(ipaddress.IPv4Address(s.strip()))
        except ValueError:
            problems.append(f"--links: '{s}' is not an IPv4 address")
    if len(links) < 2:
        problems.append(f"--links {a.links}: at least two links")
    try:
        if not ipaddress.IPv4Address(a.group).is_multicast:
            problems.append(f"--group {a.group}: not a multicast address")
    except ValueError:
        problems.append(f"--group '{a.group}': not an IPv4 address")
    if problems:
        ap.error("; ".join(problems))
    a.links = links
    return a


def main(argv):
    a = parse_args(argv)
    if a.check_only:
        return 0
    nets = [ipaddress.IPv4Network(f"{ip}/24", strict=False) for ip in a.links]
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    rx.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    rx.bind(("", a.port))
    for ip in a.links:
        rx.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                      socket.inet_aton(a.group) + socket.inet_aton(str(ip)))
    tx = []
    for ip in a.links:
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(str(ip)))
        s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, struct.pack("b", 1))
        s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, struct.pack("b", 0))
        tx.append(s)
    rng = random.Random(a.seed)
    n = len(a.links)
    stats = {"received": [0] * n, "forwarded": [0] * n, "dropped": [0] * n, "duplicated": [0] * n,
             "unknown_source": 0, "bytes_received": 0, "delay_ms_sum": 0.0,
             "config": {"loss": a.loss, "delay_ms": a.delay_ms, "jitter_ms": a.jitter_ms,
                        "duplicate": a.duplicate, "seed": a.seed, "links": [str(x) for x in a.links]}}
    queue = []  # (due, sequence, destination, payload)
    seq = 0
    running = [True]

    def stop(*_):
        running[0] = False
    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    print(f"radio_relay: {n} links, loss {a.loss}, delay {a.delay_ms} ± {a.jitter_ms} ms, "
          f"duplicate {a.duplicate}, seed {a.seed}", flush=True)
    while running[0]:
        now = time.monotonic()
        while queue and queue[0][0] <= now:
            _, _, dst, payload = heapq.heappop(queue)
            try:
                tx[dst].sendto(payload, (a.group, a.port))
                stats["forwarded"][dst] += 1
            except OSError:
                stats["dropped"][dst] += 1
        timeout = max(0.0, queue[0][0] - now) if queue else 0.2
        try:
            ready, _, _ = select.select([rx], [], [], min(timeout, 0.2))
        except InterruptedError:
            continue
        if not ready:
            continue
        payload, (src, _) = rx.recvfrom(65535)
        src_ip = ipaddress.IPv4Address(src)
        origin = next((i for i, net in enumerate(nets) if src_ip in net), None)
        if origin is None or src_ip in a.links:
            stats["unknown_source"] += 1
            continue
        stats["received"][origin] += 1
        stats["bytes_received"] += len(payload)
        now = time.monotonic()
        for dst in range(n):
            if dst == origin:
                continue
            if rng.random() < a.loss:
                stats["dropped"][dst] += 1
                continue
            copies = 2 if rng.random() < a.duplicate else 1
            if copies == 2:
                stats["duplicated"][dst] += 1
            for _ in range(copies):
                d = a.delay_ms + (rng.uniform(-a.jitter_ms, a.jitter_ms) if a.jitter_ms > 0 else 0.0)
                stats["delay_ms_sum"] += d
                seq += 1
                heapq.heappush(queue, (now + d / 1000.0, seq, dst, payload))
    if a.stats:
        with open(a.stats, "w") as f:
            json.dump(stats, f, indent=1)
    total_fwd, total_drop = sum(stats["forwarded"]), sum(stats["dropped"])
    print(f"radio_relay: received {sum(stats['received'])}, forwarded {total_fwd}, dropped {total_drop} "
          f"({100.0 * total_drop / max(1, total_fwd + total_drop):.1f} %), duplicated {sum(stats['duplicated'])}",
          flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
