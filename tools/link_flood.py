#!/usr/bin/env python3
"""Legitimate messages delivered while a keyless flood saturates the loopback (docs/security.md §9).
Run by tools/security_figures.sh inside a private network namespace with a ROS master: two real
LcmBridges, leader L (sender 0) and follower R (sender 2), per-sender keys; L forwards worker
states published at RATE_HZ to R; flood processes send, as fast as they can, datagrams of one
kind on R's worker-state channel. Prints one line per kind: delivered/sent legitimate messages,
flood datagrams sent, and R's refusal counters. Environment: T (work dir with keys/), SRC."""
import multiprocessing
import os
import random
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from gesture_formation.msg import WorkerState

T = os.environ["T"]
GROUP, PORT = "239.255.76.67", 7667
URL = "udpm://%s:%d?ttl=0" % (GROUP, PORT)
PREFIX = "GFF_"
CHANNEL = PREFIX + "WORKER_STATE"
RATE_HZ = 20.0
DURATION_S = float(os.environ.get("FLOOD_SECONDS", "10"))
FLOODERS = int(os.environ.get("FLOODERS", "2"))
# python: each flood process sends with socket.sendto; c: each runs FLOOD_SENDER (the compiled
# tools/link_flood_sender.c: sendmmsg batches, several times the Python rate).
FLOOD_IMPL = os.environ.get("FLOOD_IMPL", "python")


def lcm_datagram(seq, body):
    return struct.pack(">II", 0x4C433032, seq) + CHANNEL.encode() + b"\0" + body


def flood_worker(kind, fingerprint, stop_at, counter):
    """Sends `kind` datagrams until stop_at; no key needed for any of them."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    rng = random.Random(os.getpid())
    n = 0
    templates = []
    for i in range(256):
        if kind == "garbage":
            env = bytes(rng.getrandbits(8) for _ in range(200))
        else:
            sender = {"forged_unknown_sender": 77, "forged_as_other_follower": 1, "forged_as_leader": 0}[kind]
            payload = bytes(rng.getrandbits(8) for _ in range(113))
            header = b"GF" + struct.pack(">BBHBBQdI", 2, 2, sender, 1, 0, 2**60 + i, time.time(), len(payload))
            env = header + payload + bytes(rng.getrandbits(8) for _ in range(64))
        templates.append(fingerprint + struct.pack(">i", len(env)) + env)
    if FLOOD_IMPL == "c":
        path = "%s/flood_%d.bin" % (T, os.getpid())
        with open(path, "wb") as f:
            for i, t in enumerate(templates):
                d = lcm_datagram(i, t)
                f.write(struct.pack(">I", len(d)) + d)
        out = subprocess.run([os.environ["FLOOD_SENDER"], path, GROUP, str(PORT), repr(stop_at)],
                             check=True, capture_output=True, text=True).stdout
        counter.value += int(out.strip())
        return
    while time.time() < stop_at:
        for i in range(2000):
            try:
                s.sendto(lcm_datagram(n & 0xFFFFFFFF, templates[i & 255]), (GROUP, PORT))
            except OSError:
                pass  # ENOBUFS under saturation
            n += 1
    counter.value += n


def bridge(name, sender_id, known, key, remaps):
    subprocess.run(["rosparam", "set", "/%s/known_senders" % name, str(known)], check=True)
    args = ["rosrun", "nodelet", "nodelet", "standalone", "gesture_formation/LcmBridge", "__name:=" + name,
            "_sender_id:=%d" % sender_id, "_lcm_url:=" + URL, "_channel_prefix:=" + PREFIX,
            "_key_file:=%s/keys/%s" % (T, key), "_max_age_s:=1.0", "_heartbeat_rate_hz:=5.0",
            "_world_frame:=world", "_command_repeats:=5", "_command_repeat_period_s:=0.1",
            "_sequence_file:=%s/%s.boot" % (T, name), "_high_water_file:=%s/%s.marks" % (T, name)] + remaps
    return subprocess.Popen(args, stdout=open("%s/%s.log" % (T, name), "a"), stderr=subprocess.STDOUT,
                            start_new_session=True)


def learn_fingerprint():
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    rx.bind(("", PORT))
    rx.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                  struct.pack("4s4s", socket.inet_aton(GROUP), socket.inet_aton("0.0.0.0")))
    rx.settimeout(10)
    while True:
        data = rx.recv(65536)
        end = data.index(b"\0", 8)
        if data[8:end].decode().startswith(PREFIX):
            rx.close()
            return data[end + 1:end + 9]


def main():
    rospy.init_node("link_flood", disable_signals=True)
    received = []
    rospy.Subscriber("/r/worker_state", WorkerState, lambda m: received.append(int(m.position.x)), queue_size=1000)
    diag = {}
    rospy.Subscriber("/diagnostics", DiagnosticArray,
                     lambda a: diag.update({s.name: {kv.key: int(kv.value) for kv in s.values} for s in a.status}))
    pub = rospy.Publisher("/l/worker_state_in", WorkerState, queue_size=100)
    procs = [bridge("r_bridge", 2, [0, 1], "sender_2.key", ["worker_state_out:=/r/worker_state"]),
             bridge("l_bridge", 0, [1, 2], "sender_0.key", ["worker_state_in:=/l/worker_state_in"])]
    try:
        fingerprint = learn_fingerprint()
        deadline = time.time() + 20
        while pub.get_num_connections() == 0 and time.time() < deadline:
            time.sleep(0.1)
        time.sleep(2.0)
        print("kind | legitimate delivered / sent | flood datagrams sent (rate) | R: rate_limited, forged, unknown_sender, malformed/undecodable")
        for kind in ["none", "garbage", "forged_unknown_sender", "forged_as_other_follower", "forged_as_leader"]:
            before = dict(diag.get("LcmBridge sender 2: link", {}))
            received.clear()
            counter = multiprocessing.Value("q", 0)
            stop_at = time.time() + DURATION_S + 1.0
            workers = []
            if kind != "none":
                workers = [multiprocessing.Process(target=flood_worker, args=(kind, fingerprint, stop_at, counter))
                           for _ in range(FLOODERS)]
                for w in workers:
                    w.start()
            time.sleep(0.5)
            sent = 0
            t0 = time.time()
            while time.time() - t0 < DURATION_S:
                m = WorkerState()
                m.header.stamp = rospy.Time.now()
                m.header.frame_id = "world"
                m.position.x = sent  # identifies the message at the receiver
                m.last_fused = m.header.stamp
                m.source = "uwb"
                pub.publish(m)
                sent += 1
                time.sleep(max(0.0, t0 + sent / RATE_HZ - time.time()))
            for w in workers:
                w.join()
            time.sleep(1.5)
            after = diag.get("LcmBridge sender 2: link", {})
            d = {k: after.get(k, 0) - before.get(k, 0) for k in after}
            flood = counter.value
            print("%s | %d / %d (%.0f %%) | %d (%.0f /s) | %d, %d, %d, %d" % (
                kind, len(set(received)), sent, 100.0 * len(set(received)) / sent, flood, flood / (DURATION_S + 0.5),
                d.get("rate_limited", 0), d.get("forged", 0), d.get("unknown_sender", 0),
                d.get("malformed", 0) + d.get("undecodable_lcm", 0) + d.get("truncated", 0) + d.get("oversize", 0)), flush=True)
    finally:
        for p in procs:
            os.killpg(p.pid, signal.SIGINT)
            p.wait(10)
    return 0


if __name__ == "__main__":
    sys.exit(main())
