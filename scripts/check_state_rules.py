#!/usr/bin/env python3
"""Checks two rules that keep one vocabulary for the simulation state and for what
a controller accepts (the build helper's checks live in their own script):

  - state-fields: MuJoCo's state arrays are named in one table. `qacc_warmstart` (the one
    state field nothing but the state table has a reason to name) may appear in at most
    MAX_STATE_FIELD_FILES files of src/penumbra: scene/sim_state.h (SimState and its field
    table) and physics/mujoco_state.cc (the switch from a field to its mjData array). A third
    file means a field-by-field copy came back: loop over kStateFields instead.
  - controller-casts: no `dynamic_cast` to a concrete controller class (a class of
    src/penumbra/control/ deriving from `Controller`) outside src/penumbra/control/: ask for
    a capability (control/controller_capabilities.h: AsTwistTarget, AsWaypointTarget,
    AsJointTarget, ...) instead.

Each problem is printed as `file:line: rule: message`.

  python3 scripts/check_state_rules.py            # check this repository
  python3 scripts/check_state_rules.py --root DIR # check DIR/src/penumbra

Standard library only. Exit status: 0 clean, 1 problems found, 2 bad usage.
"""

import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_EXTS = (".h", ".hh", ".hpp", ".cc", ".cpp", ".cxx", ".inl", ".inc", ".ipp", ".cu", ".cuh")
STATE_FIELD = "qacc_warmstart"
MAX_STATE_FIELD_FILES = 2
CONTROL_DIR = "control"
# `class Name final : public Controller` or `class Name : public Other, public Controller`
CONTROLLER_CLASS_RE = re.compile(
    r"\bclass\s+([A-Za-z_]\w*)\s*(?:final\s*)?:\s*([^{;]*)\{", re.MULTILINE)
DYNAMIC_CAST_RE = re.compile(r"\bdynamic_cast\s*<\s*(?:const\s+)?(?:penumbra::)?([A-Za-z_]\w*)")


def source_files(src):
    """(path relative to src, absolute path) of every source file under src, sorted."""
    out = []
    for dirpath, dirnames, filenames in os.walk(src):
        dirnames.sort()
        for name in sorted(filenames):
            if name.endswith(SOURCE_EXTS):
                full = os.path.join(dirpath, name)
                out.append((os.path.relpath(full, src).replace(os.sep, "/"), full))
    return out


def read(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


def check_state_fields(files):
    """Problems of the state-fields rule."""
    hits = []
    for rel, full in files:
        for number, line in enumerate(read(full).splitlines(), 1):
            if STATE_FIELD in line:
                hits.append((rel, number))
                break
    if len(hits) <= MAX_STATE_FIELD_FILES:
        return []
    return [f"src/penumbra/{rel}:{number}: state-fields: '{STATE_FIELD}' named here, file {k} of "
            f"{len(hits)}; expected at most {MAX_STATE_FIELD_FILES} (scene/sim_state.h, "
            f"physics/mujoco_state.cc): loop over kStateFields (scene/sim_state.h) instead of "
            f"naming the fields" for k, (rel, number) in enumerate(hits, 1)]


def concrete_controllers(files):
    """Names of the classes of control/ that derive, directly or not, from Controller."""
    bases = {}
    for rel, full in files:
        if not rel.startswith(CONTROL_DIR + "/"):
            continue
        for m in CONTROLLER_CLASS_RE.finditer(read(full)):
            names = re.findall(r"(?:public|protected|private)?\s*(?:penumbra::)?([A-Za-z_]\w*)",
                               m.group(2))
            bases[m.group(1)] = {n for n in names if n not in ("public", "protected", "private")}
    derived = {"Controller"}
    changed = True
    while changed:
        changed = False
        for name, parents in bases.items():
            if name not in derived and parents & derived:
                derived.add(name)
                changed = True
    derived.discard("Controller")
    return derived


def check_controller_casts(files):
    """Problems of the controller-casts rule."""
    concrete = concrete_controllers(files)
    problems = []
    for rel, full in files:
        if rel.startswith(CONTROL_DIR + "/"):
            continue
        for number, line in enumerate(read(full).splitlines(), 1):
            for m in DYNAMIC_CAST_RE.finditer(line):
                if m.group(1) in concrete:
                    problems.append(
                        f"src/penumbra/{rel}:{number}: controller-casts: dynamic_cast to the "
                        f"concrete controller {m.group(1)} outside control/; ask for its "
                        f"capability instead (control/controller_capabilities.h: AsTwistTarget, "
                        f"AsWaypointTarget, AsJointTarget, AsTerrainRayCasterUser)")
    return problems


def check(root):
    src = os.path.join(root, "src", "penumbra")
    if not os.path.isdir(src):
        raise FileNotFoundError(f"{src}: no such folder; expected --root to hold src/penumbra")
    files = source_files(src)
    return check_state_fields(files) + check_controller_casts(files)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=ROOT, help="the repository root (default: this one)")
    args = parser.parse_args(argv)
    try:
        problems = check(args.root)
    except FileNotFoundError as e:
        print(f"check_state_rules: {e}", file=sys.stderr)
        return 2
    for p in problems:
        print(p)
    if problems:
        print(f"check_state_rules: {len(problems)} problem(s)")
        return 1
    print("check_state_rules: OK: state fields named in the state table only, no dynamic_cast "
          "to a concrete controller outside control/")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
