#!/usr/bin/env python3
"""Runs the command blocks of the README files that are marked to run, so that they cannot drift
from the program (the docs run verbatim). `.ci/run` calls it after the build.

A fenced block runs when the line before it (blank lines aside) is an HTML comment, invisible
on the rendered page:

    <!-- doc-run -->                              the block as written
    <!-- doc-run: "A" => "B"; "C" => "D" -->      with each literal text A replaced by B first
                                                  (small budgets: "--order 1" => "--order 1 --maxevals 300")

`sh` blocks run with bash (`set -euo pipefail`) in the repository root with target/release on
PATH (as the README says to put `campaign` there), `python` blocks with the interpreter given by
--python (skipped without it). Every block must exit 0. Nothing is written outside results/ and
scratch/, both ignored by git; the script checks that `git status` is unchanged afterwards.

    python3 scripts/doc_run.py [--python .venv/bin/python] [--list] [FILE.md ...]
"""
import argparse
import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_FILES = ("README.md", "python/README.md")
MARKER = re.compile(r"^<!--\s*doc-run(?::(.*?))?\s*-->\s*$")
REPLACEMENT = re.compile(r'"((?:[^"\\]|\\.)*)"\s*=>\s*"((?:[^"\\]|\\.)*)"')


def blocks(path):
    """(line number, language, text, replacements) of every marked fenced block of `path`."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    out, marker, i = [], None, 0
    while i < len(lines):
        line = lines[i]
        m = MARKER.match(line.strip())
        if m:
            rules = m.group(1) or ""
            marker = [(a.replace('\\"', '"'), b.replace('\\"', '"')) for a, b in REPLACEMENT.findall(rules)]
            if rules.strip() and not marker:
                sys.exit(f"{path}:{i + 1}: cannot read the replacements of {line.strip()!r}")
        elif line.startswith("```") and marker is not None:
            lang = line[3:].strip()
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            text = "\n".join(lines[i + 1:j])
            for a, b in marker:
                if a not in text:
                    sys.exit(f"{path}:{i + 1}: the replacement {a!r} matches nothing in its block")
                text = text.replace(a, b)
            out.append((i + 1, lang, text, marker))
            marker, i = None, j
        elif line.strip():
            marker = None
        i += 1
    return out


def git_status():
    return subprocess.run(["git", "status", "--porcelain", "--untracked-files=all"], cwd=ROOT,
                          capture_output=True, text=True, check=True).stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="*", default=DEFAULT_FILES)
    ap.add_argument("--python", help="interpreter for the python blocks (with hinfix installed)")
    ap.add_argument("--list", action="store_true", help="only list the blocks that would run")
    args = ap.parse_args()
    env = dict(os.environ, PATH=os.path.join(ROOT, "target", "release") + os.pathsep + os.environ["PATH"])
    before = git_status()
    failed = 0
    for md in args.files:
        for line, lang, text, _ in blocks(os.path.join(ROOT, md)):
            where = f"{md}:{line} ({lang})"
            if args.list:
                print(f"--- {where}\n{text}")
                continue
            if lang == "sh":
                cmd = ["bash", "-c", "set -euo pipefail\n" + text]
            elif lang == "python":
                if not args.python:
                    print(f"skip {where}: no --python")
                    continue
                cmd = [args.python, "-c", text]
            else:
                sys.exit(f"{where}: a marked block must be sh or python")
            t0 = time.monotonic()
            r = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
            dt = time.monotonic() - t0
            if r.returncode == 0:
                print(f"ok   {where} in {dt:.1f} s")
            else:
                failed += 1
                print(f"FAIL {where} (exit {r.returncode}) in {dt:.1f} s\n{text}\n--- stdout\n{r.stdout}"
                      f"--- stderr\n{r.stderr}")
    if not args.list and git_status() != before:
        print("FAIL: the blocks changed the working tree (git status):\n" + git_status())
        failed += 1
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
