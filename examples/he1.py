"""COMPleib HE1 (plants/HE1.json) and the plant files the worked examples derive from it: the
`make_plants.py` of examples/discrete and of examples/multi-model import this (development-time
Python, numpy).
"""
import json
import os

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NAMES = ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22")


def load():
    """HE1's document and its matrices by name (2-D float arrays)."""
    he1 = json.load(open(os.path.join(ROOT, "plants", "HE1.json")))
    return he1, {k: np.array(he1[k], dtype=float).reshape(len(he1[k]), -1) for k in NAMES}


def write(folder, name, description, derivation, script, notes, he1, mats, ts=None):
    """Writes `folder/<name>.json` in the plant file format: HE1's dimensions with the matrices
    `mats` (all of NAMES), its citation followed by `derivation`, and `Ts` for a discrete-time
    plant. Returns the path."""
    doc = {
        "name": name,
        "description": description,
        "source": {"citation": he1["source"]["citation"] + "; " + derivation, "script": script},
        "notes": notes,
    }
    if ts is not None:
        doc["Ts"] = ts
    doc["dims"] = he1["dims"]
    for k in NAMES:
        doc[k] = mats[k].tolist()
    path = os.path.join(folder, f"{name}.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    return path
