#!/usr/bin/env python3
"""OSQP beside ProxQP on the planner's own QPs: the anchor of the trajectory QP's solve times.

Reads the QPs that `gf_bench_planner --mission --qp-dump DIR` wrote (DIR/qp_NN.json, the format of
include/gesture_formation/planning/qp_json.hpp: min ½xᵀHx + gᵀx s.t. Ax = b, l ≤ Cx ≤ u, ±1e20 = no
bound, plus the planner's primal warm start x0, ProxQP's answer x / objective / status and its CPU
time `proxqp_cpu_ms`: TrajectoryQp::solveMatrices on the same matrices and warm start, median of
`repeats`, set-up included). Solves each with OSQP (the tools venv's, tools/setup.sh) at equal
accuracy — the same eps_abs, eps_rel 0, unscaled termination, no duality-gap test and no polishing
(ProxQP's criterion: primal and dual residual ∞-norms ≤ eps_abs on the original problem), the
primal infeasibility tolerance ProxQP used, the same primal warm start — and prints both CPU times
side by side (OSQP: set-up + warm start + solve, median of --repeats, the smaller of this thread's CPU
time and OSQP's own run_time, so that the Python wrapper is never charged to the anchor).
Each OSQP solution is checked against ProxQP's: relative objective difference and both constraint
violations on the original rows.

Usage (tools venv python, docs/planning.md §10):
  /opt/gesture_formation/venv/bin/python tools/bench_qp_osqp.py DIR [--repeats 5]
      [--results docs/results/planning_tails.md]
--results replaces (or appends) this program's section of that page; the rest of it is kept.
Exit 0 when every QP ProxQP solved is solved by OSQP to within --rtol (1e-4) of its objective and
the statuses agree; 1 otherwise; 2 on bad input.
"""
import argparse
import glob
import json
import os
import statistics
import sys
import time

import numpy as np
import osqp
import scipy.sparse as sp

BEGIN = "<!-- tools/bench_qp_osqp.py: begin -->"
END = "<!-- tools/bench_qp_osqp.py: end -->"
NO_BOUND = 1e19


def sparse(m):
    rows, cols, vals = (zip(*m["entries"]) if m["entries"] else ((), (), ()))
    return sp.csc_matrix((vals, (rows, cols)), shape=(m["rows"], m["cols"]))


def bounds(v):
    a = np.array(v, dtype=float)
    a[a >= NO_BOUND] = np.inf
    a[a <= -NO_BOUND] = -np.inf
    return a


def violation(q, x):
    """Worst violation of Ax = b and l ≤ Cx ≤ u by x (0 when all hold)."""
    if x is None or not np.all(np.isfinite(x)):
        return float("inf")
    worst = np.abs(q["A"] @ x - q["b"]).max(initial=0.0)
    cx = q["C"] @ x
    worst = max(worst, np.maximum(q["l"] - cx, 0.0).max(initial=0.0), np.maximum(cx - q["u"], 0.0).max(initial=0.0))
    return float(worst)


def objective(q, x):
    return float(0.5 * x @ (q["H"] @ x) + q["g"] @ x + q["cost_constant"])


def load(path):
    with open(path) as f:
        d = json.load(f)
    q = {k: sparse(d[k]) for k in ("H", "A", "C")}
    q.update({k: np.array(d[k], dtype=float) for k in ("g", "b")})
    q["l"], q["u"] = bounds(d["l"]), bounds(d["u"])
    q["x0"] = np.array(d["x0"], dtype=float) if d["x0"] else None
    q["x_prox"] = np.array([np.nan if v is None else v for v in d["x"]], dtype=float) if d["x"] else None
    for k in ("cost_constant", "eps_abs", "eps_primal_inf", "proxqp_cpu_ms", "t_s", "objective"):
        q[k] = np.nan if d[k] is None else float(d[k])
    q.update(uav=d["uav"], status=d["status"], iterations=d["iterations"], name=os.path.basename(path))
    return q


def solve_osqp(q, repeats):
    """OSQP at ProxQP's accuracy: (status, iterations, x, ms): ms = the smaller of the medians of this
    thread's CPU time around set-up + solve (the Python wrapper included) and OSQP's own run_time
    (set-up + solve in its C code, wall clock): the anchor is never charged for the wrapper."""
    P = sp.triu(q["H"], format="csc")
    A = sp.vstack([q["A"], q["C"]], format="csc")
    lo = np.concatenate([q["b"], q["l"]])
    hi = np.concatenate([q["b"], q["u"]])
    times, run_times, res = [], [], None
    for _ in range(repeats):
        t0 = time.thread_time()
        m = osqp.OSQP()
        m.setup(P, q["g"], A, lo, hi, verbose=False, eps_abs=q["eps_abs"], eps_rel=0.0, eps_prim_inf=q["eps_primal_inf"],
                scaled_termination=False, check_dualgap=False, polishing=False, max_iter=200000)
        if q["x0"] is not None:
            m.warm_start(x=q["x0"])
        res = m.solve()
        times.append(1e3 * (time.thread_time() - t0))
        run_times.append(1e3 * res.info.run_time)
    return res.info.status, res.info.iter, res.x, min(statistics.median(times), statistics.median(run_times))


def same_status(prox, osqp_status):
    if prox == "solved":
        return osqp_status == "solved"
    if prox == "primal infeasible":
        return osqp_status == "primal infeasible"
    return False


def table(rows, repeats):
    out = [f"QPs of the mission's replannings over 10 ms CPU (gf_bench_planner --qp-dump), CPU ms (median of "
           f"{repeats}; ProxQP: set-up + solve from the assembled matrices; OSQP {osqp.__version__}: set-up + solve, "
           f"the smaller of CPU time and its own run_time), "
           f"both from the planner's primal warm start, eps_abs as the planner's, eps_rel 0:",
           f"{'qp':>6} {'t_s':>7} {'uav':>3} {'rows':>5} {'ProxQP':>18} {'it':>4} {'ms':>8}   {'OSQP':>18} {'it':>6} "
           f"{'ms':>8}  {'OSQP/ProxQP':>11} {'obj rel diff':>12} {'viol ProxQP':>11} {'viol OSQP':>10}"]
    for r in rows:
        out.append(f"{r['name'][3:5]:>6} {r['t_s']:7.2f} {r['uav']:3d} {r['rows']:5d} {r['prox_status']:>18} {r['prox_it']:4d} "
                   f"{r['prox_ms']:8.2f}   {r['osqp_status']:>18} {r['osqp_it']:6d} {r['osqp_ms']:8.2f}  "
                   f"{r['osqp_ms'] / r['prox_ms']:11.2f} {r['obj_diff']:12.1e} {r['viol_prox']:11.1e} {r['viol_osqp']:10.1e}")
    for label, keep in (("solved by ProxQP", lambda r: r["prox_status"] == "solved"),
                        ("primal infeasible (ProxQP)", lambda r: r["prox_status"] == "primal infeasible")):
        sel = [r for r in rows if keep(r)]
        if not sel:
            continue
        p = [r["prox_ms"] for r in sel]
        o = [r["osqp_ms"] for r in sel]
        faster = sum(1 for r in sel if r["prox_ms"] <= r["osqp_ms"])
        out.append(f"  {label}: {len(sel)} QPs; ProxQP median {statistics.median(p):.2f} max {max(p):.2f} ms, OSQP median "
                   f"{statistics.median(o):.2f} max {max(o):.2f} ms; ProxQP at most OSQP's time on {faster}/{len(sel)}")
    return out


def write_section(path, lines, command):
    load_avg = os.getloadavg()[0]
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    body = [BEGIN, "", "## ProxQP and OSQP on the same QPs (the anchor)", "",
            f"Written by `{command}` on {stamp} (load average {load_avg:.2f}). The QPs are the ones of the run above",
            "(`--qp-dump`); what is measured: [planning.md](../planning.md) §10.", "", "```", *lines, "```", "", END]
    text = open(path).read() if os.path.exists(path) else ""
    if BEGIN in text and END in text:
        text = text[:text.index(BEGIN)] + text[text.index(END) + len(END):].lstrip("\n")
    with open(path, "w") as f:
        f.write(text.rstrip("\n") + "\n\n" + "\n".join(body) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--rtol", type=float, default=1e-4)
    ap.add_argument("--results")
    a = ap.parse_args()
    paths = sorted(glob.glob(os.path.join(a.dir, "qp_*.json")))
    if not paths or a.repeats < 1:
        print(f"bench_qp_osqp: no qp_*.json in {a.dir} (gf_bench_planner --mission --qp-dump {a.dir})" if not paths
              else "bench_qp_osqp: --repeats must be >= 1", file=sys.stderr)
        return 2
    rows, ok = [], True
    for path in paths:
        q = load(path)
        status, iters, x, ms = solve_osqp(q, a.repeats)
        r = dict(name=q["name"], t_s=q["t_s"], uav=q["uav"], rows=q["A"].shape[0] + q["C"].shape[0],
                 prox_status=q["status"], prox_it=q["iterations"], prox_ms=q["proxqp_cpu_ms"], osqp_status=status,
                 osqp_it=iters, osqp_ms=ms, obj_diff=float("nan"), viol_prox=violation(q, q["x_prox"]),
                 viol_osqp=violation(q, x) if status == "solved" else float("nan"))
        if q["status"] == "solved" and status == "solved":
            r["obj_diff"] = abs(objective(q, x) - q["objective"]) / max(1.0, abs(q["objective"]))
            ok &= r["obj_diff"] <= a.rtol
        if q["status"] != "solved":
            r["viol_prox"] = float("nan")
        ok &= same_status(q["status"], status)
        rows.append(r)
    lines = table(rows, a.repeats)
    print("\n".join(lines))
    if a.results:
        write_section(a.results, lines, "tools/bench_qp_osqp.py " + " ".join(sys.argv[1:]))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
