#!/usr/bin/env python3
"""Summarises a `gfctl estimate` output against the ground truth of a sample flight and,
when matplotlib is available (tools venv), draws the estimate against the truth.

    summarize_estimate.py --states states.csv --truth truth.csv [--plot out.png]
"""
import argparse
import csv
import math


def load(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", required=True)
    ap.add_argument("--truth", required=True)
    ap.add_argument("--plot")
    a = ap.parse_args()
    states = load(a.states)
    truth = {round(float(r["t"]), 4): r for r in load(a.truth)}
    err_by_source, errs, series = {}, [], []
    for s in states:
        t = round(float(s["t"]), 4)
        if s["x"] == "nan" or t not in truth:
            continue
        g = truth[t]
        e = math.dist([float(s[k]) for k in "xyz"], [float(g[k]) for k in "xyz"])
        errs.append(e)
        err_by_source.setdefault(s["source"], []).append(e)
        series.append((t, [float(s[k]) for k in "xyz"], [float(g[k]) for k in "xyz"], s["source"],
                       math.sqrt(float(s["pxx"]) + float(s["pyy"]) + float(s["pzz"]))))
    rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v)) if v else float("nan")
    print(f"worker position error vs ground truth over {len(errs)} rows: RMS {rms(errs):.3f} m, "
          f"max {max(errs):.3f} m")
    for src in ("uwb", "stereo", "apparent", "none"):
        if src in err_by_source:
            label = "predicted only (no detection)" if src == "none" else f"after a {src} measurement"
            print(f"  {label:34s} {len(err_by_source[src]):5d} rows, RMS {rms(err_by_source[src]):.3f} m")
    if a.plot:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("(matplotlib not available: no plot)")
            return 0
        fig, axes = plt.subplots(4, 1, figsize=(10, 9), sharex=True)
        t = [r[0] for r in series]
        colours = {"uwb": "tab:green", "stereo": "tab:blue", "apparent": "tab:orange", "none": "tab:grey"}
        for i, name in enumerate("xyz"):
            axes[i].plot(t, [r[2][i] for r in series], "k-", lw=1.2, label="ground truth")
            axes[i].plot(t, [r[1][i] for r in series], "-", color="tab:red", lw=1, label="estimate")
            axes[i].set_ylabel(f"{name} [m]")
        for src, c in colours.items():
            pts = [(r[0], math.dist(r[1], r[2])) for r in series if r[3] == src]
            if pts:
                axes[3].scatter([p[0] for p in pts], [p[1] for p in pts], s=4, color=c, label=src)
        axes[3].plot(t, [r[4] for r in series], "k:", lw=1, label="1-sigma (trace)")
        axes[3].set_ylabel("error [m]")
        axes[3].set_xlabel("t [s]")
        axes[0].legend(loc="upper left", fontsize=8)
        axes[3].legend(loc="upper right", fontsize=8, ncol=5)
        fig.suptitle("gfctl estimate on the sample flight: worker position vs ground truth")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=90)
        print(f"plot: {a.plot}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
