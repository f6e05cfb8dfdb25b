#!/usr/bin/env python3
"""Compare the two sides of results/budget-comparison (same head jobs, stall rule vs spending
the whole 300-s budget) as a Markdown table: per (plant, order, seed) γ and CPU seconds of each.

    python3 scripts/budget_comparison.py results/budget-comparison
"""
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


def main():
    root = sys.argv[1]
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


if __name__ == "__main__":
    main()
