#!/usr/bin/env python3
"""Development-time only: time SLICOT's AB13DD (through slycot) on the systems that
`cargo bench --bench lti -- --dump DIR` wrote, so both are measured on the same machine and data.

Usage: OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 python3 scripts/ab13dd_bench.py DIR [TOL]
Needs numpy and slycot (pip); the project and its tests do not.
"""
import json
import os
import sys
import time

import numpy as np
import slycot


def main():
    d = sys.argv[1]
    tol = float(sys.argv[2]) if len(sys.argv) > 2 else 1e-10
    print(f"AB13DD (slycot {slycot.__version__}), tol {tol:g}, thread CPU time (median)")
    print(f"{'system':>12} {'n':>5} {'seconds':>12} {'hinf':>14} {'peak w':>12} {'reps':>5}")
    for tag, n in [(t, n) for t in ("random", "damped") for n in (10, 50, 100, 250, 500)]:
        path = os.path.join(d, f"{tag}_n{n}.json")
        if not os.path.exists(path):
            continue
        s = json.load(open(path))
        A, B, C, D = (np.array(s[k], dtype=float, order="F") for k in "ABCD")
        m, p = B.shape[1], C.shape[0]
        E = np.eye(n, order="F")
        reps = 21 if n <= 100 else (9 if n <= 250 else 5)
        times = []
        for _ in range(reps):
            t0 = time.thread_time()
            g, w = slycot.ab13dd("C", "I", "N", "D", n, m, p, A.copy(order="F"), E, B, C, D, tol)
            times.append(time.thread_time() - t0)
        print(f"{tag:>12} {n:>5} {sorted(times)[reps // 2]:>12.6f} {g:>14.10f} {w:>12.6f} {reps:>5}")


if __name__ == "__main__":
    main()
