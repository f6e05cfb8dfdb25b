"""Builds the discrete-time worked example's plants: COMPleib HE1 (plants/HE1.json) sampled
with a zero-order hold on every input (w and u alike) at Ts = 0.1 s and Ts = 0.01 s, as
HE1_Ts0.1.json and HE1_Ts0.01.json (the plant file format with its `Ts` key).

    x[t+1] = Ad x[t] + Bd [w; u][t],  Ad = e^{A Ts},  Bd = (∫₀^Ts e^{Aτ} dτ) [B1 B2]
    z, y unchanged (C and D are not touched by a zero-order hold)

Development-time only (hinfix and its tests never run Python):

    python3 -m venv venv && venv/bin/pip install control slycot numpy scipy
    venv/bin/python examples/discrete/make_plants.py

`campaign plant examples/discrete/HE1_Ts0.1.json` shows a plant with its full-order γ.
"""
import os
import sys

import numpy as np
import scipy.linalg

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
import he1 as HE1  # noqa: E402  (examples/he1.py)


def zoh(a, b, ts):
    """(e^{A Ts}, ∫₀^Ts e^{Aτ} dτ B) from one matrix exponential of [[A, B], [0, 0]]·Ts."""
    n, m = b.shape
    big = np.zeros((n + m, n + m))
    big[:n, :n], big[:n, n:] = a, b
    e = scipy.linalg.expm(big * ts)
    return e[:n, :n], e[:n, n:]


def main():
    he1, mats = HE1.load()
    m1 = mats["B1"].shape[1]
    for ts in (0.1, 0.01):
        ad, bd = zoh(mats["A"], np.hstack([mats["B1"], mats["B2"]]), ts)
        path = HE1.write(
            HERE,
            f"HE1_Ts{ts}",
            f"COMPleib HE1 sampled with a zero-order hold on w and u at Ts = {ts} s",
            f"zero-order hold at Ts = {ts} s",
            "examples/discrete/make_plants.py",
            "x[t+1] = e^{A Ts} x[t] + (∫ e^{Aτ}dτ) [B1 B2] [w; u][t]; C1, C2 and the D blocks are HE1's.",
            he1,
            {**mats, "A": ad, "B1": bd[:, :m1], "B2": bd[:, m1:]},
            ts=ts,
        )
        print(f"wrote {path}: spectral radius {max(abs(np.linalg.eigvals(ad))):.6f}")


if __name__ == "__main__":
    main()
