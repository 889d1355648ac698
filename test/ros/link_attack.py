#!/usr/bin/env python3
"""Attacker test of the inter-UAV link (docs/security.md; run by link_attack.sh inside a private
network namespace with a ROS master and sim time). Two real LcmBridge nodelets: the leader L
(sender 0) and a follower R (sender 2, the receiver under attack). The attacker holds the key
file of follower 1 (a captured UAV) and sniffs and injects raw multicast datagrams with its
own envelope and LCM framing (written here from the wire format, not the bridge's code):

1. impersonation: envelopes claiming the leader, signed with follower 1's key, are refused
   (forged), also one pushing the leader's sequence to 2^64-1; the leader's real traffic and
   commands still pass; follower 1 speaking as itself is accepted (the builder is right);
2. every rejection class is counted per claimed sender on /diagnostics, exactly;
3. L restarted with its clock 10 s behind (faketime; stamps from the shared sim clock) is
   accepted again within one heartbeat period, without a stale refusal;
4. a command recorded from L and replayed right after R restarted (within the 5 s command
   age) is refused (replayed/stale), not delivered.
Exit 0 when every check passes."""
import os
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

import rospy
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey
from diagnostic_msgs.msg import DiagnosticArray
from gesture_formation.msg import FormationCommand
from rosgraph_msgs.msg import Clock

T = os.environ["T"]
SRC = os.environ["SRC"]
GROUP, PORT = "239.255.76.67", 7667
URL = "udpm://%s:%d?ttl=0" % (GROUP, PORT)
PREFIX = "GFA_"
HEARTBEAT, COMMAND = 1, 5
HEARTBEAT_PERIOD_S = 0.2  # heartbeat_rate_hz 5

failures = []


def check(ok, what):
    print(("PASS: " if ok else "FAIL: ") + what, flush=True)
    if not ok:
        failures.append(what)


# --- keys: follower 1's file, as a captured UAV would give it away ---------------------------
def read_seed(path):
    for line in open(path):
        words = line.split()
        if len(words) >= 3 and words[2] == "signing":
            return int(words[0]), bytes.fromhex(words[1])
    raise SystemExit("no signing line in " + path)


KEY_ID, SEED1 = read_seed(os.path.join(T, "keys", "sender_1.key"))
STOLEN = Ed25519PrivateKey.from_private_bytes(SEED1)


# --- the attacker's own envelope builder (docs/security.md §3.1, version 2) ------------------
def envelope(msg_type, sender, sequence, stamp_s, payload, key_id=KEY_ID, key=STOLEN, version=2):
    header = b"GF" + struct.pack(">BBHBBQdI", version, msg_type, sender, key_id, 0, sequence, stamp_s, len(payload))
    return header + payload + key.sign(header + payload)


def heartbeat_payload(uav, status=0):
    return struct.pack(">HBBI", uav, status, 0, 0)


# --- raw LCM over UDP multicast (LCM's small-message framing) --------------------------------
class Wire:
    def __init__(self):
        self.rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self.rx.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.rx.bind(("", PORT))
        mreq = struct.pack("4s4s", socket.inet_aton(GROUP), socket.inet_aton("0.0.0.0"))
        self.rx.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
        self.tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self.tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        self.tx.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4 << 20)
        self.seq = 0
        self.fingerprint = None
        self.captured = []  # (channel, datagram, envelope)
        self.lock = threading.Lock()
        threading.Thread(target=self._sniff, daemon=True).start()

    def _sniff(self):
        while True:
            data, _ = self.rx.recvfrom(65536)
            if len(data) < 8 or struct.unpack(">I", data[:4])[0] != 0x4C433032:
                continue
            end = data.index(b"\0", 8)
            channel = data[8:end].decode()
            body = data[end + 1:]
            if len(body) < 12:
                continue
            n = struct.unpack(">i", body[8:12])[0]
            env = body[12:12 + n]
            with self.lock:
                if self.fingerprint is None and channel.startswith(PREFIX) and env[:2] == b"GF" and env[2] == 2:
                    self.fingerprint = body[:8]  # the LCM type's fingerprint, learnt from the wire
                self.captured.append((channel, data, env, time.time()))

    def send_envelope(self, channel, env):
        body = self.fingerprint + struct.pack(">i", len(env)) + env
        self.send_raw(channel, body)

    def send_raw(self, channel, body):
        self.seq = (self.seq + 1) & 0xFFFFFFFF
        self.tx.sendto(struct.pack(">II", 0x4C433032, self.seq) + channel.encode() + b"\0" + body, (GROUP, PORT))

    def replay(self, datagram):
        self.tx.sendto(datagram, (GROUP, PORT))

    def take(self, predicate):
        with self.lock:
            return [c for c in self.captured if predicate(c)]


# --- ROS side: sim clock, diagnostics, outputs ------------------------------------------------
class Ros:
    def __init__(self):
        rospy.init_node("link_attacker", disable_signals=True)
        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self.offset_s = 0.0
        threading.Thread(target=self._clock, daemon=True).start()
        self.diag = {}
        self.diag_lock = threading.Lock()
        rospy.Subscriber("/diagnostics", DiagnosticArray, self._on_diag, queue_size=50)
        self.commands = []
        rospy.Subscriber("/r/formation_command", FormationCommand, lambda m: self.commands.append(m), queue_size=100)
        self.command_pub = rospy.Publisher("/l/formation_command_in", FormationCommand, queue_size=10)

    def now(self):
        return time.time()  # the sim clock published below is wall time

    def _clock(self):
        while True:
            t = time.time()
            msg = Clock()
            msg.clock = rospy.Time(int(t), int((t % 1) * 1e9))
            self.clock_pub.publish(msg)
            time.sleep(0.005)

    def _on_diag(self, msg):
        with self.diag_lock:
            for s in msg.status:
                self.diag[s.name] = ({kv.key: int(kv.value) for kv in s.values}, time.time())

    def counts(self, name):
        with self.diag_lock:
            return dict(self.diag.get(name, ({}, 0))[0])

    def fresh_counts(self, name, after_s=None, timeout_s=6.0):
        """Counts published after `after_s` (wall time)."""
        after_s = time.time() if after_s is None else after_s
        deadline = time.time() + timeout_s
        while time.time() < deadline:
            with self.diag_lock:
                entry = self.diag.get(name)
            if entry and entry[1] > after_s:
                return dict(entry[0])
            time.sleep(0.05)
        return None


R_LINK = "LcmBridge sender 2: link"


def from_sender(s):
    return "LcmBridge sender 2: from sender %d" % s


def bridge(name, sender_id, known, key, remaps, env_prefix=()):
    args = ["stdbuf", "-oL"] + list(env_prefix) + [
        "rosrun", "nodelet", "nodelet", "standalone", "gesture_formation/LcmBridge", "__name:=" + name,
        "_sender_id:=%d" % sender_id, "_lcm_url:=" + URL, "_channel_prefix:=" + PREFIX,
        "_key_file:=" + os.path.join(T, "keys", key), "_max_age_s:=1.0", "_heartbeat_rate_hz:=5.0",
        "_world_frame:=world", "_command_repeats:=5", "_command_repeat_period_s:=0.1",
        "_sequence_file:=%s/%s.boot" % (T, name), "_high_water_file:=%s/%s.marks" % (T, name)] + remaps
    subprocess.run(["rosparam", "set", "/%s/known_senders" % name, str(known)], check=True)
    if name == "r_bridge":  # formation commands only from the leader
        subprocess.run(["rosparam", "set", "/r_bridge/command_senders", "[0]"], check=True)
    log = open(os.path.join(T, name + ".log"), "a")
    return subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)


def stop(p):
    os.killpg(p.pid, signal.SIGINT)
    try:
        p.wait(10)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()


def wait_for(cond, timeout_s):
    deadline = time.time() + timeout_s
    while time.time() < deadline:
        value = cond()
        if value:
            return value
        time.sleep(0.05)
    return None


def phase_impersonation(wire, ros):
    now = ros.now()
    ch_hb, ch_cmd = PREFIX + "HEARTBEAT", PREFIX + "FORMATION_COMMAND"
    before0 = ros.counts(from_sender(0))
    commands_before = len(ros.commands)
    # a command claiming the leader (a valid payload: operator "evil", distance +5 m, all)
    cmd = bytes([4]) + b"evil" + struct.pack(">QBBB", 1, 0, 2, 0) + struct.pack(">BBd", 2, 0, 5.0)
    wire.send_envelope(ch_cmd, envelope(COMMAND, 0, 2**40 * 5000, now, cmd))
    wire.send_envelope(ch_hb, envelope(HEARTBEAT, 0, 2**64 - 1, now, heartbeat_payload(0)))  # push the leader's window
    wire.send_envelope(ch_hb, envelope(HEARTBEAT, 1, 2**50, now, heartbeat_payload(1)))     # follower 1 as itself
    sent_at = time.time()
    time.sleep(1.2)
    after0 = ros.fresh_counts(from_sender(0), sent_at + 1.0)
    after1 = ros.counts(from_sender(1))
    check(after0 is not None and after0["forged"] - before0.get("forged", 0) == 2,
          "2 envelopes claiming the leader signed with follower 1's key refused as forged (%s)" % (after0 or {}).get("forged"))
    check(len(ros.commands) == commands_before, "the forged command was not delivered to R's formation_command_out")
    check(after1.get("accepted", 0) == 1, "follower 1 speaking as itself accepted once (the builder is right): %s" % after1.get("accepted"))
    acc = after0["accepted"] if after0 else 0
    later = wait_for(lambda: (ros.counts(from_sender(0)).get("accepted", 0) > acc + 2) or None, 4.0)
    check(bool(later), "the leader's real heartbeats still accepted after the 2^64-1 push")


def phase_classes(wire, ros):
    ch = PREFIX + "HEARTBEAT"
    now = ros.now()
    s = 2**51  # follower 1's own key: everything but the defect is right
    base = ros.fresh_counts(from_sender(1)) or {}
    link_base = ros.counts(R_LINK)
    good = envelope(HEARTBEAT, 1, s, now, heartbeat_payload(1))
    wire.send_envelope(ch, good)                                                        # accepted
    wire.send_envelope(ch, good)                                                        # replayed
    bad_mac = bytearray(envelope(HEARTBEAT, 1, s + 1, now, heartbeat_payload(1))); bad_mac[-1] ^= 1
    wire.send_envelope(ch, bytes(bad_mac))                                              # forged (bad MAC)
    wire.send_envelope(ch, envelope(HEARTBEAT, 1, s + 2, now, heartbeat_payload(1), key_id=(KEY_ID + 8) % 256))  # unknown_key
    wire.send_envelope(ch, envelope(HEARTBEAT, 1, s + 3, now + 10.0, heartbeat_payload(1)))  # too_new (future)
    wire.send_envelope(ch, envelope(HEARTBEAT, 1, s + 4, now - 10.0, heartbeat_payload(1)))  # too_old
    wire.send_envelope(ch, envelope(HEARTBEAT, 1, s - 5000, now, heartbeat_payload(1)))      # stale
    wire.send_envelope(ch, envelope(HEARTBEAT, 1, s + 5, now, heartbeat_payload(1, status=9)))  # decode failure
    wire.send_envelope(ch, envelope(HEARTBEAT, 1, s + 6, now, heartbeat_payload(1)) + b"\0")  # malformed (totals)
    wire.send_envelope(ch, envelope(HEARTBEAT, 77, s, now, heartbeat_payload(1)))            # unknown_sender (totals)
    wire.send_raw(ch, b"\0" * 40)                                                            # not an envelope_t
    sent_at = time.time()
    got = ros.fresh_counts(from_sender(1), sent_at + 1.0)
    link = ros.counts(R_LINK)
    if got is None:
        check(False, "R published diagnostics after the class batch")
        return
    delta = {k: got.get(k, 0) - base.get(k, 0) for k in got}
    for key, expected in [("accepted", 2), ("replayed", 1), ("forged", 1), ("unknown_key", 1), ("too_new", 1),
                          ("too_old", 1), ("stale", 1), ("decode_failure", 1)]:
        # accepted 2: the good one and the decode-failure one (its signature is valid)
        check(delta.get(key) == expected, "sender 1 %s counted %s (expected %d)" % (key, delta.get(key), expected))
    for key in ["malformed", "unknown_sender", "undecodable_lcm"]:
        check(link.get(key, 0) - link_base.get(key, 0) == 1, "link %s counted %s (expected 1)" % (key, link.get(key, 0) - link_base.get(key, 0)))
    # queue overflow / flood: 3000 forgeries claiming follower 1 as fast as we can send
    bad = bytearray(envelope(HEARTBEAT, 1, s + 100, now, heartbeat_payload(1))); bad[-1] ^= 1
    for _ in range(3000):
        wire.send_envelope(ch, bytes(bad))
    sent_at = time.time()
    flood = ros.fresh_counts(from_sender(1), sent_at + 1.5)
    limited = flood.get("rate_limited", 0) - got.get("rate_limited", 0) if flood else 0
    forged = flood.get("forged", 0) - got.get("forged", 0) if flood else 0
    check(limited > 0, "flood: %d refused by the per-sender budget before the signature check, %d checked (forged)" % (limited, forged))
    check(forged <= 3000 - limited, "flood: forged + rate_limited (%d) within the 3000 sent (the rest lost in queues)" % (forged + limited))


def boot_of(env):
    return struct.unpack(">Q", env[8:16])[0] >> 40


def phase_clock_back(wire, ros, leader):
    stop(leader)
    fake = subprocess.run(["faketime", "-f", "-10s", "date", "+%s"], capture_output=True, text=True).stdout.strip()
    check(abs(int(fake) - (time.time() - 10)) < 2, "faketime sets the leader's clock 10 s back (%s vs %d)" % (fake, time.time()))
    before = ros.fresh_counts(from_sender(0)) or {}
    started = time.time()
    leader = bridge("l_bridge", 0, [1, 2], "sender_0.key", ["formation_command_in:=/l/formation_command_in"],
                    env_prefix=["faketime", "-f", "-10s"])
    ready = wait_for(lambda: "LcmBridge: boot 2" in open(os.path.join(T, "l_bridge.log")).read(), 20.0)
    check(bool(ready), "the leader restarted (boot counter 2) under faketime -10s in %.1f s" % (time.time() - started))

    def from_new_boot(c):
        return c[2][:2] == b"GF" and struct.unpack(">H", c[2][4:6])[0] == 0 and boot_of(c[2]) == 2

    wait_for(lambda: len(wire.take(from_new_boot)) >= 10 or None, 10.0)
    snapshot_at = time.time()
    after = ros.fresh_counts(from_sender(0), snapshot_at, 5.0) or {}
    sent = [c for c in wire.take(from_new_boot) if c[3] < snapshot_at - 0.1]
    first = min((c[3] for c in wire.take(from_new_boot)), default=None)
    accepted = after.get("accepted", 0) - before.get("accepted", 0)
    check(len(sent) > 0 and accepted >= len(sent),
          "R accepted all %d envelopes the restarted leader sent in its first %.1f s (%d accepted), the first heartbeat "
          "included: rejoined within one heartbeat period (%.1f s)" %
          (len(sent), snapshot_at - (first or snapshot_at), accepted, HEARTBEAT_PERIOD_S))
    for key in ("stale", "too_old", "too_new"):
        check(after.get(key, 0) == before.get(key, 0), "no %s refusal of the restarted leader (%d → %d)" %
              (key, before.get(key, 0), after.get(key, 0)))
    return leader


def phase_replay_after_restart(wire, ros, receiver):
    n0 = len(ros.commands)
    t_cmd = time.time()
    msg = FormationCommand()
    msg.header.stamp = rospy.Time.now()
    msg.sender, msg.sequence, msg.source, msg.target = "op", 7, "operator", "all"
    msg.parameter, msg.kind, msg.amount = "distance_m", "increment", 0.5
    ch = PREFIX + "FORMATION_COMMAND"
    # The captured follower first sends, with its own valid key, a command carrying the id the
    # operator will use next ("op", 7): R takes commands from the leader only (command_senders),
    # and the id must not make R drop the leader's real one as a copy.
    before1 = ros.fresh_counts(from_sender(1)) or {}
    prefill = bytes([2]) + b"op" + struct.pack(">QBBB", 7, 0, 2, 0) + struct.pack(">BBd", 2, 0, 0.5)
    wire.send_envelope(ch, envelope(COMMAND, 1, 2**52, ros.now(), prefill))
    sent_at = time.time()
    after1 = ros.fresh_counts(from_sender(1), sent_at + 1.0) or {}
    check(len(ros.commands) == n0 and after1.get("not_permitted", 0) - before1.get("not_permitted", 0) == 1,
          "follower 1's own, authentic command refused as not_permitted (command_senders [0]), not forwarded")
    wait_for(lambda: ros.command_pub.get_num_connections() > 0, 5.0)
    ros.command_pub.publish(msg)
    def leader_copies():
        return [c for c in wire.take(lambda c: c[0] == ch and c[3] > t_cmd) if struct.unpack(">H", c[2][4:6])[0] == 0]
    # 5 copies, 0.1 s apart on the leader's ROS timer; on a loaded machine later than 1 s (at load 10 the
    # attacker had 1 of 5 after a fixed 1 s), so up to 2 s more (the replay below must stay < 5 s old).
    time.sleep(1.0)
    wait_for(lambda: len(leader_copies()) >= 5, 2.0)
    recorded = leader_copies()
    check(len(ros.commands) - n0 == 1, "the leader's real command delivered once by R (%d), after follower 1 "
          "sent one with the same id" % (len(ros.commands) - n0))
    check(len(recorded) == 5, "the attacker recorded the leader's %d command copies (5 expected)" % len(recorded))
    stop(receiver)
    receiver = bridge("r_bridge", 2, [0, 1], "sender_2.key", ["formation_command_out:=/r/formation_command"])
    wait_for(lambda: "restored high-water marks" in open(os.path.join(T, "r_bridge.log")).read(), 20.0)
    up = ros.fresh_counts(R_LINK, time.time(), 10.0)
    n1 = len(ros.commands)
    stamps = [struct.unpack(">d", c[2][16:24])[0] for c in recorded]
    age = time.time() - max(stamps) if stamps else 99
    for c in recorded:
        wire.replay(c[1])
    sent_at = time.time()
    counts = ros.fresh_counts(from_sender(0), sent_at + 1.0) or {}
    check(up is not None and age < 5.0, "replayed %d copies %.1f s after they were sent (inside the 5 s command age: "
          "only the persisted high-water mark can refuse them)" % (len(recorded), age))
    check(len(ros.commands) == n1, "no replayed command delivered after R's restart")
    check(counts.get("replayed", 0) + counts.get("stale", 0) == len(recorded) and counts.get("too_old", 0) == 0,
          "R refused them as replayed/stale (%d/%d), none as too_old (%d)" %
          (counts.get("replayed", 0), counts.get("stale", 0), counts.get("too_old", 0)))
    return receiver


def main():
    ros = Ros()
    wire = Wire()
    receiver = bridge("r_bridge", 2, [0, 1], "sender_2.key", ["formation_command_out:=/r/formation_command"])
    leader = bridge("l_bridge", 0, [1, 2], "sender_0.key", ["formation_command_in:=/l/formation_command_in"])
    try:
        ok = wait_for(lambda: ros.counts(from_sender(0)).get("accepted", 0) > 2 and wire.fingerprint, 30.0)
        check(bool(ok), "R accepts the leader's per-sender signed heartbeats; fingerprint learnt from the wire")
        if not ok:
            return 1
        phase_impersonation(wire, ros)
        phase_classes(wire, ros)
        leader = phase_clock_back(wire, ros, leader)
        receiver = phase_replay_after_restart(wire, ros, receiver)
    finally:
        for p in (leader, receiver):
            stop(p)
    print("%d check(s) failed" % len(failures) if failures else "all checks passed", flush=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
