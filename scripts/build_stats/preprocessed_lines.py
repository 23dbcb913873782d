#!/usr/bin/env python3
"""Preprocessed size of every C++ translation unit of a build (`g++ -E -fdirectives-only` over
compile_commands.json).

    python3 scripts/build_stats/preprocessed_lines.py build/compile_commands.json \
        [--jobs N] [--json out.json] [--reach HEADER_SUBSTRING ...]

prints the number of translation units, the total and mean preprocessed lines, and for each
--reach substring (e.g. `eigen3/Eigen`, `effects/types/fog_params.h`) how many translation units
include a file whose path contains it (= how many objects an edit of that header recompiles).
--json writes one record per translation unit: file, lines, the headers it reaches.

CUDA entries (nvcc) are skipped. Standard library only; each command is run without a shell.
"""

import argparse
import concurrent.futures
import json
import os
import re
import shlex
import subprocess
import sys

_MARKER = re.compile(rb'^# \d+ "([^"]+)"', re.M)


def preprocess_command(entry):
    """the entry's compile command turned into `-E -fdirectives-only` to stdout (no -c, -o, depfile
    flags): #include and #if are handled, macros are not expanded (a third of plain -E's CPU time;
    about 1.3x its lines, since #define lines and comments stay)."""
    args = entry.get("arguments") or shlex.split(entry["command"])
    out = []
    skip = False
    for a in args:
        if skip:
            skip = False
            continue
        if a in ("-o", "-MT", "-MF", "-MQ"):
            skip = True
            continue
        if a in ("-c", "-MD", "-MMD"):
            continue
        out.append(a)
    return out + ["-E", "-fdirectives-only"]


def is_cxx(entry):
    args = entry.get("arguments") or shlex.split(entry["command"])
    return not any("nvcc" in os.path.basename(a) for a in args[:2]) and not entry["file"].endswith(
        ".cu")


def measure(entry, headers=True):
    """one translation unit: its file, output, preprocessed line count and (with headers) the
    sorted files its line markers name. The regex over the whole output costs 8-15 % of the
    `g++ -E` time, so callers that need only the counts (the budget check) pass headers=False."""
    cmd = preprocess_command(entry)
    proc = subprocess.run(cmd, cwd=entry["directory"], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, check=False)
    mode = "-fdirectives-only"
    if proc.returncode != 0 and b"-fdirectives-only" in proc.stderr:
        # a header that needs macros expanded inside a directive (Google Benchmark's
        # `#if ... __COUNTER__ ...`, in the bench/ units): that unit alone with plain -E
        mode = "-E"
        proc = subprocess.run(cmd[:-1], cwd=entry["directory"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, check=False)
    if proc.returncode != 0:
        raise RuntimeError("%s: g++ -E failed: %s" % (entry["file"],
                                                      proc.stderr.decode(errors="replace")[:400]))
    text = proc.stdout
    record = {"file": entry["file"], "output": entry.get("output", ""),
              "lines": text.count(b"\n"), "mode": mode}
    if headers:
        record["headers"] = sorted({m.decode(errors="replace") for m in _MARKER.findall(text)
                                    if not m.startswith(b"<")})
    return record


def run(compile_commands, jobs, headers=True):
    """measure() over every C++ entry of compile_commands.json, `jobs` at a time."""
    with open(compile_commands, encoding="utf-8") as f:
        entries = [e for e in json.load(f) if is_cxx(e)]
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(lambda e: measure(e, headers), entries))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("compile_commands")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--json")
    ap.add_argument("--reach", nargs="*", default=[])
    a = ap.parse_args()
    records = run(a.compile_commands, a.jobs, headers=bool(a.reach or a.json))
    total = sum(r["lines"] for r in records)
    n = len(records)
    print("translation units: %d" % n)
    print("preprocessed lines: total %d, mean %.0f" % (total, total / n if n else 0))
    for sub in a.reach:
        k = sum(1 for r in records if any(sub in h for h in r["headers"]))
        print("reach %s: %d of %d translation units" % (sub, k, n))
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(records, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
