"""Builds the multi-model worked example's plants: COMPleib HE1 (plants/HE1.json) at three
operating points, its state matrix perturbed as a change of flight condition would move its
stability derivatives:

    A_j = A ∘ (1 + δ_j R),   δ = −0.2, 0 (HE1 itself), +0.2

with R a fixed matrix of entries in [−1, 1] (drawn once, seed 1, and written into each file's
notes), B, C, D unchanged. HE1_op2 is HE1 exactly. The files are the plant file format; a
controller designed for all three at once (examples/multi-model/multi-model.toml) must stabilise
each of them.

Development-time only (hinfix and its tests never run Python):

    python3 examples/multi-model/make_plants.py     (numpy)
"""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
import he1 as HE1  # noqa: E402  (examples/he1.py)

DELTAS = (-0.2, 0.0, 0.2)


def main():
    he1, mats = HE1.load()
    n = mats["A"].shape[0]
    r = np.round(np.random.default_rng(1).uniform(-1.0, 1.0, size=(n, n)), 2)
    for j, delta in enumerate(DELTAS, start=1):
        a = mats["A"] * (1.0 + delta * r)
        path = HE1.write(
            HERE,
            f"HE1_op{j}",
            f"COMPleib HE1 at operating point {j} of 3: A ∘ (1 + {delta:+.1f}·R)",
            f"A perturbed entrywise by {delta:+.1f}·R",
            "examples/multi-model/make_plants.py",
            f"A_j = A ∘ (1 + δ_j R) with δ_j = {delta:+.1f} and R = {r.tolist()}; B, C, D are HE1's.",
            he1,
            {**mats, "A": a},
        )
        print(f"wrote {path}: spectral abscissa {max(np.linalg.eigvals(a).real):+.6f}")


if __name__ == "__main__":
    main()
