#!/usr/bin/env python3
"""Render speed across builds of different commits (docs/performance.md,
"The bisect: where the default room's frames went").

Each entry is LABEL=BINARY=WORLD: a `penumbra` binary and the world file of the same commit (an
old binary reads the world files and models of its own tree: `git archive COMMIT | tar -x -C
DIR`). Every round runs every binary's `bench render --world WORLD --no-adversity` twice, with
--frames LO and --frames HI, in a rotated order (so that load drifting on a shared machine hits
all alike), and takes from the two runs:

  - the 640x480 line's frames/s of the HI run (wall clock: follows the machine's load);
  - the CPU time per timed frame, (CPU(HI) - CPU(LO)) / (HI - LO), from the child's rusage
    (user + system, all threads): start-up, scene build and the warm-up frames cancel, and it
    needs nothing printed by the binary, so binaries older than the bench's cpu-ms field can be
    compared. Every bench binary renders each timed frame at 640x480 and at 800x800 (no
    --only-640x480, which old binaries lack), so this is the CPU time of one such pair.

Prints one Markdown row per entry: median (min-max) over the rounds and the ratios against the
first entry (per round, then median and min-max). Timings only: nothing passes or fails.

  scripts/perf-history.py --rounds 3 \\
      915f9fc=/tmp/bis/penumbra-915f9fc=/tmp/bis/src-915f9fc/worlds/default.yaml \\
      main=build/penumbra=worlds/default.yaml
"""
import argparse
import os
import re
import statistics
import sys
import time

LINE = re.compile(r"^640x480 rgb\+depth \S+: ([0-9.]+) frames/s")


def run_with_usage(binary, world, frames):
    """(frames/s of the 640x480 line, CPU seconds of exactly this child: os.wait4 on its pid)
    of one bench run; the command runs from an argument list, never through a shell."""
    args = [binary, "bench", "render", "--world", world, "--frames", str(frames), "--no-adversity"]
    read_fd, write_fd = os.pipe()
    pid = os.posix_spawn(binary, args, os.environ,
                         file_actions=[(os.POSIX_SPAWN_DUP2, write_fd, 1),
                                       (os.POSIX_SPAWN_DUP2, write_fd, 2),
                                       (os.POSIX_SPAWN_CLOSE, read_fd)])
    os.close(write_fd)
    chunks = []
    with os.fdopen(read_fd, "rb") as r:
        for chunk in iter(lambda: r.read(65536), b""):
            chunks.append(chunk)
    _, status, usage = os.wait4(pid, 0)
    code = os.waitstatus_to_exitcode(status)
    out = b"".join(chunks).decode(errors="replace")
    if code != 0:
        raise RuntimeError(f"{' '.join(args)} exited {code}:\n{out}")
    fps = None
    for line in out.splitlines():
        m = LINE.match(line.strip())
        if m:
            fps = float(m.group(1))
    if fps is None:
        raise RuntimeError(f"{' '.join(args)}: no '640x480 rgb+depth ...: N frames/s' line:\n{out}")
    return fps, usage.ru_utime + usage.ru_stime


def stats(values):
    return statistics.median(values), min(values), max(values)


def fmt(values, digits):
    m, lo, hi = stats(values)
    return f"{m:.{digits}f} ({lo:.{digits}f}-{hi:.{digits}f})"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("entries", nargs="+", help="LABEL=BINARY=WORLD (the first is the reference)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--frames-lo", type=int, default=4)
    parser.add_argument("--frames-hi", type=int, default=16)
    a = parser.parse_args()
    if a.rounds < 1 or not 1 <= a.frames_lo < a.frames_hi:
        parser.error("expected --rounds >= 1 and 1 <= --frames-lo < --frames-hi")
    entries = []
    for e in a.entries:
        parts = e.split("=")
        if len(parts) != 3 or not all(parts):
            parser.error(f"'{e}': expected LABEL=BINARY=WORLD")
        label, binary, world = parts
        if not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
            parser.error(f"'{binary}' is not an executable file")
        if not os.path.isfile(world):
            parser.error(f"'{world}' is not a file")
        entries.append((label, binary, world))

    fps = {label: [] for label, _, _ in entries}
    cpu = {label: [] for label, _, _ in entries}
    with open("/proc/loadavg") as f:
        load_start = " ".join(f.read().split()[:3])
    print(f"perf-history: bench render --no-adversity, --frames {a.frames_lo} and {a.frames_hi}, "
          f"{a.rounds} rounds, {os.cpu_count()} core(s), load {load_start}", flush=True)
    for r in range(a.rounds):
        order = entries[r % len(entries):] + entries[:r % len(entries)]
        for label, binary, world in order:
            _, c_lo = run_with_usage(binary, world, a.frames_lo)
            f_hi, c_hi = run_with_usage(binary, world, a.frames_hi)
            per = 1000.0 * (c_hi - c_lo) / (a.frames_hi - a.frames_lo)
            fps[label].append(f_hi)
            cpu[label].append(per)
            print(f"  round {r + 1} {label}: {f_hi:.1f} frames/s, {per:.1f} cpu-ms per frame pair",
                  file=sys.stderr, flush=True)
    with open("/proc/loadavg") as f:
        load_end = " ".join(f.read().split()[:3])
    ref = entries[0][0]
    print(f"load at the end {load_end}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    print()
    print(f"| build | 640x480 frames/s (wall) | ratio to {ref} | cpu-ms per 640x480 + 800x800 "
          f"frame | cpu ratio to {ref} |")
    print("|---|---|---|---|---|")
    for label, _, _ in entries:
        fr = [b / a_ if a_ > 0 else 0.0 for a_, b in zip(fps[ref], fps[label])]
        cr = [b / a_ if a_ > 0 else 0.0 for a_, b in zip(cpu[ref], cpu[label])]
        print(f"| {label} | {fmt(fps[label], 1)} | {fmt(fr, 3)} | {fmt(cpu[label], 1)} | "
              f"{fmt(cr, 3)} |")


if __name__ == "__main__":
    main()
