"""Campaigns from Python: run a campaign file, read a results folder into lists and numpy arrays
(no pandas) for plotting."""
import csv
import math
import os

import numpy as np

from . import _hinfix
from ._json import loads

def run_campaign(path, results=None, *, threads=None, progress=False):
    """Runs the campaign file ``path`` as ``campaign run PATH --results RESULTS`` does, into
    ``RESULTS/<campaign name>/`` (default results root: ``results``), resuming the jobs already
    journaled there, and writes the report files (best.csv, tables.tex, compare.csv/.tex).
    Returns a dict: ``dir`` (the campaign's folder), the job counts (``total``,
    ``already_done``, ``finished``, ``failed``, …) and ``best`` (the best verified γ per plant
    and order). Ctrl-C stops the run cleanly (finished jobs stay journaled; the same call
    resumes) and raises KeyboardInterrupt."""
    results = "results" if results is None else results
    text = _hinfix.run_campaign(os.fspath(path), os.fspath(results), threads, bool(progress))
    return loads(text)


class Results:
    """The records of a results folder (every ``runs*.jsonl``), as plain Python data.

    ``records`` is a list of dicts, one per journal line, in the journal format
    (campaigns/FORMAT.md): ``plant``, ``order``, ``eps``, ``seed``, ``status`` ({"kind": …}),
    ``gamma``, ``k_hinf``, ``controller`` ({"AK", "BK", "CK", "DK"}), ``cpu_s``, ``options``, ….
    ``best`` is the report's ``best.csv`` as a list of dicts (empty if the folder has no report).
    """

    def __init__(self, folder, records, best):
        self.folder = folder
        self.records = records
        self.best = best

    def __len__(self):
        return len(self.records)

    def columns(self, *keys):
        """Columns of the records as numpy arrays (float for numbers, NaN where a record has
        none, e.g. a failed job's γ; object arrays for text). Default keys: plant, order, eps,
        seed, status, gamma, k_hinf, alpha_cl, alpha_k, cpu_s."""
        keys = keys or ("plant", "order", "eps", "seed", "status", "gamma", "k_hinf", "alpha_cl",
                        "alpha_k", "cpu_s")
        out = {}
        for k in keys:
            vals = [r.get(k) for r in self.records]
            if k == "status":
                vals = [v["kind"] if isinstance(v, dict) else v for v in vals]
            if all(isinstance(v, (int, float)) or v is None for v in vals):
                out[k] = np.array([math.nan if v is None else v for v in vals], dtype=float)
            else:
                out[k] = np.array(vals, dtype=object)
        return out

    def __repr__(self):
        return f"Results({self.folder!r}: {len(self.records)} records, {len(self.best)} best rows)"


def read_results(folder):
    """Reads the results folder ``folder`` (``results/<campaign>``): every journal's records and,
    if the report was written, ``best.csv``. Returns a ``Results``."""
    folder = os.fspath(folder)
    records = loads(_hinfix.read_results(folder))
    best = []
    best_csv = os.path.join(folder, "best.csv")
    if os.path.isfile(best_csv):
        with open(best_csv, newline="") as f:
            best = [{k: _cell(v) for k, v in row.items()} for row in csv.DictReader(f)]
    return Results(folder, records, best)


def _cell(text):
    """A CSV cell: an int, a float, or the text."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text
