#!/usr/bin/env python3
"""Independent reference implementation of `gfctl gesture-filter` (docs/design.md §2, §8.3 and the
boundary semantics fixed in docs/formation.md §6-7), written from the text, not from the C++.

    gesture_filter_reference.py --config gestures.yaml --in gestures.csv --out commands.csv

Per row (t, gesture_id): skip the row (a warning in gfctl) when t is not finite, t is
earlier than the last accepted row, or the id is not an integer in 0..max_gesture_id.
Otherwise append; drop entries with t_i < t - max_age_s; keep the window_size newest;
evaluate when len(G) >= min_measurements; f_d = max count / len(G); tie for the maximum ->
nothing; fire when f_d > ratio_threshold, dominant != 0, and (no earlier command or
t - t_last >= cooldown_s), and — with `rearm: release` (the default) — the filter is armed: a
fired command disarms it; it re-arms when every evaluation since some time s had 0 as its sole
most frequent id and t - s >= release_s, or when the previous accepted row is older than
t - max_age_s (nothing seen for t_c). With `rearm: repeat` (the paper) it is always armed; any other `rearm` is an error. Fired rows: `t,gesture_id,parameter,increment,value` with value
the parameter after the increment, beta wrapped to (-180, 180], gamma / distance clamped
(docs/formation.md §3-4: every UAV's elevation - leader gamma_L, follower gamma_L + gamma_i -
within [gamma_min_deg, gamma_max_deg]; distance within [max(distance_min_m,
safety_distance_m), distance_max_m]); UAVs of a group updated leader first, values joined
with ';'. A command that would bring two UAVs' slots (their references around the worker)
closer than safety_distance_m, when they were not closer already, is refused: nothing changes,
value nan. Events: parameter = event name, increment 0, value nan; unmapped: none,0,nan.
"""
import argparse
import collections
import csv
import math
import sys

import yaml

FILTER_DEFAULTS = {"window_size": 20, "max_age_s": 20.0, "ratio_threshold": 0.8, "cooldown_s": 5.0,
                   "max_gesture_id": 4}
PAPER_MAPPING = {1: {"parameter": "leader.beta_deg", "increment": -30},
                 2: {"parameter": "leader.beta_deg", "increment": 30},
                 3: {"parameter": "leader.gamma_deg", "increment": -5},
                 4: {"parameter": "leader.gamma_deg", "increment": 5}}
TABLE2 = [{"beta_deg": 90.0, "gamma_deg": 11.0, "distance_m": 10.0},
          {"beta_deg": 60.0, "gamma_deg": 0.0, "distance_m": 8.0},
          {"beta_deg": -60.0, "gamma_deg": 0.0, "distance_m": 8.0}]
LIMITS = {"gamma_min_deg": -30.0, "gamma_max_deg": 60.0, "distance_min_m": 4.0, "distance_max_m": 25.0,
          "safety_distance_m": 2.5}


def fmt(v):
    """Like gfctl's formatDouble: 15 significant digits, shortest form."""
    if math.isnan(v):
        return "nan"
    return "%.15g" % v


def wrap_deg(a):
    w = math.fmod(a, 360.0)
    if w > 180.0:
        w -= 360.0
    elif w <= -180.0:
        w += 360.0
    return w


class Formation:
    def __init__(self, cfg):
        leader = dict(TABLE2[0])
        leader.update(cfg.get("leader") or {})
        if "followers" in cfg:
            followers = []
            for i, e in enumerate(cfg["followers"] or []):
                base = dict(TABLE2[i + 1]) if i < 2 else {"gamma_deg": 0.0, "distance_m": 8.0}
                base.update(e)
                followers.append(base)
        else:
            followers = [dict(TABLE2[1]), dict(TABLE2[2])]
        self.uavs = [leader] + followers  # index 0 leader
        self.lim = dict(LIMITS)
        self.lim.update(cfg.get("limits") or {})

    def targets(self, who):
        if who == "leader":
            return [0]
        if who == "all":
            return list(range(len(self.uavs)))
        if who == "followers":
            return list(range(1, len(self.uavs)))
        assert who.startswith("follower")
        return [int(who[len("follower"):])]

    def slots(self):
        """Every UAV's reference around a worker at the origin facing +x (docs/formation.md §2)."""
        gl, bl, dl = math.radians(self.uavs[0]["gamma_deg"]), math.radians(self.uavs[0]["beta_deg"]), self.uavs[0]["distance_m"]
        phi = -bl
        out = [(-dl * math.cos(phi) * math.cos(gl), -dl * math.sin(phi) * math.cos(gl), dl * math.sin(gl))]
        for f in self.uavs[1:]:
            az, e, d = phi - math.radians(f["beta_deg"]), gl + math.radians(f["gamma_deg"]), f["distance_m"]
            out.append((-d * math.cos(az) * math.cos(e), -d * math.sin(az) * math.cos(e), d * math.sin(e)))
        return out

    def closest(self):
        p = self.slots()
        return min((math.dist(p[a], p[b]) for a in range(len(p)) for b in range(a + 1, len(p))), default=None)

    def apply(self, path, inc):
        """The values after the command, or None when it is refused (nothing changes): it would bring
        two slots closer than safety_distance_m, and they were not closer already."""
        before = [dict(u) for u in self.uavs]
        before_min = self.closest()
        values = self.apply_clamped(path, inc)
        after_min = self.closest()
        if after_min is not None and after_min < self.lim["safety_distance_m"] and (
                before_min is None or after_min < before_min - 1e-9):
            self.uavs = before
            return None
        return values

    def apply_clamped(self, path, inc):
        who, name = path.split(".")
        values = []
        for u in sorted(set(self.targets(who))):
            q = self.uavs[u][name] + inc
            if name == "beta_deg":
                q = wrap_deg(q)
            elif name == "distance_m":
                q = min(max(q, max(self.lim["distance_min_m"], self.lim["safety_distance_m"])), self.lim["distance_max_m"])
            elif u == 0:  # the leader's gamma also lifts every follower
                lo = max([self.lim["gamma_min_deg"]] + [self.lim["gamma_min_deg"] - f["gamma_deg"] for f in self.uavs[1:]])
                hi = min([self.lim["gamma_max_deg"]] + [self.lim["gamma_max_deg"] - f["gamma_deg"] for f in self.uavs[1:]])
                q = min(max(q, lo), hi)
            else:
                g0 = self.uavs[0]["gamma_deg"]
                q = min(max(q, self.lim["gamma_min_deg"] - g0), self.lim["gamma_max_deg"] - g0)
            self.uavs[u][name] = q
            values.append(q)
        return values


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--config", required=True)
    ap.add_argument("--in", dest="inp", required=True)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    with open(args.config) as f:
        cfg = yaml.safe_load(f) or {}
    p = dict(FILTER_DEFAULTS)
    p.update({k: cfg[k] for k in FILTER_DEFAULTS if k in cfg})
    K = int(p["window_size"])
    min_meas = int(cfg.get("min_measurements", K))
    t_c, ratio, t_d, max_id = float(p["max_age_s"]), float(p["ratio_threshold"]), float(p["cooldown_s"]), int(p["max_gesture_id"])
    mapping = {int(k): v for k, v in (cfg["mapping"] if "mapping" in cfg else PAPER_MAPPING).items()}
    rearm = cfg.get("rearm", "release")
    if rearm not in ("release", "repeat"):
        sys.exit(f"{args.config}: rearm: value '{rearm}' is not one of release|repeat")
    release_mode = rearm == "release"
    release_s = float(cfg.get("release_s", 1.0))
    formation = Formation(cfg)

    G = []  # (t, id), oldest first
    last_t = None
    last_fire = None
    armed = True
    none_run_start = None  # first evaluation of the current run whose sole top id is 0
    out = ["t,gesture_id,parameter,increment,value"]
    with open(args.inp) as f:
        for row in csv.DictReader(f):
            t, g = float(row["t"]), float(row["gesture_id"])
            if not math.isfinite(t) or (last_t is not None and t < last_t):
                continue
            if not math.isfinite(g) or g != int(g) or not 0 <= g <= max_id:
                continue
            g = int(g)
            if last_t is not None and last_t < t - t_c:
                armed = True  # nothing seen for t_c: a new performance
            last_t = t
            G.append((t, g))
            G = [e for e in G if e[0] >= t - t_c]
            G = G[-K:]
            if len(G) < min_meas:
                continue
            counts = collections.Counter(e[1] for e in G)
            top = max(counts.values())
            leaders = [k for k, c in counts.items() if c == top]
            if len(leaders) == 1 and leaders[0] == 0:
                if none_run_start is None:
                    none_run_start = t
                if t - none_run_start >= release_s:
                    armed = True
            else:
                none_run_start = None
            if len(leaders) > 1:
                continue
            dominant = leaders[0]
            if not top / len(G) > ratio or dominant == 0:
                continue
            if last_fire is not None and not (t - last_fire >= t_d):
                continue
            if release_mode and not armed:
                continue
            last_fire = t
            armed = not release_mode
            none_run_start = None
            action = mapping.get(dominant)
            if action is None:
                out.append(f"{fmt(t)},{dominant},none,0,nan")
            elif "event" in action:
                out.append(f"{fmt(t)},{dominant},{action['event']},0,nan")
            else:
                inc = float(action["increment"])
                vals = formation.apply(action["parameter"], inc)
                value = "nan" if vals is None else ";".join(fmt(v) for v in vals)  # refused: nothing changed
                out.append(f"{fmt(t)},{dominant},{action['parameter']},{fmt(inc)},{value}")
    with open(args.out, "w") as f:
        f.write("\n".join(out) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
