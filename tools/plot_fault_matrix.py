#!/usr/bin/env python3
"""The fault matrix at a glance (docs/results/reliability.md): per fault profile, every mission's minimum
UAV–UAV distance, minimum obstacle distance and minimum UAV–worker distance as dots, with the
median marked and the safety thresholds drawn. `tools/campaign.py report` calls draw() with the
missions of the campaign store; the command line reads a CSV with the same columns.

  /opt/gesture_formation/venv/bin/python tools/plot_fault_matrix.py RUNS.csv OUT.png [PROFILE ...]
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PANELS = [  # column, title, threshold, threshold label
    ("min_mutual_distance_m", "min UAV–UAV distance [m]", 2.5, "Γ_dis 2.5 m"),
    ("min_obstacle_distance_m", "min obstacle distance [m]", 0.5, "verification clearance 0.5 m"),
    ("min_human_distance_m", "min UAV–worker distance [m]", 3.0, "worker safety distance 3 m"),
]


def main(argv):
    if len(argv) < 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    runs, out, profiles = argv[1], argv[2], argv[3:]
    rows = list(csv.DictReader(open(runs)))
    try:
        draw(rows, profiles, out, source=runs)
    except ValueError as e:
        print(f"plot_fault_matrix.py: {e}", file=sys.stderr)
        return 2
    return 0


def draw(rows, profiles, out, source="the store"):
    """rows: dicts with profile and the PANELS columns (numbers, numeric strings, None or "")."""
    if not profiles:
        profiles = list(dict.fromkeys(r["profile"] for r in rows))
    data = {}
    for col, *_ in PANELS:
        per = []
        for p in profiles:
            vals = []
            for r in rows:
                if r["profile"] != p or r.get(col) is None or r.get(col) == "":
                    continue
                try:
                    vals.append(float(r[col]))
                except ValueError:
                    raise ValueError(f"{source}: column {col}, profile {p}: not a number: {r[col]!r}") from None
            per.append(vals)
        data[col] = per
    n = sum(1 for r in rows if r["profile"] in profiles)
    fig, axes = plt.subplots(1, len(PANELS), figsize=(15, 0.42 * len(profiles) + 1.6), sharey=True)
    for ax, (col, title, thr, thr_label) in zip(axes, PANELS):
        for k, vals in enumerate(data[col]):
            y = [k + 0.25 * ((i * 0.618) % 1.0 - 0.5) for i in range(len(vals))]  # deterministic jitter
            ax.scatter(vals, y, s=9, alpha=0.55, color="tab:blue", linewidths=0)
            if vals:
                med = sorted(vals)[len(vals) // 2]
                ax.plot([med, med], [k - 0.3, k + 0.3], color="black", lw=1.5)
                worst = min(vals)
                ax.annotate(f"{worst:.2f}", (worst, k), xytext=(-4, 0), textcoords="offset points",
                            ha="right", va="center", fontsize=7, color="tab:red" if worst < thr else "dimgray")
        ax.axvline(thr, color="tab:red", lw=1.2, ls="--", label=thr_label)
        ax.set_title(title, fontsize=10)
        ax.grid(axis="x", alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
        lo = min([thr] + [v for vals in data[col] for v in vals])
        ax.set_xlim(left=max(0.0, lo - 0.6))
    axes[0].set_yticks(range(len(profiles)))
    axes[0].set_yticklabels(profiles, fontsize=9)
    axes[0].invert_yaxis()
    counts = [len(v) for v in data[PANELS[0][0]]]
    fig.suptitle(f"Power-tower mission under faults: {n} missions, {min(counts)}–{max(counts)} seeds per profile "
                 "(dot: one mission; bar: median; number: the minimum)", fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    print(f"wrote {out}")


if __name__ == "__main__":
    sys.exit(main(sys.argv))
