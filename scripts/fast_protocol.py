#!/usr/bin/env python3
"""The fast protocol (results/strong-stab-fast) against the paper and the full protocol
(results/strong-stab), as a Markdown table for results/strong-stab-fast/README.md: per entry
(plant, order) the paper's HIFOO value, the full protocol's best γ, the fast run's, and the
ratios fast/paper and fast/full; then the targets: entries at or below paper·(1 + 1e-3), within
2 % of the full run, and the rows whose γ rises with n_K (order k + 1 above order k by more
than RISE_RTOL = 1e-9 relative: γ is recomputed on the padded closed loop by an H∞ norm of
relative tolerance 1e-10, so a rise below that is the norm's rounding, not the search), each
counted over the entries the fast run has. Reads the compare.csv files `campaign report` writes.

    python3 scripts/fast_protocol.py results/strong-stab-fast results/strong-stab
"""
import csv
import os
import sys

RISE_RTOL = 1e-9


def rows(path):
    with open(path, encoding="utf-8") as f:
        return {(r["plant"], int(r["order"])): r for r in csv.DictReader(f) if r.get("objective", "strong") == "strong"}


def main(fast_root, full_root):
    fast = rows(os.path.join(fast_root, "compare.csv"))
    full = rows(os.path.join(full_root, "compare.csv"))
    print("| plant | n_K | paper | full protocol | fast | fast/paper | fast/full |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    at_paper = within = have = 0
    rises = []
    tiny = []
    for key in sorted(full):
        plant, order = key
        paper, best = float(full[key]["paper"]), float(full[key]["ours"])
        f = fast.get(key)
        g = float(f["ours"]) if f and f["ours"] not in ("", "nan", "NaN") else None
        if g is None:
            print(f"| {plant} | {order} | {paper:.4g} | {best:.4g} | — | — | — |")
            continue
        have += 1
        at_paper += g <= paper * (1 + 1e-3)
        within += g <= best * 1.02
        print(f"| {plant} | {order} | {paper:.4g} | {best:.4g} | {g:.4g} | {g / paper:.4f} | {g / best:.4f} |")
        below = fast.get((plant, order - 1))
        if below and below["ours"] not in ("", "nan", "NaN"):
            b = float(below["ours"])
            if g > b * (1 + RISE_RTOL):
                rises.append(f"{plant} n_K = {order} ({g:.6g} > {b:.6g})")
            elif g > b:
                tiny.append(g / b - 1)
    print(f"\nEntries run: {have} of {len(full)}. At or below the paper·(1 + 1e-3): {at_paper} of {have}. "
          f"Within 2 % of the full protocol: {within} of {have}.")
    print("γ rising with n_K by more than 1e-9 (relative): " + ("; ".join(rises) if rises else "none") + ".")
    if tiny:
        print(f"Rises below that (the norm's rounding): {len(tiny)}, the largest {max(tiny):.1e}.")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "results/strong-stab-fast",
         sys.argv[2] if len(sys.argv) > 2 else "results/strong-stab")
