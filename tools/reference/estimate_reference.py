#!/usr/bin/env python3
"""Independent reference implementation of `gfctl estimate` (docs/design.md §3 and §8.1), written
straight from the paper's equations with numpy, to check the C++ core against.

    estimate_reference.py --config estimator.yaml --in meas.csv --out states.csv

Conventions (docs/conventions.md): quaternion order w,x,y,z (camera optical frame -> world),
plumb_bob distortion inverted by fixed-point iteration (as cv::undistortPoints, run to
convergence), Q added once per CSV row, Joseph-free textbook update P = (I - K H) P.
Semantics beyond the paper, shared with the C++ implementation: Mahalanobis gate
d^2 <= gate_chi2; at most max_consecutive_rejections gated measurements in a row, the next
one re-initialises; a detection older than the filter's time is dropped; invalid rows
(non-finite values, non-positive box size, box centre outside the image, |q| off by more
than 1e-3) are not fused but the row still predicts.
"""
import argparse
import csv
import math
import sys

import numpy as np
import yaml

DEFAULTS = {
    "camera": {"fx": 615.0, "fy": 615.0, "cx": 320.0, "cy": 240.0, "distortion": [0, 0, 0, 0, 0]},
    "human_height_m": 1.75,
    "max_apparent_distance_m": 40.0,
    "process_noise": {"sigma_p_m": 0.1, "sigma_v_mps": 0.1},
    "measurement_noise": {"sigma_xy_m": 0.05, "sigma_z_uwb_m": 0.1, "sigma_z_stereo_m": 0.3,
                          "sigma_z_apparent_m": 0.6},
    "initial_velocity_std_mps": 1.0,
    "gate_chi2": 16.27,
    "max_consecutive_rejections": 10,
    "lost_timeout_s": 5.0,
}


def merged(cfg, key):
    d = DEFAULTS[key]
    if isinstance(d, dict):
        out = dict(d)
        out.update(cfg.get(key, {}) or {})
        return out
    return cfg.get(key, d)


def quat_to_rot(w, x, y, z):
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


class Camera:
    def __init__(self, c):
        self.fx, self.fy, self.cx, self.cy = c["fx"], c["fy"], c["cx"], c["cy"]
        self.k1, self.k2, self.p1, self.p2, self.k3 = c["distortion"]
        self.width = c.get("width", round(2 * self.cx))
        self.height = c.get("height", round(2 * self.cy))

    def ray(self, u, v):
        xd = (u - self.cx) / self.fx
        yd = (v - self.cy) / self.fy
        x, y = xd, yd
        for _ in range(1000):  # fixed point: x = (xd - tangential) / radial
            r2 = x * x + y * y
            radial = 1 + self.k1 * r2 + self.k2 * r2 * r2 + self.k3 * r2 * r2 * r2
            dx = 2 * self.p1 * x * y + self.p2 * (r2 + 2 * x * x)
            dy = self.p1 * (r2 + 2 * y * y) + 2 * self.p2 * x * y
            xn, yn = (xd - dx) / radial, (yd - dy) / radial
            if abs(xn - x) < 1e-15 and abs(yn - y) < 1e-15:
                x, y = xn, yn
                break
            x, y = xn, yn
        r = np.array([x, y, 1.0])
        return r / np.linalg.norm(r)


def fnum(s):
    if s is None or s.strip() == "":
        return None
    return float(s)


def fmt(v):
    if isinstance(v, str):
        return v
    if math.isnan(v):
        return "nan"
    return "%.15g" % v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--config", required=True)
    ap.add_argument("--in", dest="inp", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    with open(a.config) as f:
        cfg = yaml.safe_load(f) or {}
    cam = Camera(merged(cfg, "camera"))
    H_m = merged(cfg, "human_height_m")
    max_apparent_m = merged(cfg, "max_apparent_distance_m")
    pn = merged(cfg, "process_noise")
    mn = merged(cfg, "measurement_noise")
    sv0 = merged(cfg, "initial_velocity_std_mps")
    gate = merged(cfg, "gate_chi2")
    max_rej = merged(cfg, "max_consecutive_rejections")
    Q = np.diag([pn["sigma_p_m"] ** 2] * 3 + [pn["sigma_v_mps"] ** 2] * 3)
    Hm = np.hstack([np.eye(3), np.zeros((3, 3))])

    x = None
    P = None
    t_state = None
    t_fused = None
    lost_timeout = merged(cfg, "lost_timeout_s")
    rejections = 0
    rows_out = []
    with open(a.inp) as f:
        for row in csv.DictReader(f):
            t = float(row["t"])
            source, accepted = "none", 0
            meas = None
            if row["u"].strip() != "":
                u, v, w, h = (float(row[k]) for k in ("u", "v", "w", "h"))
                pose = [float(row[k]) for k in ("cam_x", "cam_y", "cam_z", "cam_qw", "cam_qx", "cam_qy", "cam_qz")]
                d_uwb, d_st = fnum(row["d_uwb"]), fnum(row["d_stereo"])
                qn = math.sqrt(sum(q * q for q in pose[3:]))
                cu, cv = u + w / 2, v + h / 2
                ok = all(math.isfinite(q) for q in [t, u, v, w, h] + pose) and w > 0 and h > 0 \
                    and abs(qn - 1) <= 1e-3 and 0 <= cu <= cam.width and 0 <= cv <= cam.height
                if ok:
                    R = quat_to_rot(*pose[3:])
                    dhat = cam.ray(cu, cv)
                    if d_uwb is not None and math.isfinite(d_uwb) and d_uwb > 0:
                        d, sz, source = d_uwb, mn["sigma_z_uwb_m"], "uwb"
                    elif d_st is not None and math.isfinite(d_st) and d_st > 0:
                        d, sz, source = d_st, mn["sigma_z_stereo_m"], "stereo"
                    elif v <= 0.5 or v + h >= cam.height - 0.5:
                        d = None  # clipped at the top or bottom edge: its height gives no distance
                    else:
                        rt, rb = cam.ray(cu, v), cam.ray(cu, v + h)
                        alpha = math.atan2(np.linalg.norm(np.cross(rt, rb)), float(rt @ rb))
                        d, sz, source = H_m / (2 * math.tan(alpha / 2)), mn["sigma_z_apparent_m"], "apparent"
                        if not d <= max_apparent_m:
                            d, source = None, "none"
                    if d is not None:
                        z = R @ (d * dhat) + np.array(pose[:3])
                        S_m = R @ np.diag([mn["sigma_xy_m"] ** 2, mn["sigma_xy_m"] ** 2, sz ** 2]) @ R.T
                        meas = (z, S_m)
            if x is None:
                if meas is not None and math.isfinite(t):
                    x = np.concatenate([meas[0], np.zeros(3)])
                    P = np.zeros((6, 6))
                    P[:3, :3] = meas[1]
                    P[3:, 3:] = np.eye(3) * sv0 ** 2
                    t_state, t_fused, accepted, rejections = t, t, 1, 0
                else:
                    source = "none"
            elif math.isfinite(t) and t >= t_state:
                # constant velocity until lost_timeout_s after the last fused measurement; beyond
                # it the position is held, the velocity forgotten, P_pp grows by σ_v0²·1 s per s
                t_model_end = t_fused + lost_timeout
                dt = max(0.0, min(t, t_model_end) - t_state)
                dt_held = max(0.0, t - max(t_state, t_model_end))
                F = np.eye(6)
                F[:3, 3:] = dt * np.eye(3)
                x = F @ x
                P = F @ P @ F.T
                if t > t_model_end:
                    x[3:] = 0.0
                    P[:3, 3:] = 0.0
                    P[3:, :3] = 0.0
                    P[3:, 3:] = np.eye(3) * sv0 ** 2
                    P[:3, :3] += np.eye(3) * sv0 ** 2 * dt_held
                P = P + Q
                t_state = t
                if meas is not None:
                    z, S_m = meas
                    y = z - x[:3]
                    S = P[:3, :3] + S_m
                    d2 = float(y @ np.linalg.solve(S, y))
                    if d2 <= gate:
                        K = P @ Hm.T @ np.linalg.inv(S)
                        x = x + K @ y
                        P = (np.eye(6) - K @ Hm) @ P
                        accepted, rejections, t_fused = 1, 0, t
                    elif rejections >= max_rej:
                        x = np.concatenate([z, np.zeros(3)])
                        P = np.zeros((6, 6))
                        P[:3, :3] = S_m
                        P[3:, 3:] = np.eye(3) * sv0 ** 2
                        accepted, rejections, t_fused = 1, 0, t
                    else:
                        rejections += 1
            # else: time went backwards: nothing changes (a detection is dropped)
            if x is None:
                rows_out.append([t] + [math.nan] * 6 + ["none", 0] + [math.nan] * 6)
            else:
                rows_out.append([t] + list(x) + [source, accepted] + list(np.diag(P)))
    with open(a.out, "w") as f:
        f.write("t,x,y,z,vx,vy,vz,source,accepted,pxx,pyy,pzz,pvxx,pvyy,pvzz\n")
        for r in rows_out:
            f.write(",".join(fmt(c) if not isinstance(c, int) else str(c) for c in r) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
