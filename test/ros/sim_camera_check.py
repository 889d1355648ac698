#!/usr/bin/env python3
"""Checks simulation.launch camera:=rendered while it runs (test/ros/sim_camera.sh):
- every UAV's camera publishes colour (rgb8), aligned depth (32FC1) and CameraInfo of the same
  size, stamped alike, in its optical frame, at about its camera rate in sim time;
- the depth is the rendered world's: at the pixel where the worker's true mid-body projects
  (its truth /world/worker_truth, the camera's true pose /uav<i>/ground_truth: camera axis =
  odometry orientation, docs/ros.md) the depth is finite and within WORKER_DEPTH_TOL_M of the
  mid-body's depth along the optical axis, in most of the leader's frames;
- the leader's Perception nodelet finds the worker (WorkerDetection.detected) with a finite stereo
  range from the rendered depth, and only the UAV managers (the Perception nodelets) publish
  detections and classifications: SimWorld (/world/manager) none;
- the leader's WorkerEstimator, fed by that Perception alone (and the UWB range), tracks the
  worker: its last estimates are not lost and within ESTIMATE_TOL_M of the truth.
Usage: sim_camera_check.py DURATION_WALL_S CAMERA_RATE_HZ; exit code = number of failures."""
import math
import sys
import time

import numpy as np
import rospy
import rosgraph
from gesture_formation.msg import WorkerDetection, WorkerState
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image

WORKER_DEPTH_TOL_M = 0.6   # the mid-body lies inside the body: the surface is 0.1-0.3 m nearer
ESTIMATE_TOL_M = 1.5       # tracking, not a precision figure: the estimate is on the worker, not elsewhere
N_UAVS = 3

fails = 0


def check(ok, what):
    global fails
    print(("PASS: " if ok else "FAIL: ") + what)
    if not ok:
        fails += 1


def quat_to_R(q):
    w, x, y, z = q.w, q.x, q.y, q.z
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


# optical frame (z forward, x right, y down) in the camera-axis frame (FLU: x forward)
R_AXIS_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def nearest(history, t):
    return min(history, key=lambda m: abs(m.header.stamp.to_sec() - t)) if history else None


def main():
    wall_s, rate_hz = float(sys.argv[1]), float(sys.argv[2])
    rospy.init_node("sim_camera_check", anonymous=True)
    images = {i: [] for i in range(N_UAVS)}
    depths = {i: [] for i in range(N_UAVS)}
    infos = {i: [] for i in range(N_UAVS)}
    truths = {i: [] for i in range(N_UAVS)}
    worker, detections, estimates = [], [], []
    subs = []
    for i in range(N_UAVS):
        ns = "/uav%d/" % i
        subs.append(rospy.Subscriber(ns + "camera/color/image_raw", Image, images[i].append, queue_size=20))
        subs.append(rospy.Subscriber(ns + "camera/aligned_depth_to_color/image_raw", Image, depths[i].append, queue_size=20))
        subs.append(rospy.Subscriber(ns + "camera/color/camera_info", CameraInfo, infos[i].append, queue_size=20))
        subs.append(rospy.Subscriber(ns + "ground_truth", Odometry, truths[i].append, queue_size=100))
    subs.append(rospy.Subscriber("/world/worker_truth", Odometry, worker.append, queue_size=100))
    subs.append(rospy.Subscriber("/uav0/perception/worker_detection", WorkerDetection, detections.append, queue_size=50))
    subs.append(rospy.Subscriber("/uav0/worker_state", WorkerState, estimates.append, queue_size=50))
    t0 = time.time()
    while time.time() - t0 < wall_s and not rospy.is_shutdown():
        time.sleep(0.2)
        for h in list(truths.values()) + [worker, estimates]:
            del h[:-400]  # keep the last seconds
    sim_end = rospy.get_time()
    for s in subs:
        s.unregister()

    # SimWorld publishes no detection and no classification in this mode.
    pubs, _, _ = rosgraph.Master("/sim_camera_check").getSystemState()
    publishers = {topic: nodes for topic, nodes in pubs}
    sim_outputs = [t for t, nodes in publishers.items()
                   if "/world/manager" in nodes and ("worker_detection" in t or t.endswith("perception/gesture"))]
    check(not sim_outputs, "SimWorld publishes no detection / classification (got %s)" % sim_outputs)
    check("/uav0/manager" in publishers.get("/uav0/perception/worker_detection", []),
          "the leader's manager (its Perception nodelet) publishes /uav0/perception/worker_detection")

    for i in range(N_UAVS):
        imgs, deps, infs = images[i], depths[i], infos[i]
        check(len(imgs) >= 5 and len(deps) >= 5 and len(infs) >= 5,
              "uav%d: %d colour, %d depth, %d camera info messages" % (i, len(imgs), len(deps), len(infs)))
        if not imgs or not deps or not infs:
            continue
        im, dp, inf = imgs[-1], deps[-1], infs[-1]
        check(im.encoding == "rgb8" and dp.encoding == "32FC1" and im.width == dp.width == inf.width and
              im.height == dp.height == inf.height and len(im.data) == im.step * im.height and
              len(dp.data) == dp.step * dp.height,
              "uav%d: rgb8 %dx%d + 32FC1 %dx%d + CameraInfo %dx%d" % (i, im.width, im.height, dp.width, dp.height,
                                                                      inf.width, inf.height))
        check(im.header.frame_id == dp.header.frame_id == inf.header.frame_id == "uav%d/camera_optical" % i,
              "uav%d: frame %s" % (i, im.header.frame_id))
        stamps = [m.header.stamp.to_sec() for m in imgs]
        span = stamps[-1] - stamps[0]
        gaps = np.diff(stamps)
        # on the camera rate's grid in sim time: never more frames than the rate allows (a frame that
        # came late, after a slow one, is followed by the next grid point), most of them delivered
        # (SimWorld's frames lie on its 0.01 s clock steps)
        on_grid = np.mean(np.abs(gaps - np.round(gaps * rate_hz) / rate_hz) < 0.0101) if len(gaps) else 0.0
        check(len(stamps) > 1 and np.all(gaps > 0) and len(stamps) - 1 <= span * rate_hz + 0.5 and
              len(stamps) - 1 >= 0.6 * span * rate_hz and on_grid >= 0.8,
              "uav%d: %d frames over %.1f s sim (%.2f Hz, camera rate %.1f Hz), %.0f %% of the gaps whole periods" %
              (i, len(stamps), span, (len(stamps) - 1) / span if span > 0 else 0, rate_hz, 100 * on_grid))
        pixels = np.frombuffer(im.data, np.uint8)
        check(pixels.std() > 10, "uav%d: the colour image is not blank (std %.1f)" % (i, pixels.std()))

    # Depth where the worker is (the leader's frames).
    K = None
    checked, good = 0, 0
    dstamps = {d.header.stamp.to_sec(): d for d in depths[0]}
    for inf in infos[0]:
        K = np.array(inf.K).reshape(3, 3)
        t = inf.header.stamp.to_sec()
        d, cam, w = dstamps.get(t), nearest(truths[0], t), nearest(worker, t)
        if d is None or cam is None or w is None or abs(cam.header.stamp.to_sec() - t) > 0.03 or \
                abs(w.header.stamp.to_sec() - t) > 0.06:
            continue
        p = cam.pose.pose.position
        q = w.pose.pose.position
        R_world_optical = quat_to_R(cam.pose.pose.orientation) @ R_AXIS_OPTICAL
        x = R_world_optical.T @ (np.array([q.x, q.y, q.z]) - np.array([p.x, p.y, p.z]))
        if x[2] <= 0.5:
            continue
        u, v = K[0, 0] * x[0] / x[2] + K[0, 2], K[1, 1] * x[1] / x[2] + K[1, 2]
        if not (2 <= u < d.width - 2 and 2 <= v < d.height - 2):
            continue
        depth = np.frombuffer(d.data, np.float32).reshape(d.height, d.step // 4)[:, :d.width]
        window = depth[int(round(v)) - 2:int(round(v)) + 3, int(round(u)) - 2:int(round(u)) + 3]
        z = float(np.nanmedian(window)) if np.isfinite(window).any() else float("nan")
        checked += 1
        good += int(math.isfinite(z) and abs(z - x[2]) < WORKER_DEPTH_TOL_M)
    check(checked >= 5 and good >= 0.8 * checked,
          "leader: depth at the worker's projected mid-body finite and within %.1f m of its optical depth in %d of %d frames"
          % (WORKER_DEPTH_TOL_M, good, checked))

    found = [d for d in detections if d.detected]
    ranged = [d for d in found if math.isfinite(d.stereo_distance_m)]
    check(len(detections) >= 5 and len(found) >= 0.7 * len(detections),
          "leader Perception: %d of %d WorkerDetections find the worker" % (len(found), len(detections)))
    check(len(ranged) >= 0.7 * max(1, len(found)) and all(2.0 < d.stereo_distance_m < 20.0 for d in ranged),
          "leader Perception: %d stereo ranges from the rendered depth, in (2, 20) m: %s" %
          (len(ranged), ["%.1f" % d.stereo_distance_m for d in ranged[:6]]))
    errors = []
    for e in estimates[-40:]:
        w = nearest(worker, e.header.stamp.to_sec())
        if w is not None and abs(w.header.stamp.to_sec() - e.header.stamp.to_sec()) < 0.06:
            a, b = e.position, w.pose.pose.position
            errors.append(math.sqrt((a.x - b.x) ** 2 + (a.y - b.y) ** 2 + (a.z - b.z) ** 2))
    tracked = [e for e in estimates[-40:] if not e.lost]
    check(len(errors) >= 10 and len(tracked) == len(estimates[-40:]) and max(errors) < ESTIMATE_TOL_M,
          "leader WorkerEstimator on the rendered camera: %d of the last %d estimates tracked, error vs truth max %s m"
          % (len(tracked), len(estimates[-40:]), "%.2f" % max(errors) if errors else "-"))
    print("sim time reached: %.1f s" % sim_end)
    return fails


if __name__ == "__main__":
    sys.exit(main())
