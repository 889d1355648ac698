#!/usr/bin/env python3
"""Independent check of the planner's trajectory QP (docs/planning.md §6).

Reads the JSON written by `gfctl plan --dump-qp qp.json` (the matrices handed to ProxQP:
min ½xᵀHx + gᵀx  s.t.  Ax = b,  l ≤ Cx ≤ u, with ±1e20 meaning "no bound", plus ProxQP's
solution x and objective), solves the same QP with SciPy's SLSQP (an active-set SQP, a
different algorithm and code base), and compares. Exit 0 when the objectives agree within
--rtol and ProxQP's x satisfies every constraint within --feas; prints the figures.
Usage: qp_reference.py qp.json [--rtol 1e-5] [--feas 1e-5]
"""
import argparse
import json
import sys

import numpy as np
from scipy.optimize import minimize


def dense(m):
    out = np.zeros((m["rows"], m["cols"]))
    for r, c, v in m["entries"]:
        out[r, c] += v
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("qp")
    ap.add_argument("--rtol", type=float, default=1e-5)
    ap.add_argument("--feas", type=float, default=1e-5)
    a = ap.parse_args()
    with open(a.qp) as f:
        q = json.load(f)
    if q is None:
        print("qp_reference: no QP in the dump (the planner did not reach stage 3)")
        return 1
    H, A, C = dense(q["H"]), dense(q["A"]), dense(q["C"])
    g, b = np.array(q["g"]), np.array(q["b"])
    l, u = np.array(q["l"]), np.array(q["u"])
    x_prox = np.array(q["x"])
    H = 0.5 * (H + H.T)
    lo_rows = l > -1e19
    hi_rows = u < 1e19

    def f(x):
        return 0.5 * x @ H @ x + g @ x

    cons = [{"type": "eq", "fun": lambda x: A @ x - b, "jac": lambda x: A}]
    if lo_rows.any():
        cons.append({"type": "ineq", "fun": lambda x: C[lo_rows] @ x - l[lo_rows], "jac": lambda x: C[lo_rows]})
    if hi_rows.any():
        cons.append({"type": "ineq", "fun": lambda x: u[hi_rows] - C[hi_rows] @ x, "jac": lambda x: -C[hi_rows]})
    # Start from the equality-constrained least-norm point (not from ProxQP's answer).
    x0 = np.linalg.lstsq(A, b, rcond=None)[0]
    res = minimize(f, x0, jac=lambda x: H @ x + g, constraints=cons, method="SLSQP",
                   options={"ftol": 1e-13, "maxiter": 2000})
    viol_prox = max(np.abs(A @ x_prox - b).max(),
                    np.maximum(0, l[lo_rows] - C[lo_rows] @ x_prox).max(initial=0),
                    np.maximum(0, C[hi_rows] @ x_prox - u[hi_rows]).max(initial=0))
    viol_ref = max(np.abs(A @ res.x - b).max(),
                   np.maximum(0, l[lo_rows] - C[lo_rows] @ res.x).max(initial=0),
                   np.maximum(0, C[hi_rows] @ res.x - u[hi_rows]).max(initial=0))
    f_prox, f_ref = f(x_prox), f(res.x)
    scale = max(1.0, abs(f_ref) + abs(q["cost_constant"]))
    rel = abs(f_prox - f_ref) / scale
    dx = np.abs(x_prox - res.x).max()
    print(f"qp_reference: n={H.shape[0]} n_eq={A.shape[0]} n_in={C.shape[0]} ({int(lo_rows.sum() + hi_rows.sum())} finite bounds); "
          f"SLSQP {'ok' if res.success else 'FAILED: ' + res.message}, {res.nit} iterations")
    print(f"qp_reference: objective ProxQP {f_prox:.10g} vs SLSQP {f_ref:.10g} (relative difference {rel:.2e}); "
          f"max |x_prox - x_slsqp| = {dx:.2e}; violation ProxQP {viol_prox:.2e}, SLSQP {viol_ref:.2e}")
    ok = res.success and viol_ref <= 1e-6 and viol_prox <= a.feas and rel <= a.rtol
    if not ok:
        print("qp_reference: MISMATCH")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
