#!/usr/bin/env python3
"""Development-time only: writes tests/fixtures/hinf-stress/*.json, H∞-norm reference values from
SLICOT's AB13DD (slycot, tol 1e-12) for systems that stress the level-set method's Hamiltonian
eigenvalue step: lightly damped modes spread over many decades, a low-frequency peak beside
fast modes (|λ| ≪ ‖H‖, the square-reduced method's weak spot), bad scaling, MIMO, D ≠ 0.
Same keys as the shared oracle's hinfnorm files; kind "modal" (flat enough that only the value, not
the peak frequency, is compared). Needs numpy and slycot (pip)."""
import json
import os
import sys

import numpy as np
import slycot

OUT = os.path.join(os.path.dirname(__file__), "..", "tests", "fixtures", "hinf-stress")


def modal(rng, freqs, zetas, m, p, dscale, bscale=1.0):
    """Block-diagonal lightly damped modes, then a random orthogonal similarity (non-modal A)."""
    blocks = []
    for w, z in zip(freqs, zetas):
        blocks.append(np.array([[-z * w, w * np.sqrt(1 - z * z)], [-w * np.sqrt(1 - z * z), -z * w]]))
    n = 2 * len(blocks)
    A = np.zeros((n, n))
    for k, b in enumerate(blocks):
        A[2 * k:2 * k + 2, 2 * k:2 * k + 2] = b
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    A = Q @ A @ Q.T
    B = bscale * rng.standard_normal((n, m))
    C = rng.standard_normal((p, n))
    D = dscale * rng.standard_normal((p, m))
    return A, B, C, D


def ab13dd(A, B, C, D):
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    g, w = slycot.ab13dd("C", "I", "N", "D", n, m, p, A.copy(order="F"), np.eye(n, order="F"),
                         B.copy(order="F"), C.copy(order="F"), D.copy(order="F"), 1e-12)
    return g, w


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = np.random.default_rng(20261201)
    cases = []
    for i in range(12):  # many lightly damped modes over 4 decades
        k = int(rng.integers(5, 40))
        freqs = 10 ** rng.uniform(-2, 2, k)
        zetas = 10 ** rng.uniform(-4, -1, k)
        cases.append((f"modal_spread_{i}", "modal", modal(rng, freqs, zetas, int(rng.integers(1, 4)), int(rng.integers(1, 4)), 0.1)))
    for i in range(8):  # one slow lightly damped peak among fast, big modes
        k = int(rng.integers(5, 30))
        # kept well enough conditioned for 1e-8 comparisons: ε‖A‖ / (ζω of the peak) ≲ 1e-9
        freqs = np.concatenate([[10 ** rng.uniform(-2, -1)], 10 ** rng.uniform(1.5, 3, k)])
        zetas = np.concatenate([[10 ** rng.uniform(-2, -1.5)], 10 ** rng.uniform(-2, -0.5, k)])
        cases.append((f"slow_peak_fast_modes_{i}", "modal", modal(rng, freqs, zetas, 2, 2, 0.0)))
    for i in range(6):  # badly scaled random stable
        n = int(rng.integers(20, 70))
        A = rng.standard_normal((n, n)) / np.sqrt(n)
        A -= (np.max(np.linalg.eigvals(A).real) + 10 ** rng.uniform(-3, 0)) * np.eye(n)
        S = np.diag(10 ** rng.uniform(-2, 2, n))
        A = S @ A @ np.linalg.inv(S)
        B = rng.standard_normal((n, 2)) * 10 ** rng.uniform(-2, 3)
        C = rng.standard_normal((3, n))
        D = rng.standard_normal((3, 2)) * 10 ** rng.uniform(-2, 1)
        cases.append((f"scaled_random_{i}", "random", (A, B, C, D)))
    for i in range(4):  # peak at infinity approached: D dominates
        n = int(rng.integers(10, 40))
        A = rng.standard_normal((n, n)) / np.sqrt(n) - 1.5 * np.eye(n)
        B, C = 0.05 * rng.standard_normal((n, 2)), 0.05 * rng.standard_normal((2, n))
        D = rng.standard_normal((2, 2))
        cases.append((f"near_infinity_{i}", "peak-inf", (A, B, C, D)))
    for name, kind, (A, B, C, D) in cases:
        g, w = ab13dd(A, B, C, D)
        doc = {"A": A.tolist(), "B": B.tolist(), "C": C.tolist(), "D": D.tolist(), "hinf": g,
               "peak_freq": "inf" if not np.isfinite(w) else w,
               "spectral_abscissa": float(np.max(np.linalg.eigvals(A).real)), "kind": kind,
               "source": "scripts/gen_hinf_stress.py (AB13DD via slycot 0.7.1, tol 1e-12)"}
        with open(os.path.join(OUT, name + ".json"), "w") as f:
            json.dump(doc, f)
        print(f"{name:<26} n={A.shape[0]:<4} hinf={g:.10g} peak={w:.6g}")


if __name__ == "__main__":
    sys.exit(main())
