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
import json
import os

import numpy as np
import scipy.linalg

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
NAMES = ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22")


def zoh(a, b, ts):
    """(e^{A Ts}, ∫₀^Ts e^{Aτ} dτ B) from one matrix exponential of [[A, B], [0, 0]]·Ts."""
    n, m = b.shape
    big = np.zeros((n + m, n + m))
    big[:n, :n], big[:n, n:] = a, b
    e = scipy.linalg.expm(big * ts)
    return e[:n, :n], e[:n, n:]


def main():
    he1 = json.load(open(os.path.join(ROOT, "plants", "HE1.json")))
    mats = {k: np.array(he1[k], dtype=float).reshape(len(he1[k]), -1) for k in NAMES}
    m1 = mats["B1"].shape[1]
    for ts in (0.1, 0.01):
        ad, bd = zoh(mats["A"], np.hstack([mats["B1"], mats["B2"]]), ts)
        doc = {
            "name": f"HE1_Ts{ts}",
            "description": f"COMPleib HE1 sampled with a zero-order hold on w and u at Ts = {ts} s",
            "source": {
                "citation": he1["source"]["citation"] + f"; zero-order hold at Ts = {ts} s",
                "script": "examples/discrete/make_plants.py",
            },
            "notes": "x[t+1] = e^{A Ts} x[t] + (∫ e^{Aτ}dτ) [B1 B2] [w; u][t]; C1, C2 and the D blocks are HE1's.",
            "Ts": ts,
            "dims": he1["dims"],
            "A": ad.tolist(),
            "B1": bd[:, :m1].tolist(),
            "B2": bd[:, m1:].tolist(),
        }
        for k in ("C1", "C2", "D11", "D12", "D21", "D22"):
            doc[k] = mats[k].tolist()
        path = os.path.join(HERE, f"HE1_Ts{ts}.json")
        with open(path, "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")
        print(f"wrote {path}: spectral radius {max(abs(np.linalg.eigvals(ad))):.6f}")


if __name__ == "__main__":
    main()
