#!/usr/bin/env python3
"""Compare the two sides of results/budget-comparison (same head jobs, stall rule vs spending
the whole 300-s budget) as a Markdown table: per (plant, order, seed) γ and CPU seconds of each;
then, if the quarter-budget run (budget-quarter/) is there, each protocol entry's best γ at a
quarter of the per-run budget against the paper's value and the full protocol's best.

    python3 scripts/budget_comparison.py results/budget-comparison [results/strong-stab]
"""
import csv
import json
import os
import sys


def jobs(path):
    out = {}
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.strip():
                    r = json.loads(line)
                    out[(r["plant"], r["order"], r["seed"])] = r
    return out


def rows(path):
    with open(path, encoding="utf-8") as f:
        return {(r["plant"], int(r["order"])): r for r in csv.DictReader(f)}


def quarter(root, full_root):
    """The quarter-budget table: per entry, paper, full protocol, quarter budget, ratio."""
    q_dir = os.path.join(root, "budget-quarter")
    if not os.path.exists(os.path.join(q_dir, "compare.csv")):
        return
    q = rows(os.path.join(q_dir, "compare.csv"))
    full = rows(os.path.join(full_root, "compare.csv"))
    with open(os.path.join(q_dir, "runs.jsonl"), encoding="utf-8") as f:
        q_jobs = [json.loads(line) for line in f if line.strip()]
    print("\n| plant | n_K | paper | full protocol | quarter budget | quarter/paper |")
    print("|---|---:|---:|---:|---:|---:|")
    at_or_below = 0
    for key in sorted(q):
        r = q[key]
        paper = float(r["paper"])
        ours = float(r["ours"])
        ratio = ours / paper
        at_or_below += ratio <= 1 + 1e-3
        print(f"| {key[0]} | {key[1]} | {paper:.4g} | {float(full[key]['ours']):.4g} | {ours:.4g} | {ratio:.4f} |")
    cpu = sum(r["cpu_s"] for r in q_jobs)
    print(f"\nQuarter budget: {at_or_below} of {len(q)} entries at or below paper·(1 + 1e-3); "
          f"{len(q_jobs)} jobs, {cpu / 3600:.2f} CPU h.")


def main():
    root = sys.argv[1]
    full_root = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(os.path.abspath(root)), "strong-stab")
    stall = jobs(os.path.join(root, "budget-stall", "runs.jsonl"))
    spend = jobs(os.path.join(root, "budget-spend", "runs.jsonl"))
    print("| plant | n_K | seed | γ stall rule | CPU s | γ whole budget | CPU s | spend/stall |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for key in sorted(stall):
        a, b = stall[key], spend.get(key)
        row = [key[0], str(key[1]), str(key[2]), f"{a['gamma']:.6f}", f"{a['cpu_s']:.1f}"]
        if b is None:
            row += ["not run yet", "", ""]
        else:
            row += [f"{b['gamma']:.6f}", f"{b['cpu_s']:.1f}", f"{b['gamma'] / a['gamma']:.5f}"]
        print("| " + " | ".join(row) + " |")
    cpu_a = sum(r["cpu_s"] for r in stall.values())
    cpu_b = sum(r["cpu_s"] for r in spend.values())
    print(f"\nCPU: stall rule {cpu_a:.0f} s over {len(stall)} jobs; whole budget {cpu_b:.0f} s over {len(spend)} jobs.")
    quarter(root, full_root)


if __name__ == "__main__":
    main()
