#!/usr/bin/env python3
"""Runs bundled worlds and checks that their outputs are byte-identical.

Two uses:

  # record every bundled world at 1 and 2 render threads with one binary ...
  python3 scripts/compare_outputs.py record --binary build/penumbra --out /tmp/before
  # ... and with another (a later commit), then compare the two folders file by file
  python3 scripts/compare_outputs.py record --binary build/penumbra --out /tmp/after
  python3 scripts/compare_outputs.py compare /tmp/before /tmp/after

  # or both at once, for a subset: runs each world at 1 and 2 threads and compares them
  python3 scripts/compare_outputs.py check --binary build/penumbra --out /tmp/x \
      --worlds worlds/default.yaml worlds/effects/rain.yaml --duration 0.5

Compared: every file a run writes (PNG, CSV, PCD, camera_info, ...) except run.json (wall-clock
timings, command line), composed.xml (the model text; its layout may change while the model
it describes does not) and a generated environment's model text (environments/*.xml: it names
its height field by the run folder's absolute path; the .hfield data is compared). Exit status 0 when everything matches, 1 with a list of differences.
"""

import argparse
import filecmp
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKIPPED = {"run.json", "composed.xml"}


def bundled_worlds():
    worlds = []
    for sub in ("worlds", os.path.join("worlds", "effects")):
        folder = os.path.join(ROOT, sub)
        for name in sorted(os.listdir(folder)):
            if name.endswith(".yaml") and name != "presets.yaml":
                worlds.append(os.path.join(sub, name))
    return worlds


def world_key(world):
    rel = os.path.relpath(os.path.abspath(world), ROOT)
    return rel[:-len(".yaml")].replace(os.sep, "__")


def run_world(binary, world, out, threads, duration, outputs):
    cmd = [binary, "run", world, "--out", out, "--force", "--threads", str(threads), "-q"]
    if duration is not None:
        cmd += ["--duration", str(duration)]
    if outputs:
        cmd += ["--outputs", outputs]
    t0 = time.monotonic()
    proc = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True)
    if proc.returncode != 0:
        sys.exit(f"{' '.join(cmd)} exited {proc.returncode}:\n{proc.stdout}")
    return time.monotonic() - t0


def record(binary, out_root, worlds, threads_list, duration, outputs):
    for world in worlds:
        for threads in threads_list:
            out = os.path.join(out_root, world_key(world), f"t{threads}")
            sec = run_world(binary, world, out, threads, duration, outputs)
            print(f"{world} threads={threads}: {count_files(out)} files, {sec:.1f} s", flush=True)


def count_files(folder):
    return sum(len(files) for _, _, files in os.walk(folder))


def listing(folder):
    files = set()
    for root, _, names in os.walk(folder):
        for n in names:
            rel = os.path.relpath(os.path.join(root, n), folder)
            # a generated environment's model text names its height field by the run's absolute
            # path (and its file name hashes that text); the height field itself is compared.
            generated_model = rel.startswith("environments" + os.sep) and n.endswith(".xml")
            if n not in SKIPPED and not generated_model:
                files.add(rel)
    return files


def compare_folders(a, b, label):
    """returns a list of differences between two run folders."""
    la, lb = listing(a), listing(b)
    problems = [f"{label}: only in {a}: {p}" for p in sorted(la - lb)]
    problems += [f"{label}: only in {b}: {p}" for p in sorted(lb - la)]
    for p in sorted(la & lb):
        if not filecmp.cmp(os.path.join(a, p), os.path.join(b, p), shallow=False):
            problems.append(f"{label}: differs: {p}")
    if not la:
        problems.append(f"{label}: {a} holds no outputs")
    return problems, len(la & lb)


def compare(a_root, b_root):
    problems, files = [], 0
    for key in sorted(os.listdir(a_root)):
        for t in sorted(os.listdir(os.path.join(a_root, key))):
            pa, pb = os.path.join(a_root, key, t), os.path.join(b_root, key, t)
            if not os.path.isdir(pb):
                problems.append(f"{key}/{t}: missing in {b_root}")
                continue
            p, n = compare_folders(pa, pb, f"{key}/{t}")
            problems += p
            files += n
    return problems, files


def threads_agree(root):
    """every world's t1 and t2 outputs must match each other."""
    problems, files = [], 0
    for key in sorted(os.listdir(root)):
        runs = sorted(os.listdir(os.path.join(root, key)))
        for other in runs[1:]:
            p, n = compare_folders(os.path.join(root, key, runs[0]),
                                   os.path.join(root, key, other), f"{key} {runs[0]} vs {other}")
            problems += p
            files += n
    return problems, files


def report(problems, files, what):
    if problems:
        print("\n".join(problems[:200]))
        print(f"{len(problems)} difference(s) ({what})")
        return 1
    print(f"identical: {files} files ({what})")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="verb", required=True)
    for verb in ("record", "check"):
        p = sub.add_parser(verb)
        p.add_argument("--binary", default=os.path.join(ROOT, "build", "penumbra"))
        p.add_argument("--out", required=True, help="folder for the runs' outputs")
        p.add_argument("--worlds", nargs="*", help="world files (default: every bundled world)")
        p.add_argument("--threads", default="1,2", help="render thread counts, comma-separated")
        p.add_argument("--duration", type=float, default=1.5, help="sim seconds per run")
        p.add_argument("--outputs", help="--outputs of every run (default: each world's own)")
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    args = ap.parse_args()

    if args.verb == "compare":
        p, n = compare(args.a, args.b)
        return report(p, n, f"{args.a} vs {args.b}")
    worlds = args.worlds or bundled_worlds()
    threads = [int(t) for t in args.threads.split(",")]
    record(os.path.abspath(args.binary), os.path.abspath(args.out), worlds, threads,
           args.duration, args.outputs)
    p, n = threads_agree(os.path.abspath(args.out))
    return report(p, n, "thread counts agree")


if __name__ == "__main__":
    sys.exit(main())
