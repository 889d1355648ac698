"""The skeleton network's systematic errors applied to the generator's 2-D skeletons (training
augmentation for tools/train_gesture_lstm.py --error-model; docs/gestures.md §2 and §9).

The generator's keypoints are the true joints plus random noise; MoveNet's keypoints on rendered
frames err systematically (measured on the rendered TUNING set only, docs/gestures.md §9): hands
named by image side, crossed wrists pulled together, palms reported apart, the wrists of an object
held between the hands pulled together (optional `gap_deflation`), a raised arm read lower,
straight arms read bent, wrists with low confidence and poor positions. `apply` reproduces these
on one sequence, with the ranges of an error-model YAML (tools/gesture/error_model_movenet.yaml)
drawn once per sequence from a seeded generator. Labels are not changed.

Keypoints are COCO-17 in pixels, image y down: [T, 17, 3] (x, y, c); a keypoint with c <= 0 is
missing and left alone.
"""
import numpy as np
import yaml

LS, RS, LE, RE, LW, RW, LH, RH = 5, 6, 7, 8, 9, 10, 11, 12


def load(path):
    with open(path) as f:
        cfg = yaml.safe_load(f)
    for key in ("sequence_fraction", "swap_when_crossed", "crossed_gap_factor", "gap_inflation", "arm_compression",
                "arm_bend", "confidence_scale", "missing_wrist", "min_shoulder_separation"):
        if key not in cfg:
            raise ValueError(f"{path}: missing field '{key}'")
    if not 0.0 <= cfg["sequence_fraction"] <= 1.0:
        raise ValueError(f"{path}: sequence_fraction {cfg['sequence_fraction']} is not in [0, 1]")
    return cfg


def _draw(rng, r):
    return float(rng.uniform(r[0], r[1]))


def _present(kp, *joints):
    return np.all(kp[:, list(joints), 2] > 0, axis=1)


def _rotate(p, centre, angle_rad):
    """Rotates points p [T, 2] about centre [T, 2] by angle [T] (image coordinates)."""
    d = p - centre
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return centre + np.stack([c * d[:, 0] - s * d[:, 1], s * d[:, 0] + c * d[:, 1]], axis=1)


def _signed_angle(a, b):
    """Signed angle [rad] from vectors a to b [T, 2]."""
    return np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], np.sum(a * b, axis=1))


def _down(kp):
    """Per frame, the image direction from the shoulders' midpoint to the hips' (unit; (0, 1) without hips)."""
    d = np.tile([0.0, 1.0], (len(kp), 1))
    ok = _present(kp, LS, RS, LH, RH)
    v = 0.5 * (kp[:, LH, :2] + kp[:, RH, :2]) - 0.5 * (kp[:, LS, :2] + kp[:, RS, :2])
    n = np.linalg.norm(v, axis=1)
    ok &= n > 1e-6
    d[ok] = v[ok] / n[ok, None]
    return d


def _compress_and_bend(kp, h, cfg, rng):
    down = _down(kp)
    factor = _draw(rng, cfg["arm_compression"]["factor"])
    knee = np.radians(cfg["arm_compression"]["knee_deg"])
    bend = np.radians(_draw(rng, cfg["arm_bend"]["bend_deg"])) * (1 if rng.random() < 0.5 else -1)
    straight = np.radians(cfg["arm_bend"]["straight_deg"])
    for s, e, w in ((LS, LE, LW), (RS, RE, RW)):
        ok = _present(kp, s, e, w) & (np.linalg.norm(kp[:, e, :2] - kp[:, s, :2], axis=1) > 0.02 * h)
        if not ok.any():
            continue
        sh, el = kp[ok, s, :2], kp[ok, e, :2]
        signed = _signed_angle(down[ok], el - sh)
        elev = np.abs(signed)
        turn = np.where(elev > knee, -(elev - knee) * (1.0 - factor) * np.sign(signed), 0.0)
        kp[ok, e, :2] = _rotate(el, sh, turn)
        kp[ok, w, :2] = _rotate(kp[ok, w, :2], sh, turn)
        el, wr = kp[ok, e, :2], kp[ok, w, :2]
        elbow = np.abs(_signed_angle(sh - el, wr - el))
        kp[ok, w, :2] = _rotate(wr, el, np.where(elbow > straight, bend, 0.0))


def _image_side(kp, h, cfg):
    """+1 where the left shoulder is right of the right shoulder in the image (a frontal view), -1 where
    left of it, 0 where side-on or unknown."""
    dx = kp[:, LS, 0] - kp[:, RS, 0]
    ok = _present(kp, LS, RS) & (np.abs(dx) > cfg["min_shoulder_separation"] * h)
    return np.where(ok, np.sign(dx), 0.0)


def _gaps(kp, h, cfg, motion, rng, side):
    ok = _present(kp, LW, RW) & (side != 0)
    lw, rw = kp[:, LW, :2].copy(), kp[:, RW, :2].copy()
    mid = 0.5 * (lw + rw)
    crossed = ok & (side * (lw[:, 0] - rw[:, 0]) < 0)
    if motion == "cross_arms" and crossed.any():
        f = _draw(rng, cfg["crossed_gap_factor"])
        kp[crossed, LW, :2] = mid[crossed] + f * (lw[crossed] - mid[crossed])
        kp[crossed, RW, :2] = mid[crossed] + f * (rw[crossed] - mid[crossed])
    if motion in cfg.get("gap_deflation", {}):
        # wrists apart (an object between the hands) reported pulled together towards their midpoint:
        # the gap times the drawn factor, never below min_gap (box heights); with min_offset, only
        # where the wrists' midpoint lies at least that many shoulder widths aside of the shoulders'
        # (frontal views only: side-on, aside is not decided)
        spec = cfg["gap_deflation"][motion]
        spec = spec if isinstance(spec, dict) else {"factor": spec}
        f = _draw(rng, spec["factor"])
        both = _present(kp, LW, RW)
        if "min_offset" in spec:
            width = np.abs(kp[:, LS, 0] - kp[:, RS, 0])
            aside = np.abs(mid[:, 0] - 0.5 * (kp[:, LS, 0] + kp[:, RS, 0]))
            both &= (side != 0) & (aside >= spec["min_offset"] * np.maximum(width, 1e-9))
        gap = np.linalg.norm(lw - rw, axis=1)
        target = np.maximum(f * gap, spec.get("min_gap", 0.0) * h)
        scale = np.where(gap > target, target / np.maximum(gap, 1e-12), 1.0)
        kp[both, LW, :2] = mid[both] + scale[both, None] * (lw[both] - mid[both])
        kp[both, RW, :2] = mid[both] + scale[both, None] * (rw[both] - mid[both])
        lw, rw = kp[:, LW, :2].copy(), kp[:, RW, :2].copy()
    if motion in cfg["gap_inflation"]:
        target = _draw(rng, cfg["gap_inflation"][motion]) * h
        gap = np.linalg.norm(lw - rw, axis=1)
        widen = ok & (gap < target)
        # each wrist on its own shoulder's image side, along the shoulder line
        axis = kp[:, LS, :2] - kp[:, RS, :2]
        axis /= np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-9)
        kp[widen, LW, :2] = mid[widen] + 0.5 * target[widen, None] * axis[widen]
        kp[widen, RW, :2] = mid[widen] - 0.5 * target[widen, None] * axis[widen]


def _swaps(kp, cfg, rng, side):
    p = _draw(rng, cfg["swap_when_crossed"])
    for a, b in ((LW, RW), (LE, RE)):
        crossed = _present(kp, a, b) & (side != 0) & (side * (kp[:, a, 0] - kp[:, b, 0]) < 0)
        swap = crossed & (rng.random(len(kp)) < p)
        kp[swap, a], kp[swap, b] = kp[swap, b].copy(), kp[swap, a].copy()


def _confidences(kp, h, cfg, rng):
    scale = _draw(rng, cfg["confidence_scale"])
    for j in (LE, RE, LW, RW):
        kp[:, j, 2] = np.where(kp[:, j, 2] > 0, kp[:, j, 2] * scale, 0.0)
    m = cfg["missing_wrist"]
    rate = _draw(rng, m["rate"])
    for j in (LW, RW):
        miss = (kp[:, j, 2] > 0) & (rng.random(len(kp)) < rate)
        n = int(miss.sum())
        kp[miss, j, 2] = rng.uniform(m["confidence"][0], m["confidence"][1], n)
        kp[miss, j, :2] += rng.normal(0.0, m["position_noise"], (n, 2)) * h[miss, None]


def apply(keypoints, box, motion, cfg, rng):
    """Returns a copy of keypoints [T, 17, 3] with the network's errors; box [T, 4] (u, v, w, h) gives the
    scale; motion is the sequence's motion name (sequences.csv)."""
    kp = np.array(keypoints, dtype=np.float64, copy=True)
    h = np.where(box[:, 3] > 0, box[:, 3], 1.0)
    _compress_and_bend(kp, h, cfg, rng)
    side = _image_side(kp, h, cfg)
    _gaps(kp, h, cfg, motion, rng, side)
    _swaps(kp, cfg, rng, side)
    _confidences(kp, h, cfg, rng)
    return kp


def augment(raw, motions, cfg, seed, set_index):
    """raw: gesture_data.load_raw output; motions: sequence -> motion. Applies the model to
    cfg['sequence_fraction'] of the sequences (chosen and drawn from numpy's generator seeded with
    (seed, set_index, sequence)); returns a dict of the same form and the number of sequences changed."""
    out, changed = {}, 0
    for sid, (kp, box, lab, t) in raw.items():
        seq = sid[0] if isinstance(sid, tuple) else sid
        rng = np.random.default_rng([seed, set_index, seq])
        if rng.random() < cfg["sequence_fraction"]:
            kp = apply(kp, box, motions[seq], cfg, rng)
            changed += 1
        out[sid] = (kp, box, lab, t)
    return out, changed
