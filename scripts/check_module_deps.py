#!/usr/bin/env python3
"""Checks the module includes of src/penumbra against its dependency table.

src/penumbra/DEPENDENCIES has one line per module (a folder of src/penumbra; `main` is the files
directly in src/penumbra): `module: dep dep ...`, '#' starting a comment. CMake links each
module's penumbra_<dep> libraries from it. A sub-module is a sub-folder with a line of its own,
named by its path (`render/cpu`: src/penumbra/render/cpu/, library penumbra_render_cpu); its
files belong to it, not to the parent, and other sub-folders belong to the module above them.
This script fails (exit status 1) when

  - a file of module M includes "penumbra/D/..." and D is not on M's line (file:line and the
    edge are named; when the table already leads from D back to M, the cycle the include would
    close is printed too);
  - a module lists (or includes) one of its own sub-modules: the root of a module stays below
    its sub-modules (render/ includes neither render/cpu/ nor render/embree/);
  - a dep on M's line is included by no file of M (an unused edge: the table must equal the real
    includes). Lines of modules whose folder does not exist yet are exempt (planned modules);
  - the table has a cycle (the cycle is printed: "a -> b -> a");
  - a folder of src/penumbra has no line, or the table is malformed.

  python3 scripts/check_module_deps.py            # check this repository
  python3 scripts/check_module_deps.py --root DIR # check DIR/src/penumbra
  python3 scripts/check_module_deps.py --derive   # print the table the includes imply

Standard library only. Exit status: 0 clean, 1 problems found, 2 bad usage.
"""

import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_EXTS = (".h", ".hh", ".hpp", ".cc", ".cpp", ".cxx", ".inl", ".inc", ".ipp")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*[<"]penumbra/((?:[^/">]+/)+)[^/">]+[">]')
LINE_RE = re.compile(r"^([A-Za-z0-9_./-]+)\s*:(.*)$")
NAME_RE = re.compile(r"^[a-z][a-z0-9_]*(/[a-z][a-z0-9_]*)*$")
MAIN = "main"  # the files directly in src/penumbra (main.cc: the executable)


class Table:
    """The parsed DEPENDENCIES file: module -> (line number, deps in file order)."""

    def __init__(self):
        self.lines = {}  # module -> 1-based line
        self.deps = {}  # module -> [dep, ...]

    def graph(self):
        return {m: list(d) for m, d in self.deps.items()}


def read_table(path, shown):
    """Parses the table; returns (Table, [error])."""
    table = Table()
    errors = []
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        return table, [f"{shown}: cannot read the dependency table: {e.strerror}"]
    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        m = LINE_RE.match(line)
        if not m or not NAME_RE.match(m.group(1)):
            errors.append(f"{shown}:{n}: got '{line}'; expected 'module: dep dep ...' with "
                          "lowercase module names")
            continue
        module, deps = m.group(1), m.group(2).split()
        if module in table.lines:
            errors.append(f"{shown}:{n}: module '{module}' has a second line (the first is "
                          f"line {table.lines[module]}); expected one line per module")
            continue
        seen = []
        for d in deps:
            if not NAME_RE.match(d):
                errors.append(f"{shown}:{n}: {module}: got dep '{d}'; expected a lowercase "
                              "module name")
            elif d == module:
                errors.append(f"{shown}:{n}: {module} lists itself; a module's own includes "
                              "need no line entry")
            elif d in seen:
                errors.append(f"{shown}:{n}: {module} lists '{d}' twice")
            else:
                seen.append(d)
        table.lines[module] = n
        table.deps[module] = seen
    for module, deps in table.deps.items():
        for d in deps:
            if d not in table.deps:
                errors.append(f"{shown}:{table.lines[module]}: {module} lists '{d}', which has "
                              "no line of its own; expected a module of the table")
    return table, errors


def owner(path, sub_modules):
    """The module of a folder path ('render/cpu/x' -> 'render/cpu' when that is a sub-module of
    the table, else its first component 'render')."""
    parts = path.split("/")
    for n in range(len(parts), 1, -1):
        if "/".join(parts[:n]) in sub_modules:
            return "/".join(parts[:n])
    return parts[0]


def is_sub_module(name):
    return "/" in name


def scan_includes(src, sub_modules=()):
    """Every include of another module: [(path relative to src, line, module, dep)], and the
    set of modules that have source files. sub_modules: the table's names with a '/'."""
    edges = []
    modules = set()
    for folder, dirs, files in os.walk(src):
        dirs.sort()
        rel_folder = os.path.relpath(folder, src)
        module = MAIN if rel_folder == "." else owner(rel_folder.replace(os.sep, "/"),
                                                      sub_modules)
        for name in sorted(files):
            if not name.endswith(SOURCE_EXTS):
                continue
            modules.add(module)
            rel = os.path.normpath(os.path.join(rel_folder, name))
            with open(os.path.join(folder, name), encoding="utf-8", errors="replace") as f:
                for n, line in enumerate(f, start=1):
                    m = INCLUDE_RE.match(line)
                    if not m:
                        continue
                    dep = owner(m.group(1).rstrip("/"), sub_modules)
                    if dep != module:
                        edges.append((rel, n, module, dep))
    return edges, modules


def module_folders(src, sub_modules=()):
    """Folders directly under src (candidate modules) and the sub-modules whose folder exists,
    sorted."""
    tops = [d for d in os.listdir(src) if os.path.isdir(os.path.join(src, d))]
    subs = [m for m in sub_modules if os.path.isdir(os.path.join(src, *m.split("/")))]
    return sorted(tops + subs)


def find_cycles(graph):
    """One cycle per strongly connected component with a cycle, each as [a, b, ..., a]."""
    index, low, on_stack, stack, sccs = {}, {}, set(), [], []
    counter = [0]

    def strongconnect(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, []):
            if w not in graph:
                continue
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            scc = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                scc.append(w)
                if w == v:
                    break
            sccs.append(scc)

    for v in graph:
        if v not in index:
            strongconnect(v)
    cycles = []
    for scc in sccs:
        members = set(scc)
        if len(scc) == 1 and scc[0] not in graph.get(scc[0], []):
            continue
        # the shortest cycle through the component's first module in table order
        start = next(v for v in graph if v in members)
        path = shortest_path(graph, start, start, members)
        cycles.append(path)
    cycles.sort(key=lambda c: list(graph).index(c[0]))
    return cycles


def shortest_path(graph, a, b, allowed=None):
    """Shortest path a -> ... -> b (at least one edge) as a list of modules, or None."""
    frontier = [[a]]
    seen = set()
    while frontier:
        nxt = []
        for path in frontier:
            for w in graph.get(path[-1], []):
                if allowed is not None and w not in allowed:
                    continue
                if w == b:
                    return path + [w]
                if w not in seen:
                    seen.add(w)
                    nxt.append(path + [w])
        frontier = nxt
    return None


def check(root):
    """(errors, notes, stats) for root/src/penumbra."""
    src = os.path.join(root, "src", "penumbra")
    table_path = os.path.join(src, "DEPENDENCIES")
    shown_src = os.path.join("src", "penumbra")
    shown_table = os.path.join(shown_src, "DEPENDENCIES")
    table, errors = read_table(table_path, shown_table)
    if errors:
        return errors, [], {}
    notes = []
    graph = table.graph()
    sub_modules = {m for m in table.deps if is_sub_module(m)}
    edges, with_sources = scan_includes(src, sub_modules)
    on_disk = set(module_folders(src, sub_modules)) | ({MAIN} & with_sources)

    for m in sorted(on_disk - set(table.deps)):
        where = os.path.join(shown_src, m) + os.sep if m != MAIN else shown_src + " (top level)"
        errors.append(f"{where}: module '{m}' has no line in {shown_table}; expected "
                      f"'{m}: <the modules it includes>'")

    used = {}
    for rel, n, module, dep in edges:
        used.setdefault(module, set()).add(dep)
        shown = os.path.join(shown_src, rel)
        if module not in table.deps:
            continue  # reported above
        if dep not in table.deps:
            errors.append(f"{shown}:{n}: includes penumbra/{dep}/, which is no module of "
                          f"{shown_table}")
            continue
        if dep in table.deps[module]:
            continue
        if dep.startswith(module + "/"):
            errors.append(f"{shown}:{n}: {module} -> {dep}: {module}/ includes its own "
                          f"sub-module {dep}/; the root of a module must not include its "
                          f"sub-modules: move what it needs into {module}/ or behind an "
                          "interface there")
            continue
        msg = (f"{shown}:{n}: {module} -> {dep}: '{dep}' is not on the '{module}:' line "
               f"({shown_table}:{table.lines[module]}: {module}: {' '.join(table.deps[module])})")
        back = shortest_path(graph, dep, module)
        if back:
            msg += ("; with it the modules would form a cycle: " + module + " -> " +
                    " -> ".join(back) + ": move what both need to a lower module instead")
        else:
            msg += f"; add '{dep}' to the line if the dependency is intended"
        errors.append(msg)

    for module, deps in table.deps.items():
        for d in deps:
            if d.startswith(module + "/"):
                errors.append(f"{shown_table}:{table.lines[module]}: {module} -> {d}: a module "
                              f"must not depend on its own sub-module ({d} sits on top of "
                              f"{module}); move what {module} needs from {d} into {module}, or "
                              "hide it behind an interface there")
        if module not in on_disk:
            notes.append(f"{shown_table}:{table.lines[module]}: module '{module}' has no folder "
                         f"{os.path.join(shown_src, module)}{os.sep} yet; only the cycle check "
                         "reads its line")
            continue
        for d in deps:
            if d not in used.get(module, set()):
                where = (os.path.join(shown_src, module) + os.sep if module != MAIN
                         else "src/penumbra (top level)")
                errors.append(f"{shown_table}:{table.lines[module]}: {module} -> {d} is unused: "
                              f"no file of {where} includes penumbra/{d}/; remove '{d}' from "
                              "the line")

    for cycle in find_cycles(graph):
        lines = ", ".join(str(table.lines[m]) for m in cycle[:-1])
        errors.append(f"{shown_table}: cycle: {' -> '.join(cycle)} (lines {lines}); expected "
                      "no cycle: one of these includes must go the other way")
    stats = {"modules": len(table.deps), "includes": len(edges)}
    return errors, notes, stats


def derive(root):
    """The table the includes imply, lowest module first."""
    src = os.path.join(root, "src", "penumbra")
    table, errors = read_table(os.path.join(src, "DEPENDENCIES"), "DEPENDENCIES")
    sub_modules = {m for m in table.deps if is_sub_module(m)} if not errors else set()
    edges, with_sources = scan_includes(src, sub_modules)
    graph = {m: set() for m in sorted(set(module_folders(src, sub_modules)) |
                                      ({MAIN} & with_sources))}
    for _, _, module, dep in edges:
        graph.setdefault(module, set()).add(dep)
        graph.setdefault(dep, set())
    # depth: 0 for modules without deps, else 1 + the deepest dep (cycles cut)
    depth = {}

    def visit(m, active):
        if m in depth:
            return depth[m]
        if m in active:
            return 0
        active.add(m)
        d = 1 + max((visit(x, active) for x in graph[m]), default=-1)
        active.discard(m)
        depth[m] = d
        return d

    for m in graph:
        visit(m, set())
    order = sorted(graph, key=lambda m: (depth[m], m))
    out = []
    for m in order:
        deps = sorted(graph[m], key=lambda x: (-depth[x], x))
        out.append(f"{m}: {' '.join(deps)}".rstrip())
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=ROOT, help="repository root (default: this one)")
    parser.add_argument("--derive", action="store_true",
                        help="print the table that the includes imply and exit")
    args = parser.parse_args()
    if not os.path.isdir(os.path.join(args.root, "src", "penumbra")):
        print(f"check_module_deps: {args.root} has no src/penumbra folder", file=sys.stderr)
        return 2
    if args.derive:
        print("\n".join(derive(args.root)))
        return 0
    errors, notes, stats = check(args.root)
    for n in notes:
        print(f"note: {n}")
    for e in errors:
        print(f"error: {e}")
    if errors:
        print(f"check_module_deps: {len(errors)} problem(s)")
        return 1
    print(f"check_module_deps: OK: {stats['modules']} modules, {stats['includes']} includes of "
          "other modules, all on the table, no unused edge, no cycle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
