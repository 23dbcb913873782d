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
                          "--fields=+sZSEt", "--extras=-q", f"--c++-kinds={KINDS}", "-o", "-",
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


def param_types(signature):
    """a ctags signature without parameter names and default arguments, so that two copies of a
    helper whose parameters are named differently (OctDecode(double u, double v) and
    OctDecode(double s, double t)) compare equal: "(double, double)"."""
    inner = signature.strip()
    if inner.startswith("(") and inner.endswith(")"):
        inner = inner[1:-1]
    params, depth, cur = [], 0, ""
    for ch in inner:
        if ch in "<([{":
            depth += 1
        elif ch in ">)]}":
            depth -= 1
        if ch == "," and depth == 0:
            params.append(cur)
            cur = ""
        else:
            cur += ch
    params.append(cur)
    out = []
    for p in params:
        p = p.split("=")[0].strip()
        # a trailing identifier after a type (and not the type's only word) is the name
        m = re.match(r"^(.*[\w>&*\]])\s*[&*]*\s*\b([A-Za-z_]\w*)$", p)
        if m and re.search(r"[\w>]", m.group(1)) and m.group(1).strip() not in ("const",
                                                                              "unsigned",
                                                                              "signed", "long",
                                                                              "short"):
            p = p[:m.start(2)].strip()
        out.append(re.sub(r"\s+", " ", p))
    return "(" + ", ".join(x for x in out if x) + ")"


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
        aliased = collections.defaultdict(set)  # what each file-local alias names
        for path in files:
            for t in tags(path):
                if not file_local(t):
                    continue
                scope = re.sub(r"__anon\w+", "<anon>", t.get("scope", ""))
                sig = param_types(t.get("signature", "")) if t["kind"] in ("function",) else ""
                seen[(scope, t["name"], sig, t["kind"])].add(path)
                if t["kind"] == "typedef":
                    aliased[(scope, t["name"])].add(t.get("typeref", path))
        for (scope, name, sig, kind), paths in sorted(seen.items()):
            # the same alias of the same type twice is a valid redeclaration (using Clock = ...)
            same_alias = kind == "typedef" and len(aliased[(scope, name)]) == 1
            if len(paths) > 1 and not same_alias:
                clashes += 1
                batch = os.path.relpath(unity, build)
                print(f"{batch}: {kind} {scope}::{name}{sig} in "
                      + ", ".join(sorted(os.path.relpath(p) for p in paths)))
    return 1 if clashes else 0


if __name__ == "__main__":
    sys.exit(main())
