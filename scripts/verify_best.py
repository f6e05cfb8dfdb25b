#!/usr/bin/env python3
"""Development-time only: recompute every controller of a results folder's best.csv
independently — the closed loop by python-control's LFT, its poles by numpy, ‖Tzw‖∞ by SLICOT's
AB13DD (python-control `linfnorm`) — and compare with the γ the report gives.

Usage: python3 scripts/verify_best.py results/compleib [--rtol 1e-6] [--max-n 600]
Needs numpy, control and slycot (pip); the project and its tests do not. Plants are read from
plants/ and plants/compleib/ (.json or .json.gz); continuous time only.
"""
import argparse
import csv
import gzip
import json
import math
import os

import control
import numpy as np

from protocol_progress import records


def plant_file(name):
    for d in ("plants", "plants/compleib"):
        for ext in (".json", ".json.gz"):
            p = os.path.join(d, name + ext)
            if os.path.exists(p):
                return p
    raise FileNotFoundError(name)


def load_plant(name):
    p = plant_file(name)
    with (gzip.open(p, "rt") if p.endswith(".gz") else open(p)) as f:
        d = json.load(f)
    n = d["dims"]["n"] if "dims" in d else len(d["A"])
    m = lambda k, r, c: np.array(d[k], dtype=float).reshape(r, c)
    dims = d["dims"]
    n, m1, m2, p1, p2 = dims["n"], dims["m1"], dims["m2"], dims["p1"], dims["p2"]
    A = m("A", n, n)
    B = np.hstack([m("B1", n, m1), m("B2", n, m2)])
    C = np.vstack([m("C1", p1, n), m("C2", p2, n)])
    D = np.block([[m("D11", p1, m1), m("D12", p1, m2)], [m("D21", p2, m1), m("D22", p2, m2)]])
    return control.ss(A, B, C, D), (n, m1, m2, p1, p2)


def controllers(folder):
    return {r["job_id"]: r["controller"] for r in records(folder) if r.get("controller")}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("--rtol", type=float, default=1e-6)
    ap.add_argument("--max-n", type=int, default=600)
    a = ap.parse_args()
    ks = controllers(a.folder)
    plants = {}
    bad = checked = skipped = 0
    for r in csv.DictReader(open(os.path.join(a.folder, "best.csv"), newline="")):
        # every row with a controller, its own jobs' or the other objective's (campaigns/FORMAT.md)
        if not r["job_id"]:
            continue
        name = r["plant"]
        if name not in plants:
            plants[name] = load_plant(name)
        P, (n, m1, m2, p1, p2) = plants[name]
        if n > a.max_n:
            skipped += 1
            continue
        K = ks[r["job_id"]]
        nk = len(K["AK"])
        if nk:
            Ks = control.ss(np.array(K["AK"]), np.array(K["BK"]), np.array(K["CK"]), np.array(K["DK"]))
        else:
            Ks = control.ss([], [], [], np.array(K["DK"]))
        cl = P.lft(Ks, nu=m2, ny=p2)  # u = K y
        alpha = max(np.linalg.eigvals(cl.A).real) if cl.nstates else -math.inf
        alpha_k = max(np.linalg.eigvals(np.array(K["AK"])).real) if nk else -math.inf
        gamma = float(control.linfnorm(cl)[0]) if alpha < 0 else math.inf
        ours = float(r["gamma"])
        strong_ok = r["objective"] != "strong" or alpha_k < 0
        close = math.isclose(gamma, ours, rel_tol=a.rtol, abs_tol=1e-12)
        checked += 1
        if not (alpha < 0 and strong_ok and close):
            bad += 1
            print(f"DIFFERS {name} n_K={r['order']} {r['objective']}: ours {ours:.10g}, SLICOT {gamma:.10g}, "
                  f"α(A_cl) {alpha:.3e}, α(A_K) {alpha_k:.3e}")
    print(f"checked {checked} controllers ({skipped} skipped: n > {a.max_n}); {bad} differ")


if __name__ == "__main__":
    main()
