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
import json
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
NAMES = ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22")
DELTAS = (-0.2, 0.0, 0.2)


def main():
    he1 = json.load(open(os.path.join(ROOT, "plants", "HE1.json")))
    mats = {k: np.array(he1[k], dtype=float).reshape(len(he1[k]), -1) for k in NAMES}
    n = mats["A"].shape[0]
    r = np.round(np.random.default_rng(1).uniform(-1.0, 1.0, size=(n, n)), 2)
    for j, delta in enumerate(DELTAS, start=1):
        a = mats["A"] * (1.0 + delta * r)
        doc = {
            "name": f"HE1_op{j}",
            "description": f"COMPleib HE1 at operating point {j} of 3: A ∘ (1 + {delta:+.1f}·R)",
            "source": {
                "citation": he1["source"]["citation"] + f"; A perturbed entrywise by {delta:+.1f}·R",
                "script": "examples/multi-model/make_plants.py",
            },
            "notes": f"A_j = A ∘ (1 + δ_j R) with δ_j = {delta:+.1f} and R = {r.tolist()}; B, C, D are HE1's.",
            "dims": he1["dims"],
            "A": a.tolist(),
        }
        for k in NAMES[1:]:
            doc[k] = mats[k].tolist()
        path = os.path.join(HERE, f"HE1_op{j}.json")
        with open(path, "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")
        print(f"wrote {path}: spectral abscissa {max(np.linalg.eigvals(a).real):+.6f}")


if __name__ == "__main__":
    main()
