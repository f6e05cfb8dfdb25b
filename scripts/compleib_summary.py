#!/usr/bin/env python3
"""The front-page summary of a COMPleib run (results/compleib/README.md), as Markdown.

Reads what `campaign report` wrote into a results folder (standard library only): best.csv (best
re-verified γ per plant, order and objective), strong_vs_plain.csv (γ_strong/γ_plain per plant and
order) and compare.csv (the full-order γ beside each entry), and the journal(s) for the jobs and
CPU hours. It prints how many entries have a re-verified controller, which do not, and the
distribution of the cost of strong stabilisation, γ_strong/γ_plain. The numbers are the report's;
this only counts them.

    python3 scripts/compleib_summary.py results/compleib [--expected 1928]
"""
import argparse
import collections
import csv
import math
import os
import statistics

from protocol_progress import records


def read_csv(folder, name):
    with open(os.path.join(folder, name), newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def number(text):
    try:
        v = float(text)
    except (TypeError, ValueError):
        return math.nan
    return v


def journal(folder):
    """Jobs and CPU seconds of the folder's journals."""
    jobs, cpu = 0, 0.0
    for r in records(folder):
        jobs += 1
        cpu += r.get("cpu_s") or 0.0
    return jobs, cpu


# Bins of γ_strong/γ_plain: (upper bound, label); the first is "the same" up to the norm's
# tolerance and the search's rounding.
BINS = [(1 + 1e-6, "1 (within 1e-6)"), (1.01, "1 to 1.01"), (1.1, "1.01 to 1.1"), (2.0, "1.1 to 2"), (math.inf, "above 2")]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("--expected", type=int, help="the campaign's number of jobs")
    a = ap.parse_args()
    best = read_csv(a.folder, "best.csv")
    ratios = read_csv(a.folder, "strong_vs_plain.csv")
    jobs, cpu = journal(a.folder)

    plants = sorted({r["plant"] for r in best})
    by_obj = collections.defaultdict(list)
    for r in best:
        by_obj[r["objective"]].append(r)
    # A row has a re-verified controller when it has a job and a finite γ: its own jobs' or, through
    # the cross-objective rule (campaigns/FORMAT.md, best.csv), the other objective's.
    verified = lambda r: r["job_id"] != "" and math.isfinite(number(r["gamma"]))
    done = f"{jobs} of {a.expected}" if a.expected else f"{jobs}"
    print(f"- jobs journaled: {done} ({100 * jobs / a.expected:.1f} %), {cpu / 3600:.2f} CPU h"
          if a.expected else f"- jobs journaled: {done}, {cpu / 3600:.2f} CPU h")
    print(f"- entries (plant, n_K, objective): {len(best)} over {len(plants)} plants; "
          f"with a re-verified controller: {sum(verified(r) for r in best)}")
    for obj in ("plain", "strong"):
        rows = by_obj.get(obj, [])
        ok = [r for r in rows if verified(r)]
        stab_plants = {r["plant"] for r in ok}
        all_plants = {r["plant"] for r in rows}
        print(f"  - {obj}: {len(ok)} of {len(rows)} entries; {len(stab_plants)} of {len(all_plants)} plants "
              f"stabilised at some order")
        missing = collections.defaultdict(list)
        for r in rows:
            if not verified(r):
                missing[r["plant"]].append(int(r["order"]))
        if missing:
            text = "; ".join(f"{p} n_K = {', '.join(map(str, sorted(ks)))}" for p, ks in sorted(missing.items()))
            print(f"    not stabilised (jobs ran, none re-verified): {text}")
    vals = []
    for r in ratios:
        q = number(r["ratio"])
        if math.isfinite(q):
            vals.append((q, r["plant"], int(r["order"])))
    if vals:
        print(f"- cost of strong stabilisation, γ_strong/γ_plain over the {len(vals)} (plant, n_K) with both:")
        lo = 0.0
        for hi, label in BINS:
            n = sum(lo < q <= hi if lo > 0 else q <= hi for q, _, _ in vals)
            print(f"  - {label}: {n}")
            lo = hi
        qs = sorted(q for q, _, _ in vals)
        top = max(vals)
        print(f"  - median {statistics.median(qs):.4g}; 90th percentile {qs[int(0.9 * (len(qs) - 1))]:.4g}; "
              f"largest {top[0]:.3g} ({top[1]} n_K = {top[2]})")


if __name__ == "__main__":
    main()
