#!/usr/bin/env python3
"""Independent reference implementation of `gfctl formation-ref` (docs/design.md §4 and §8.2),
written from docs/design.md (paper eqs. leader_ref / follower_ref) with numpy, vectorised
over the input rows, to check the C++ core against.

    formation_ref_reference.py --config formation.yaml --in human.csv --out refs.csv
    formation_ref_reference.py --compare A.csv B.csv [--tol 1e-9]

Equations (angles in radians, headings wrapped to (-pi, pi], pitch = camera pitch):
  leader:     pL = pH - dL [cos(phiH - bL) cos gL, sin(phiH - bL) cos gL, -sin gL]
              phiL = phiH - bL, xiL = -gL
  follower i: pi = pH - di [cos(phiL - bi) cos(gi - xiL), sin(phiL - bi) cos(gi - xiL), sin(xiL - gi)]
              phii = phiL - bi, xii = xiL - gi
Followers use the leader's desired phiL, xiL of the same row; h_heading is phiH.
Config: leader/followers as in docs/design.md §8.2 (degrees), defaults Table II; limits as in
docs/formation.md §3 (this script checks them and exits 2 on a violation, like gfctl).

--compare: same header and labels; numeric fields equal to an absolute tol (gfctl
prints 15 significant digits), heading/pitch compared modulo 2*pi; both files' headings
must lie in (-pi, pi].
"""
import argparse
import csv
import math
import sys

import numpy as np
import yaml

TABLE2_LEADER = {"beta_deg": 90.0, "gamma_deg": 11.0, "distance_m": 10.0}
TABLE2_FOLLOWERS = [{"beta_deg": 60.0, "gamma_deg": 0.0, "distance_m": 8.0},
                    {"beta_deg": -60.0, "gamma_deg": 0.0, "distance_m": 8.0}]
LIMITS = {"gamma_min_deg": -30.0, "gamma_max_deg": 60.0, "distance_min_m": 4.0, "distance_max_m": 25.0,
          "safety_distance_m": 2.5}


def wrap(a):
    """(-pi, pi]"""
    w = np.mod(a + np.pi, 2 * np.pi) - np.pi  # [-pi, pi)
    return np.where(w <= -np.pi, w + 2 * np.pi, w)


def load_config(path):
    with open(path) as f:
        cfg = yaml.safe_load(f) or {}
    leader = dict(TABLE2_LEADER)
    leader.update(cfg.get("leader") or {})
    if "followers" in cfg:
        followers = []
        for i, entry in enumerate(cfg["followers"] or []):
            base = dict(TABLE2_FOLLOWERS[i]) if i < 2 else {"gamma_deg": 0.0, "distance_m": 8.0}
            base.update(entry)
            followers.append(base)
    else:
        followers = [dict(f) for f in TABLE2_FOLLOWERS]
    limits = dict(LIMITS)
    limits.update(cfg.get("limits") or {})
    problems = []
    floor = max(limits["distance_min_m"], limits["safety_distance_m"])
    for name, u, elev in [("leader", leader, leader["gamma_deg"])] + [
            (f"followers[{i}]", f, leader["gamma_deg"] + f["gamma_deg"]) for i, f in enumerate(followers)]:
        if not (-180 < u["beta_deg"] <= 180):
            problems.append(f"{name}.beta_deg")
        if not (limits["gamma_min_deg"] <= elev <= limits["gamma_max_deg"]):
            problems.append(f"{name}.gamma_deg")
        if not (floor <= u["distance_m"] <= limits["distance_max_m"]):
            problems.append(f"{name}.distance_m")
    return leader, followers, problems


def compute(config, rows):
    leader, followers, _ = load_config(config)
    t = np.array([r[0] for r in rows])
    pH = np.array([[r[1], r[2], r[3]] for r in rows]).reshape(-1, 3)
    phiH = np.array([r[4] for r in rows])
    bL, gL, dL = math.radians(leader["beta_deg"]), math.radians(leader["gamma_deg"]), leader["distance_m"]
    phiL = phiH - bL
    xiL = -gL
    pL = pH - dL * np.stack([np.cos(phiL) * math.cos(gL), np.sin(phiL) * math.cos(gL),
                             np.full_like(phiL, -math.sin(gL))], axis=1)
    out = [("L", pL, wrap(phiL), np.full_like(phiL, xiL))]
    for i, f in enumerate(followers, start=1):
        b, g, d = math.radians(f["beta_deg"]), math.radians(f["gamma_deg"]), f["distance_m"]
        az = phiL - b
        p = pH - d * np.stack([np.cos(az) * math.cos(g - xiL), np.sin(az) * math.cos(g - xiL),
                               np.full_like(az, math.sin(xiL - g))], axis=1)
        out.append((str(i), p, wrap(az), np.full_like(az, xiL - g)))
        # self-check: the reference lies at d from the worker
        assert np.allclose(np.linalg.norm(p - pH, axis=1), d, atol=1e-9)
    assert np.allclose(np.linalg.norm(pL - pH, axis=1), dL, atol=1e-9)
    return t, out


def fmt(v):
    return "nan" if math.isnan(v) else repr(float(v))


def run(args):
    leader, followers, problems = load_config(args.config)
    if problems:
        print(f"{args.config}: out of limits: {', '.join(problems)}", file=sys.stderr)
        return 2
    with open(args.inp) as f:
        rows = [[float(r[k]) for k in ("t", "hx", "hy", "hz", "h_heading")] for r in csv.DictReader(f)]
    t, refs = compute(args.config, rows)
    with open(args.out, "w") as f:
        f.write("t,uav,x,y,z,heading,pitch\n")
        for k in range(len(t)):
            for label, p, phi, xi in refs:
                f.write(",".join([fmt(t[k]), label, fmt(p[k, 0]), fmt(p[k, 1]), fmt(p[k, 2]), fmt(phi[k]), fmt(xi[k])]) + "\n")
    return 0


def compare(a, b, tol):
    with open(a) as fa, open(b) as fb:
        ra, rb = list(csv.reader(fa)), list(csv.reader(fb))
    if ra[0] != rb[0] or len(ra) != len(rb):
        print(f"header or row count differ: {ra[0]} {len(ra)} vs {rb[0]} {len(rb)}")
        return 1
    bad, worst = 0, 0.0
    for line, (x, y) in enumerate(zip(ra[1:], rb[1:]), start=2):
        for name, u, v in zip(ra[0], x, y):
            if name == "uav":
                if u != v:
                    bad += 1
                    print(f"line {line}: uav {u} vs {v}")
                continue
            fu, fv = float(u), float(v)
            diff = abs(fu - fv)
            if name in ("heading", "pitch"):
                diff = abs(math.remainder(fu - fv, 2 * math.pi))
                if name == "heading" and not all(-math.pi < w <= math.pi + 1e-9 for w in (fu, fv)):
                    bad += 1
                    print(f"line {line}: heading not wrapped: {u} / {v}")
            rel = diff
            worst = max(worst, rel)
            if rel > tol:
                bad += 1
                if bad <= 10:
                    print(f"line {line} field {name}: {u} vs {v} (abs diff {rel:.3g})")
    print(f"compared {len(ra) - 1} rows: {bad} differences beyond {tol} (absolute); worst {worst:.3g}")
    return 1 if bad else 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--config")
    ap.add_argument("--in", dest="inp")
    ap.add_argument("--out")
    ap.add_argument("--compare", nargs=2)
    ap.add_argument("--tol", type=float, default=1e-9)
    args = ap.parse_args()
    if args.compare:
        return compare(args.compare[0], args.compare[1], args.tol)
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
