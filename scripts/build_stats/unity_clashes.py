#!/usr/bin/env python3
"""Names that clash in a unity batch: file-local definitions (anonymous namespace, `static` at
namespace scope, macros) that two files of one batch define with the same scope, name and
signature. Reads the batches CMake generated (<build>/CMakeFiles/*.dir/Unity/unity_*_cxx.cxx)
and Universal Ctags' tags of their files; a hit is a likely "redefinition" error, so rename one
side (give file-local helpers names unique in their module) before the compiler finds it.

    python3 scripts/build_stats/unity_clashes.py BUILD_DIR [--module-wide]

--module-wide checks all batches of a target together (names unique in the module, so that a
file added later, which shifts the batches, exposes no clash). exit 1 when a clash is found.
"""

import collections
import glob
import json
import os
import re
import subprocess
import sys

KINDS = "fvdtcsgeu"  # functions, variables, macros, typedefs, classes, structs, enums, unions


def tags(path):
    out = subprocess.run(["ctags", "--output-format=json", "--language-force=c++",
                          "--fields=+sZSE", "--extras=-q", f"--c++-kinds={KINDS}", "-o", "-",
                          path], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                         check=False).stdout
    for line in out.splitlines():
        try:
            yield json.loads(line)
        except ValueError:
            continue


def file_local(tag):
    scope = tag.get("scope", "")
    if tag["kind"] == "macro":
        return True
    if "__anon" in scope and tag.get("scopeKind") == "namespace":
        return True
    props = tag.get("properties", "")
    return "static" in props and tag.get("scopeKind") in (None, "namespace")


def main():
    build = sys.argv[1]
    module_wide = "--module-wide" in sys.argv[2:]
    groups = collections.defaultdict(list)
    for unity in sorted(glob.glob(os.path.join(build, "CMakeFiles", "*.dir", "Unity",
                                                "unity_*_cxx.cxx"))):
        with open(unity, encoding="utf-8") as f:
            files = re.findall(r'#include "([^"]+)"', f.read())
        key = os.path.dirname(os.path.dirname(unity)) if module_wide else unity
        groups[key] += files
    clashes = 0
    for unity, files in sorted(groups.items()):
        seen = collections.defaultdict(set)
        for path in files:
            for t in tags(path):
                if not file_local(t):
                    continue
                scope = re.sub(r"__anon\w+", "<anon>", t.get("scope", ""))
                sig = t.get("signature", "") if t["kind"] in ("function",) else ""
                seen[(scope, t["name"], sig, t["kind"])].add(path)
        for (scope, name, sig, kind), paths in sorted(seen.items()):
            if len(paths) > 1:
                clashes += 1
                batch = os.path.relpath(unity, build)
                print(f"{batch}: {kind} {scope}::{name}{sig} in "
                      + ", ".join(sorted(os.path.relpath(p) for p in paths)))
    return 1 if clashes else 0


if __name__ == "__main__":
    sys.exit(main())
