#!/usr/bin/env python3
"""Generates the sample flight logs in test/data/flights/ (deterministic for a seed).

A worker walks to a power tower, climbs 6 m and works there, then walks away; the leader
UAV holds the paper's Table II view (beta 90 deg, gamma 11 deg, d 10 m) with a lag and
position noise, its D435 colour camera (615 px focal length, 640x480) pointed at the worker.
Rows at 15 Hz: the worker's box (projected head-to-feet extent plus pixel noise; missed
detections in bursts), UWB range (sigma 0.1 m, dropouts, 25 m limit), stereo range
(sigma 0.3 m, valid up to 12 m). The `_nasty` variant adds outliers, repeated and
out-of-order rows, invalid boxes and quaternions, and lens distortion.

    make_sample_flight.py --seed 1 --out test/data/flights/sample_flight
writes <out>.csv (the gfctl estimate input) and <out>_truth.csv (t,x,y,z of the worker).
"""
import argparse
import math

import numpy as np

FX = FY = 615.0
CX, CY = 320.0, 240.0
W, H = 640, 480


def worker_position(t):
    """Piecewise path: walk 0-20 s, climb 20-32 s, work 32-50 s, descend 50-58 s, walk 58-75 s."""
    if t < 20:
        return np.array([-10 + 0.5 * t, 2.0 + 0.1 * t, 0.9])
    if t < 32:
        return np.array([0.0, 4.0, 0.9 + 0.5 * (t - 20)])
    if t < 50:
        return np.array([0.3 * math.sin(0.4 * (t - 32)), 4.0, 6.9])
    if t < 58:
        return np.array([0.0, 4.0, 6.9 - 0.75 * (t - 50)])
    return np.array([0.6 * (t - 58), 4.0 - 0.3 * (t - 58), 0.9])


def rot_from_optical(z_axis):
    """Optical frame (z forward, x right, y down) looking along z_axis, horizon level."""
    zc = z_axis / np.linalg.norm(z_axis)
    xc = np.cross(zc, [0, 0, 1.0])
    xc /= np.linalg.norm(xc)
    yc = np.cross(zc, xc)
    return np.column_stack([xc, yc, zc])


def quat_from_rot(R):
    tr = np.trace(R)
    if tr > 0:
        s = 2 * math.sqrt(tr + 1)
        return np.array([0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s])
    i = int(np.argmax(np.diag(R)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * math.sqrt(1 + R[i, i] - R[j, j] - R[k, k])
    q = np.zeros(4)
    q[0] = (R[k, j] - R[j, k]) / s
    q[1 + i] = 0.25 * s
    q[1 + j] = (R[j, i] + R[i, j]) / s
    q[1 + k] = (R[k, i] + R[i, k]) / s
    return q


def distort(x, y, D):
    k1, k2, p1, p2, k3 = D
    r2 = x * x + y * y
    rad = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 ** 3
    return (x * rad + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), y * rad + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y)


def project(p_cam, D):
    x, y = distort(p_cam[0] / p_cam[2], p_cam[1] / p_cam[2], D)
    return FX * x + CX, FY * y + CY


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", required=True)
    ap.add_argument("--nasty", action="store_true")
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    D = [0.08, -0.15, 0.0005, -0.0008, 0.04] if a.nasty else [0, 0, 0, 0, 0]
    dt = 1.0 / 15.0
    n = int(75 / dt)
    rows, truth = [], []
    miss_left = 0
    uwb_left = 0
    uav_lag = np.zeros(3)
    for i in range(n):
        t = round(i * dt, 6)
        p_h = worker_position(t)
        # Leader at beta = 90 deg, gamma = 11 deg, d = 10 m, worker heading 0, with a slow
        # wandering offset (tracking lag) and the camera pointed at the worker's chest.
        beta, gamma, d = math.radians(90), math.radians(11), 10.0
        uav_lag = 0.98 * uav_lag + rng.normal(0, 0.05, 3)
        p_uav = p_h - d * np.array([math.cos(-beta) * math.cos(gamma), math.sin(-beta) * math.cos(gamma),
                                    -math.sin(gamma)]) + uav_lag
        R = rot_from_optical(p_h + np.array([0, 0, 0.1]) - p_uav + rng.normal(0, 0.02, 3))
        q = quat_from_rot(R)
        truth.append((t, *p_h))
        # The worker's box: head (p + 0.875 m) and feet (p - 0.875 m), 0.5 m wide. In the
        # nasty flight the tracker locks onto a colleague 2.5 m away for 1.5 s at t = 40 s.
        p_box = p_h + (np.array([2.5, 0, 0]) if a.nasty and 40 <= t < 41.5 else 0)
        pts = []
        for dz in (-0.875, 0.875):
            for dy in (-0.25, 0.25):
                pc = R.T @ (p_box + np.array([0, 0, dz]) + dy * R[:, 0] - p_uav)
                pts.append(project(pc, D))
        us, vs = [p[0] for p in pts], [p[1] for p in pts]
        u0, v0 = min(us) + rng.normal(0, 1.5), min(vs) + rng.normal(0, 1.5)
        bw, bh = max(us) - min(us) + rng.normal(0, 1.5), max(vs) - min(vs) + rng.normal(0, 1.5)
        rng_true = float(np.linalg.norm(p_h - p_uav))
        if miss_left == 0 and rng.random() < 0.02:
            miss_left = int(rng.integers(3, 30))
        detected = miss_left == 0
        miss_left = max(0, miss_left - 1)
        if uwb_left == 0 and rng.random() < 0.01:
            uwb_left = int(rng.integers(15, 120))
        uwb_ok = uwb_left == 0 and rng_true < 25
        uwb_left = max(0, uwb_left - 1)
        d_uwb = rng_true + rng.normal(0, 0.1) if uwb_ok else None
        d_st = rng_true + rng.normal(0, 0.3) if rng_true < 12 and rng.random() < 0.8 else None
        if a.nasty and rng.random() < 0.03:  # outlier detections (another person, reflections)
            u0 += rng.normal(0, 150)
            d_uwb = None if d_uwb is None else d_uwb + rng.normal(0, 8)
        row = [t, *p_uav, *q]
        row += [u0, v0, bw, bh, d_uwb, d_st] if detected else [None] * 6
        rows.append(row)
        if a.nasty and rng.random() < 0.01:
            rows.append(list(row))  # duplicated row
        if a.nasty and rng.random() < 0.01 and len(rows) > 3:
            late = list(rows[-3])  # an old detection delivered late
            rows.append(late)
        if a.nasty and rng.random() < 0.01:
            bad = list(row)
            choice = rng.integers(0, 4)
            if choice == 0:
                bad[10] = -5.0  # negative width
            elif choice == 1:
                bad[4] = 1.3  # non-unit quaternion
            elif choice == 2:
                bad[8] = 2000.0  # box outside the image
            else:
                bad[1] = float("nan")  # NaN camera position
            if bad[8] is not None:
                rows.append(bad)

    def fmt(v):
        if v is None:
            return ""
        return "%.9g" % v

    with open(a.out + ".csv", "w") as f:
        f.write("t,cam_x,cam_y,cam_z,cam_qw,cam_qx,cam_qy,cam_qz,u,v,w,h,d_uwb,d_stereo\n")
        for r in rows:
            f.write(",".join(fmt(c) for c in r) + "\n")
    with open(a.out + "_truth.csv", "w") as f:
        f.write("t,x,y,z\n")
        for r in truth:
            f.write(",".join("%.9g" % c for c in r) + "\n")
    if a.nasty:
        with open(a.out + "_camera.yaml", "w") as f:
            f.write("# The lens of the nasty sample flight (plumb_bob k1 k2 p1 p2 k3).\n")
            f.write("camera: {fx: 615.0, fy: 615.0, cx: 320.0, cy: 240.0, distortion: [%s]}\n" % ", ".join(str(x) for x in D))


if __name__ == "__main__":
    main()
