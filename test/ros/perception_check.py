#!/usr/bin/env python3
"""A tiny camera for the Perception nodelet (test/ros/perception_image.sh): publishes a PNG
(decoded here with zlib + numpy: no OpenCV in Debian's python) as a bgr8 sensor_msgs/Image at
10 Hz, an aligned 32FC1 depth image (constant DEPTH_M) and a CameraInfo, and checks what comes
out: a WorkerDetection with the worker found, its box inside the image and a stereo range along
the box-centre ray (>= DEPTH_M, within the ray's stretch), then a Gesture once the skeleton FIFO
is full (the still astronaut: none, as GestureEndToEndTest.CommittedStillImageSkeletonClassifiesAsNone).
With --compressed the colour image goes out as the PNG file's bytes in a sensor_msgs/CompressedImage
(format "png") on /cam/image/compressed, image_transport's `compressed` topic, and no raw image.
Usage: perception_check.py IMAGE.png [--compressed]; exit code = number of failures."""
import math
import os
import struct
import subprocess
import sys
import time
import zlib

import numpy as np
import rospy
from diagnostic_msgs.msg import DiagnosticArray
from gesture_formation.msg import Gesture, WorkerCandidates, WorkerDetection
from gesture_formation.srv import SelectWorker
from sensor_msgs.msg import CameraInfo, CompressedImage, Image

DEPTH_M = 4.0
F_PX = 500.0


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, w = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and ctype in (2, 6) and interlace == 0, "only 8-bit RGB(A), not interlaced"
            bpp = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * bpp
    out = np.zeros((h, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, dtype=np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 255
        else:  # Sub, Average, Paeth depend on the reconstructed left neighbour
            for x in range(stride):
                a = cur[x - bpp] if x >= bpp else 0
                b = prev[x]
                c = prev[x - bpp] if x >= bpp else 0
                if f == 1:
                    p = a
                elif f == 3:
                    p = (a + b) // 2
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + p) & 255
        out[y] = cur
        prev = cur
    rgb = out.reshape(h, w, bpp)[:, :, :3]
    return np.ascontiguousarray(rgb[:, :, ::-1])  # BGR


def check_worker_choice(candidates, send):
    """The candidates of each detection round, and ~select_worker: a point on nobody and a stale
    candidate index are refused; a point on the person chooses it (locked in later rounds); unlock."""
    fails = 0
    ok = bool(candidates) and len(candidates[-1].u) >= 1 and candidates[-1].worker == 0 and candidates[-1].worker_id >= 0 \
        and not candidates[-1].locked
    print("%s: WorkerCandidates each detection round: %d rounds, last with %d candidate(s), worker %s, locked %s" % (
        "PASS" if ok else "FAIL", len(candidates), len(candidates[-1].u) if candidates else 0,
        candidates[-1].worker if candidates else None, candidates[-1].locked if candidates else None))
    fails += 0 if ok else 1
    if not candidates:
        return fails + 1
    rospy.wait_for_service("/perception/select_worker", timeout=10)
    select = rospy.ServiceProxy("/perception/select_worker", SelectWorker)
    last = candidates[-1]
    nobody = select(u=1.0, v=1.0, candidate=-1, candidates_seq=0, unlock=False)
    stale = select(u=0.0, v=0.0, candidate=0, candidates_seq=last.header.seq + 1000, unlock=False)
    cu, cv = last.u[0] + last.w[0] / 2, last.v[0] + last.h[0] / 2
    chosen = select(u=cu, v=cv, candidate=-1, candidates_seq=0, unlock=False)
    ok = not nobody.accepted and "no person" in nobody.message and not stale.accepted and "candidates_seq" in stale.message \
        and chosen.accepted and abs(chosen.u - last.u[0]) < 1e-3 and abs(chosen.w - last.w[0]) < 1e-3
    print("%s: select_worker: point on nobody refused (%s); stale candidate refused (%s); point on the person chosen (%s)" % (
        "PASS" if ok else "FAIL", nobody.message, stale.message, chosen.message))
    fails += 0 if ok else 1
    n = len(candidates)
    t0 = time.time()
    while time.time() - t0 < 20 and not any(c.locked and c.worker >= 0 for c in candidates[n:]):
        send()
        time.sleep(0.1)
    later = [c for c in candidates[n:] if c.locked and c.worker >= 0]
    # The ground station's tool lists the candidates of the next round (frames keep coming meanwhile).
    tool = subprocess.Popen([sys.executable, os.path.join(os.path.dirname(__file__), "..", "..", "tools", "gf_worker.py"),
                             "list", "--ns", "/perception", "--timeout", "15"], stdout=subprocess.PIPE, text=True)
    while tool.poll() is None:
        send()
        time.sleep(0.1)
    listed = tool.stdout.read()
    ok = tool.returncode == 0 and "1 person(s)" in listed and "locked by the operator" in listed and "<- worker" in listed
    print("%s: tools/gf_worker.py list: exit %d: %s" % ("PASS" if ok else "FAIL", tool.returncode, listed.strip()))
    fails += 0 if ok else 1
    unlock = select(u=0.0, v=0.0, candidate=-1, candidates_seq=0, unlock=True)
    ok = bool(later) and later[0].worker_id != last.worker_id and unlock.accepted
    fails += 0 if ok else 1
    print("%s: after the choice the tracker is locked to the chosen person with a new id (%s -> %s); unlock accepted" % (
        "PASS" if ok else "FAIL", last.worker_id, later[0].worker_id if later else None))
    return fails


def main():
    bgr = read_png(sys.argv[1])
    compressed = "--compressed" in sys.argv[2:]
    png_bytes = open(sys.argv[1], "rb").read()
    h, w = bgr.shape[:2]
    rospy.init_node("perception_check")
    img_pub = rospy.Publisher("/cam/image/compressed", CompressedImage, queue_size=2) if compressed \
        else rospy.Publisher("/cam/image", Image, queue_size=2)
    depth_pub = rospy.Publisher("/cam/depth", Image, queue_size=2)
    info_pub = rospy.Publisher("/cam/camera_info", CameraInfo, queue_size=2, latch=True)
    detections, gestures = [], []
    rospy.Subscriber("/perception/worker_detection", WorkerDetection, detections.append)
    rospy.Subscriber("/perception/gesture", Gesture, gestures.append)
    candidates = []
    rospy.Subscriber("/perception/candidates", WorkerCandidates, candidates.append)
    health = []
    rospy.Subscriber("/diagnostics", DiagnosticArray, lambda a: health.extend(x for x in a.status if x.name == "Perception"))
    info = CameraInfo(width=w, height=h, distortion_model="plumb_bob", D=[0.0] * 5,
                      K=[F_PX, 0, w / 2.0, 0, F_PX, h / 2.0, 0, 0, 1])
    info.header.frame_id = "cam_optical"
    info_pub.publish(info)
    depth = np.full((h, w), DEPTH_M, dtype=np.float32)
    wall0 = time.time()
    def send(depth_frame="cam_optical"):  # one depth image and its colour image
        stamp = rospy.Time.now()
        m = CompressedImage(format="png", data=png_bytes) if compressed \
            else Image(height=h, width=w, encoding="bgr8", step=3 * w, data=bgr.tobytes())
        m.header.stamp, m.header.frame_id = stamp, "cam_optical"
        d = Image(height=h, width=w, encoding="32FC1", step=4 * w, data=depth.tobytes())
        d.header.stamp, d.header.frame_id = stamp, depth_frame
        depth_pub.publish(d)
        time.sleep(0.03)  # depth first (a RealSense driver publishes both at once; order is not guaranteed)
        img_pub.publish(m)

    while time.time() - wall0 < 50 and not rospy.is_shutdown():
        send()
        if gestures and len(detections) >= 10:
            break
        time.sleep(0.1)
    fails = 0
    found = [x for x in detections if x.detected]
    ok = len(detections) >= 10 and len(found) >= 9
    print("%s: %d WorkerDetection messages from %s images, %d with the worker found (expected >= 10, >= 9)" % (
        "PASS" if ok else "FAIL", len(detections), "compressed (png)" if compressed else "raw bgr8", len(found)))
    fails += 0 if ok else 1
    if found:
        x = found[-1]
        inside = x.w > 0.2 * w and x.h > 0.2 * h and x.u >= -1 and x.v >= -1 and x.u + x.w <= w + 1 and x.v + x.h <= h + 1 \
            and 0.0 < x.confidence <= 1.0
        cu, cv = x.u + x.w / 2 - w / 2.0, x.v + x.h / 2 - h / 2.0
        expected = DEPTH_M * math.sqrt(1 + (cu / F_PX) ** 2 + (cv / F_PX) ** 2)  # depth → range along the ray
        print("%s: box u %.0f v %.0f w %.0f h %.0f px in the %dx%d image, confidence %.2f (expected in (0, 1])" % (
            "PASS" if inside else "FAIL", x.u, x.v, x.w, x.h, w, h, x.confidence))
        fails += 0 if inside else 1
        # Depth and colour are two topics: ROS 1 does not order their delivery, so a frame whose
        # colour image is handled before its depth image has no range (the nodelet uses a depth
        # image only within max_depth_dt_s of the colour stamp). Every range given must be the
        # depth along the box-centre ray, and most frames must have one.
        ranged = [y for y in found if math.isfinite(y.stereo_distance_m)]
        wrong = []
        for y in ranged:
            cu, cv = y.u + y.w / 2 - w / 2.0, y.v + y.h / 2 - h / 2.0
            exp_y = DEPTH_M * math.sqrt(1 + (cu / F_PX) ** 2 + (cv / F_PX) ** 2)
            if abs(y.stereo_distance_m - exp_y) >= 1e-3:
                wrong.append((y.stereo_distance_m, exp_y))
        ok = len(ranged) * 2 >= len(found) and not wrong
        print("%s: stereo range on %d of %d detections, e.g. %.4f m (depth %.1f m along the box-centre ray: %.4f m); "
              "wrong: %s" % ("PASS" if ok else "FAIL", len(ranged), len(found),
                             ranged[-1].stereo_distance_m if ranged else float("nan"), DEPTH_M, expected, wrong[:3]))
        fails += 0 if ok else 1
    ok = len(gestures) >= 1 and gestures[0].gesture_id == 0 and len(gestures[0].probabilities) == 5
    print("%s: Gesture after a full skeleton window: %s (expected id 0, none: a still worker)" % (
        "PASS" if ok else "FAIL", "id %d, p(none) %.3f" % (gestures[0].gesture_id, gestures[0].probabilities[0])
        if gestures else "none published"))
    fails += 0 if ok else 1
    if not compressed:
        fails += check_worker_choice(candidates, send)
    time.sleep(1.2)  # one more /diagnostics report (1 s of wall time)
    values = [{kv.key: kv.value for kv in x.values} for x in health]
    busy = [v for v in values if float(v.get("images_per_s", 0)) > 0 and float(v.get("found_per_s", 0)) > 0]
    want = "compressed (decoded here)" if compressed else "raw"
    ok = bool(busy) and all(v.get("image_transport") == want for v in values)
    print("%s: /diagnostics Perception: %d reports, %d with images and finds per second, transport %s (%s expected)" % (
        "PASS" if ok else "FAIL", len(values), len(busy), sorted({v.get("image_transport") for v in values}), want))
    fails += 0 if ok else 1
    if not compressed:  # a depth image in another frame (not aligned to the colour image): no range, counted
        mark = len(detections)
        for _ in range(12):
            send("other_depth_frame")
            time.sleep(0.1)
        time.sleep(1.2)
        late = [y for y in detections[mark:] if y.detected]
        refused = [float({kv.key: kv.value for kv in x.values}.get("depth_refused", 0)) for x in health]
        ok = len(late) >= 5 and not any(math.isfinite(y.stereo_distance_m) for y in late) and max(refused) > 0
        print("%s: depth in another frame than the colour image: %d detections, %d with a range (0 expected), "
              "depth_refused %s on /diagnostics" % ("PASS" if ok else "FAIL", len(late),
                                                     sum(math.isfinite(y.stereo_distance_m) for y in late), max(refused)))
        fails += 0 if ok else 1
    return fails


if __name__ == "__main__":
    sys.exit(main())
