#!/usr/bin/env python3
"""Provenance and progress of a campaign's journals, for results/<name>/README.md.

Reads every runs*.jsonl of a results folder (standard library only) and prints, as Markdown:
the builds (git commits), hosts, threads and CPU models that ran its jobs; the jobs journaled;
CPU hours (sum of the jobs' thread CPU seconds) and the wall-clock span of the sittings; and per
plant the jobs, CPU hours and how the jobs stopped. The tables themselves come from
`campaign report`; this only says where and at what cost the journals were made.

    python3 scripts/protocol_progress.py results/strong-stab [--expected 2850] [--compare]

With --compare it also prints the folder's compare.csv (written by `campaign report`) as a
Markdown table: per plant and order, ours, the paper's HIFOO value and their ratio.
"""
import csv
import math
import argparse
import collections
import glob
import json
import os


def records(folder):
    for path in sorted(glob.glob(os.path.join(folder, "runs*.jsonl"))):
        with open(path, encoding="utf-8") as f:
            for line in f:
                line = line.strip()
                if line:
                    yield json.loads(line)


def sittings(ends, gap=600.0):
    """Wall-clock spans of runs: finish times further apart than `gap` seconds start a new one."""
    spans = []
    for t in sorted(ends):
        if spans and t - spans[-1][1] <= gap:
            spans[-1][1] = t
        else:
            spans.append([t, t])
    return spans


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("--expected", type=int, help="jobs the campaign expands to")
    ap.add_argument("--compare", action="store_true", help="also print compare.csv as Markdown")
    a = ap.parse_args()
    recs = list(records(a.folder))
    by_id = {}
    for r in recs:
        by_id.setdefault(r["job_id"], r)
    jobs = list(by_id.values())
    cpu = sum(float(r["cpu_s"]) for r in jobs)
    prov = collections.Counter()
    for r in jobs:
        p = r.get("provenance") or {}
        prov[(p.get("git_commit", "?")[:12], p.get("host", "?"), p.get("threads", "?"), p.get("cpu_model", "?"))] += 1
    # a job's wall span starts wall_s before it finished
    starts = [float(r["finished_unix_s"]) - float(r["wall_s"]) for r in jobs]
    ends = [float(r["finished_unix_s"]) for r in jobs]
    spans = sittings(starts + ends)
    wall = sum(b - a for a, b in spans)
    done = f"{len(jobs)}" + (f" of {a.expected}" if a.expected else "")
    print(f"- jobs journaled: {done} ({len(recs) - len(jobs)} duplicate records)")
    print(f"- CPU: {cpu / 3600:.2f} CPU hours (sum of the jobs' thread CPU seconds)")
    print(f"- wall clock: {wall / 3600:.2f} h in {len(spans)} sitting(s)")
    print("- builds and machines (commit, host, worker threads, CPU model: jobs):")
    for (commit, host, threads, model), n in sorted(prov.items()):
        print(f"  - `{commit}` on {host}, {threads} threads, {model}: {n}")
    print()
    print("| plant | jobs | CPU h | mean CPU s/job | stops |")
    print("|---|---:|---:|---:|---|")
    per = collections.defaultdict(list)
    for r in jobs:
        per[r["plant"]].append(r)
    for plant, rs in per.items():
        c = sum(float(r["cpu_s"]) for r in rs)
        stops = collections.Counter((r.get("search") or {}).get("stop", r["status"]["kind"]) for r in rs)
        s = ", ".join(f"{k} {v}" for k, v in sorted(stops.items()))
        print(f"| {plant} | {len(rs)} | {c / 3600:.2f} | {c / len(rs):.1f} | {s} |")
    if a.compare:
        print()
        print("| plant | n_K | ours | paper (HIFOO) | ours/paper |")
        print("|---|---:|---:|---:|---:|")
        with open(os.path.join(a.folder, "compare.csv"), encoding="utf-8") as f:
            for row in csv.DictReader(f):
                def num(key, fmt):
                    try:
                        x = float(row[key])
                    except ValueError:
                        return "–"
                    return fmt.format(x) if math.isfinite(x) else "–"
                ours, paper, ratio = num("ours", "{:#.4g}"), num("paper", "{:#.4g}"), num("ratio", "{:.4f}")
                print(f"| {row['plant']} | {row['order']} | {ours} | {paper} | {ratio} |")


if __name__ == "__main__":
    main()
