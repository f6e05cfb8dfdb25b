"""Campaigns from Python: run a campaign file, read a results folder into lists and numpy arrays
for plotting (pandas optional: ``Results.to_pandas()``)."""
from __future__ import annotations

import csv
import math
import os
import warnings

import numpy as np

from . import _hinfix
from ._json import loads

def run_campaign(path: str | os.PathLike, results: str | os.PathLike | None = None, *, threads: int | None = None,
                 progress: bool = False) -> dict:
    """Runs the campaign file ``path`` as ``campaign run PATH --results RESULTS`` does, into
    ``RESULTS/<campaign name>/`` (default results root: ``results``), resuming the jobs already
    journaled there, and writes the report files (best.csv, tables.tex, compare.csv/.tex).
    Returns a dict: ``dir`` (the campaign's folder), the job counts (``total``,
    ``already_done``, ``finished``, ``failed``, …) and ``best`` (the best verified γ per plant
    and order). Ctrl-C stops the run cleanly (finished jobs stay journaled; the same call
    resumes) and raises KeyboardInterrupt."""
    results = "results" if results is None else results
    if threads is not None and (isinstance(threads, bool) or not isinstance(threads, int) or threads < 1 or threads > 256):
        raise ValueError(f"run_campaign: threads must be a whole number in 1..=256, found {threads!r}")
    text = _hinfix.run_campaign(os.fspath(path), os.fspath(results), threads, bool(progress))
    return loads(text)


class Results:
    """The records of a results folder (every ``runs*.jsonl``), as plain Python data.

    ``records`` is a list of dicts, one per journal line, in the journal format
    (campaigns/FORMAT.md): ``plant``, ``order``, ``eps``, ``seed``, ``status`` ({"kind": …}),
    ``gamma``, ``k_hinf``, ``controller`` ({"AK", "BK", "CK", "DK"}), ``cpu_s``, ``options``, ….
    ``best`` is the report's ``best.csv`` as a list of dicts (empty if the folder has no report).
    """

    def __init__(self, folder: str, records: list[dict], best: list[dict]):
        self.folder = folder
        self.records = records
        self.best = best

    def __len__(self):
        return len(self.records)

    def columns(self, *keys: str) -> dict[str, np.ndarray]:
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
            numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) or v is None for v in vals)
            if numbers and vals and all(isinstance(v, int) for v in vals):
                out[k] = np.array(vals, dtype=np.int64)  # order, seed: integers stay integers
            elif numbers:
                out[k] = np.array([math.nan if v is None else v for v in vals], dtype=float)
            elif all(isinstance(v, bool) for v in vals):
                out[k] = np.array(vals, dtype=bool)
            else:
                out[k] = np.array(vals, dtype=object)
        return out

    def to_pandas(self, *keys: str) -> "pandas.DataFrame":  # noqa: F821
        """``columns(*keys)`` as a ``pandas.DataFrame`` (pandas must be installed; it is not a
        dependency of hinfix)."""
        try:
            import pandas
        except ImportError:
            raise ImportError("Results.to_pandas() needs pandas (pip install pandas); "
                              "Results.columns() gives the same columns as numpy arrays") from None
        return pandas.DataFrame(self.columns(*keys))

    def __repr__(self):
        return f"Results({self.folder!r}: {len(self.records)} records, {len(self.best)} best rows)"


def read_results(folder: str | os.PathLike) -> Results:
    """Reads the results folder ``folder`` of one campaign (``results/<campaign>``, not the
    results root ``results/``: that is a ValueError naming the campaign folders in it): every
    journal's records and, if the report was written, ``best.csv``. A torn last journal line
    (a run killed while writing) is left out with a ``UserWarning``, as ``campaign report``
    warns. Returns a ``Results``."""
    folder = os.fspath(folder)
    read = loads(_hinfix.read_results(folder))
    for w in read["warnings"]:
        warnings.warn(w, UserWarning, stacklevel=2)
    best = []
    best_csv = os.path.join(folder, "best.csv")
    if os.path.exists(best_csv) and not os.path.isfile(best_csv):
        raise ValueError(f"{best_csv} is not a file (`campaign report` writes it from the journal)")
    if os.path.isfile(best_csv):
        with open(best_csv, newline="") as f:
            reader = csv.DictReader(f)
            for row in reader:
                if None in row or None in row.values():  # more, or fewer, cells than the header
                    raise ValueError(f"{best_csv}: line {reader.line_num} does not have the header's "
                                     f"{len(reader.fieldnames)} cells: the file is damaged (`campaign report` "
                                     "writes it again from the journal)")
                cells = {k: _cell(v) for k, v in row.items()}
                for column, kinds in (("order", (int,)), ("gamma", (int, float))):
                    if column in cells and (isinstance(cells[column], bool) or not isinstance(cells[column], kinds)):
                        raise ValueError(f"{best_csv}: line {reader.line_num}, column {column}: "
                                         f"{row[column]!r} is not a number: the file is damaged "
                                         "(`campaign report` writes it again from the journal)")
                best.append(cells)
    return Results(folder, read["records"], best)


def _cell(text):
    """A CSV cell: a bool (``true``, ``false``, as ``run_campaign()["best"]`` gives them), an
    int, a float, or the text."""
    if text in ("true", "false"):
        return text == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text
