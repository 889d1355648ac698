#!/usr/bin/env python3
"""Pass rates of candidate 3-D gesture rules on the rendered TUNING set (docs/gestures.md §6, §9):
the three views' network keypoints triangulated per frame, each frame read on the per-keypoint median
of the 5 frames around it (as view_fusion's require_3d does), measured in the body frame as
gesture_geometry.hpp does, and every candidate rule's share of frames per motion (gesture frames:
the labelled ones; work motions: every frame of the motion, start to end).

    python3 tools/gesture/geometry_rules.py --data /work/lstm_data [--out FILE.json] [--features]

Refuses the held-out set: rules and thresholds are chosen on tuning data only (§8).
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rendered_eval as re_  # noqa: E402

LS, RS, LE, RE, LW, RW, LH, RH = 5, 6, 7, 8, 9, 10, 11, 12
MEDIAN = 5


def tri_frames(d, spec):
    """{sequence: [(t, {k: xyz})]} triangulated from the network keypoints of every view (>= 2 views per keypoint)."""
    views = [re_.view_frames(d, sfx) for sfx in re_.VIEW_SUFFIXES(spec)]
    out = {}
    for key in sorted(views[0][0], key=lambda k: (k[0], float(k[1]))):
        seq, t = key
        obs = {}
        for frames, meta in views:
            if key not in frames or seq not in meta:
                continue
            _, sk = frames[key]
            if sk is None:
                continue
            R, p, K = re_.camera_of(meta[seq])
            for k in range(17):
                c = float(sk[f"c{k}"])
                if c >= re_.MIN_CONF:
                    obs.setdefault(k, []).append((R, p, K, float(sk[f"x{k}"]), float(sk[f"y{k}"]), c))
        P = {k: re_.triangulate(v) for k, v in obs.items() if len(v) >= 2}
        if len(P) >= 4:
            out.setdefault(seq, []).append((float(t), P))
    return out


def median_of(frames, i):
    lo, hi = max(0, i - MEDIAN // 2), min(len(frames) - 1, i + MEDIAN // 2)
    out = {}
    for k in range(17):
        pts = [frames[j][1][k] for j in range(lo, hi + 1) if k in frames[j][1]]
        if pts:
            out[k] = np.median(np.array(pts), axis=0)
    return out


def features(P):
    """Body-frame measures (H units, degrees), or None without shoulders and hips."""
    if any(k not in P for k in (LS, RS, LH, RH)):
        return None
    sm, hm = 0.5 * (P[LS] + P[RS]), 0.5 * (P[LH] + P[RH])
    y = P[LS] - P[RS]
    y = y / np.linalg.norm(y)
    z = sm - hm
    z = z - (z @ y) * y
    z = z / np.linalg.norm(z)
    x = np.cross(y, z)
    torso = (sm - hm) @ z
    if torso < 0.1:
        return None
    H = torso / 0.30
    body = lambda p: np.array([(p - sm) @ x, (p - sm) @ y, (p - sm) @ z]) / H  # noqa: E731
    f = {}
    for side, (sh, el, wr) in (("l", (LS, LE, LW)), ("r", (RS, RE, RW))):
        if el in P and wr in P:
            up, fore, whole = body(P[el]) - body(P[sh]), body(P[wr]) - body(P[el]), body(P[wr]) - body(P[sh])
            ang = lambda a, b: np.degrees(np.arccos(np.clip(a @ b / (np.linalg.norm(a) * np.linalg.norm(b)), -1, 1)))  # noqa: E731
            outward = up[1] * (1.0 if side == "l" else -1.0)
            f[side] = {"elev": ang(up, np.array([0, 0, -1.0])), "whole": ang(whole, np.array([0, 0, -1.0])),
                       "abd": float(np.degrees(np.arctan2(outward, abs(up[0])))),
                       "wabd": float(np.degrees(np.arctan2(whole[1] * (1.0 if side == "l" else -1.0), abs(whole[0])))),
                       "elbow": ang(-up, fore), "fore_h": abs(np.degrees(np.arcsin(np.clip(fore[2] / np.linalg.norm(fore), -1, 1)))),
                       "w": body(P[wr]), "e": body(P[el])}
    if "l" in f and "r" in f:
        wl, wr_ = f["l"]["w"], f["r"]["w"]
        f["gap"] = float(np.linalg.norm(wl - wr_))
        f["wh"] = 0.82 + 0.5 * (wl[2] + wr_[2])  # mean wrist height / H (shoulders at 0.82 H)
        f["wh_min"] = 0.82 + min(wl[2], wr_[2])
        f["wh_max"] = 0.82 + max(wl[2], wr_[2])
        f["off"] = max(abs(wl[1]), abs(wr_[1]))  # the wrists' largest offset from the midline
        f["fwd"] = min(wl[0], wr_[0])
        f["elb_out"] = min(abs(f["l"]["e"][1]) - abs(wl[1]), abs(f["r"]["e"][1]) - abs(wr_[1]))  # elbows lateral of the wrists
        f["elb_h"] = 0.82 + 0.5 * (f["l"]["e"][2] + f["r"]["e"][2])
        f["fore_max"] = max(f["l"]["fore_h"], f["r"]["fore_h"])
    return f


def rules(f):
    """Candidate rules -> bool per frame (None when not measurable)."""
    out = {}
    both = "gap" in f
    arms = [f[s] for s in ("l", "r") if s in f]
    for g in (0.10, 0.12, 0.13, 0.15):
        for lo in (0.62, 0.65, 0.67):
            out[f"palms gap<={g} h{lo}-0.85 off<=0.10"] = both and f["gap"] <= g and lo <= f["wh"] <= 0.85 and f["off"] <= 0.10
    out["palms gap<=0.13 h0.65-0.85 off<=0.10 fwd>0"] = both and f["gap"] <= 0.13 and 0.65 <= f["wh"] <= 0.85 and f["off"] <= 0.10 and f["fwd"] > 0
    out["palms gap<=0.13 h0.65-0.85 off<=0.08"] = both and f["gap"] <= 0.13 and 0.65 <= f["wh"] <= 0.85 and f["off"] <= 0.08
    out["palms design gap<=0.06 h0.67-0.80"] = both and f["gap"] <= 0.06 and 0.67 <= f["wh"] <= 0.80
    for h in (0.75, 0.78, 0.80):
        for o in (0.10, 0.12):
            out[f"cross h_min>={h} off<={o}"] = both and f["wh_min"] >= h and f["off"] <= o
            out[f"cross h_min>={h} off<={o} elb_out>0"] = both and f["wh_min"] >= h and f["off"] <= o and f["elb_out"] > 0
            out[f"cross h_min>={h} off<={o} elb_out>0 elb_h<=wh"] = (both and f["wh_min"] >= h and f["off"] <= o and f["elb_out"] > 0
                                                                  and f["elb_h"] <= f["wh"] + 0.02)
            out[f"cross h_min>={h} off<={o} gap<=0.15 elb_out>0"] = (both and f["wh_min"] >= h and f["off"] <= o and f["gap"] <= 0.15
                                                                  and f["elb_out"] > 0)
    for plo, phi in ((0.65, 0.78), (0.65, 0.80), (0.66, 0.78)):
        out[f"palmsN gap<=0.13 h{plo}-{phi} off<=0.10 fwd>0"] = (both and f["gap"] <= 0.13 and plo <= f["wh"] <= phi and f["off"] <= 0.10
                                                            and f["fwd"] > 0)
    for fm in (25, 30, 35):
        out[f"palmsN gap<=0.13 h0.65-0.78 off<=0.10 fwd>0 fore<={fm}"] = (both and f["gap"] <= 0.13 and 0.65 <= f["wh"] <= 0.78
                                                                   and f["off"] <= 0.10 and f["fwd"] > 0 and f["fore_max"] <= fm)
    for ch in (0.74, 0.76, 0.78):
        for cg in (0.16, 0.20, 9):
            out[f"crossN h_min>={ch} off<=0.10 gap<={cg}"] = both and f["wh_min"] >= ch and f["off"] <= 0.10 and f["gap"] <= cg
    # Label-free cross with a ceiling (session 27, chosen on rendered_tuning + rendered_tuning_2): the
    # hands in front of the upper chest or face, not above the head (a ladder's rungs).
    for ch in (0.76, 0.78, 0.80):
        for top in (0.90, 0.92, 0.94):
            for o in (0.10, 0.12, 0.14):
                out[f"crossC h_min>={ch} h_max<={top} off<={o}"] = (both and f["wh_min"] >= ch and f["wh_max"] <= top
                                                                    and f["off"] <= o)
    # Extend: the design's region on the upper arm (elevation 70-110, out of the sagittal plane >= 70,
    # elbow >= 150), and on the line shoulder -> wrist (the elbow of a straight arm reads bent).
    out["extend design"] = any(70 <= a["elev"] <= 110 and a["abd"] >= 70 and a["elbow"] >= 150 for a in arms)
    for lo, hi in ((70, 110), (65, 115), (60, 120)):
        for ab in (70, 60):
            for e in (150, 140, 130):
                out[f"extendW whole{lo}-{hi} wabd>={ab} elbow>={e}"] = any(
                    lo <= a["whole"] <= hi and a["wabd"] >= ab and a["elbow"] >= e for a in arms)
    for w in (135, 140, 145, 150):
        for e in (120, 130, 140):
            out[f"raise whole>={w} elbow>={e}"] = any(a["whole"] >= w and a["elbow"] >= e for a in arms)
    out["raise design elev>=150 elbow>=150"] = any(a["elev"] >= 150 and a["elbow"] >= 150 for a in arms)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", default="/work/lstm_data")
    ap.add_argument("--set", default="rendered_tuning")
    ap.add_argument("--out", default=None)
    ap.add_argument("--features", action="store_true", help="also print feature percentiles per motion")
    a = ap.parse_args()
    protocol = re_.load_protocol(re_.PROTOCOL)
    spec = protocol["sets"][a.set]
    if a.set == "rendered_heldout" or spec["seed"] in range(*protocol["seed_range"]):
        sys.exit("geometry_rules: the held-out set is never used for choices (docs/gestures.md §8)")
    d = re_.set_dir(a.data, a.set, spec)
    meta = {int(r["sequence"]): r for r in re_.csv_rows(os.path.join(d, "sequences.csv"))}
    frames = tri_frames(d, spec)
    acc, feats = {}, {}
    for seq, fr in frames.items():
        md = meta[seq]
        t0, t1 = float(md["motion_start_s"]), float(md["motion_end_s"])
        for i, (t, _) in enumerate(fr):
            if not t0 <= t <= t1:
                continue
            f = features(median_of(fr, i))
            if f is None:
                continue
            motion = md["motion"]
            for k, v in rules(f).items():
                acc.setdefault(motion, {}).setdefault(k, []).append(bool(v))
            if "gap" in f:
                fl = feats.setdefault(motion, {})
                for k in ("gap", "wh", "wh_min", "off", "fwd", "elb_out", "elb_h", "fore_max"):
                    fl.setdefault(k, []).append(f[k])
            for s in ("l", "r"):
                if s in f:
                    fl = feats.setdefault(motion, {})
                    fl.setdefault("whole_max", []).append(f[s]["whole"])
            arms_ = [f[s] for s in ("l", "r") if s in f]
            if arms_:
                arm = max(arms_, key=lambda x: x["whole"] if x["whole"] < 125 else -1)
                fl = feats.setdefault(motion, {})
                for k in ("elev", "abd", "elbow", "whole", "wabd"):
                    fl.setdefault("ext_" + k, []).append(arm[k])
    motions = sorted(acc)
    names = list(next(iter(acc.values())).keys())
    res = {m: {k: round(float(np.mean(v)), 3) for k, v in acc[m].items()} for m in motions}
    width = max(len(n) for n in names)
    short = [m[:7] for m in motions]
    print(" " * width + " " + " ".join(f"{s:>7}" for s in short))
    print(" " * width + " " + " ".join(f"{len(next(iter(acc[m].values()))):>7}" for m in motions))
    for n in names:
        print(f"{n:<{width}} " + " ".join(f"{res[m][n]:>7.3f}" for m in motions))
    if a.features:
        for m in motions:
            print(m, {k: [round(float(np.percentile(v, q)), 3) for q in (10, 50, 90)] for k, v in feats.get(m, {}).items()})
    if a.out:
        with open(a.out, "w") as fo:
            json.dump({"set": a.set, "seed": spec["seed"], "median_frames": MEDIAN, "share_of_frames": res}, fo, indent=1)


if __name__ == "__main__":
    main()
