#!/usr/bin/env python3
"""Writes README.md's "Layout" block and docs/architecture.md's module table from
src/penumbra/DEPENDENCIES (modules, their order and deps) and src/penumbra/MODULES (what each
does), so both list every module and never drift from the table CMake builds by.

    python3 scripts/module_docs.py --write        rewrite both blocks in place
    python3 scripts/module_docs.py [--root DIR]   check (ctest -R ModuleDocs): exit 1 naming the
                                                  file and what differs, or a module without an
                                                  entry in MODULES / an entry without a module

The blocks sit between `<!-- modules:layout -->` (README.md) or `<!-- modules:table -->`
(docs/architecture.md) and the next `<!-- /modules -->`. Standard library only.
"""

import argparse
import os
import re
import sys
import textwrap

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import check_module_deps  # noqa: E402

WIDTH = 98
LAYOUT_MARK = "<!-- modules:layout -->"
TABLE_MARK = "<!-- modules:table -->"
END_MARK = "<!-- /modules -->"
ENTRY_RE = re.compile(r"^([a-z][a-z0-9_]*(?:/[a-z][a-z0-9_]*)*)\s*:\s*(.*)$")


def read_descriptions(path):
    """MODULES -> ({module: text}, [error])."""
    out, errors, current = {}, [], None
    with open(path, encoding="utf-8") as f:
        for n, raw in enumerate(f, start=1):
            line = raw.rstrip("\n")
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            if line[0] in " \t":
                if current is None:
                    errors.append(f"src/penumbra/MODULES:{n}: a continuation line before any "
                                  "entry; expected 'module: what it does'")
                else:
                    out[current] += " " + line.strip()
                continue
            m = ENTRY_RE.match(line)
            if not m:
                errors.append(f"src/penumbra/MODULES:{n}: got '{line}'; expected "
                              "'module: what it does'")
                continue
            current = m.group(1)
            if current in out:
                errors.append(f"src/penumbra/MODULES:{n}: {current} has a second entry")
            out[current] = m.group(2).strip()
    return out, errors


def layers(deps):
    """module -> layer (0 for a module with no deps, else 1 + the highest layer of its deps)."""
    memo = {}

    def layer(m):
        if m not in memo:
            memo[m] = 0 if not deps[m] else 1 + max(layer(d) for d in deps[m])
        return memo[m]

    return {m: layer(m) for m in deps}


def layout_block(order, desc):
    lines = ["```", "src/penumbra/"]
    for m in order:
        name = "main.cc" if m == "main" else m + "/"
        head = "  " + name.ljust(16) + " "
        body = textwrap.wrap(desc[m], WIDTH - len(head))
        lines.append(head + body[0])
        lines += [" " * len(head) + b for b in body[1:]]
    tail = [
        ("DEPENDENCIES", "which modules each module includes, lowest layer first; CMake links "
                         "by it, `ctest -R ModuleDependencies` fails on an include it does not "
                         "list or on a cycle"),
        ("MODULES", "what each module does: this block and docs/architecture.md's module table "
                    "are written from it (scripts/module_docs.py, `ctest -R ModuleDocs`)"),
    ]
    for name, text in tail:
        head = "  " + name.ljust(16) + " "
        body = textwrap.wrap(text, WIDTH - len(head))
        lines.append(head + body[0])
        lines += [" " * len(head) + b for b in body[1:]]
    lines += [
        "tests/<module>/    GoogleTest suites mirroring src/ (tests/meta: the build's own checks)",
        "bench/             Penumbra's own speed: Google Benchmark micro-benchmarks, the fuzzing",
        "                   script (the `penumbra bench` harnesses are src/penumbra/bench/)",
        "benchmarks/        campaign specs of `penumbra benchmark` (SLAM, navigation; run by",
        "                   src/penumbra/campaign/)",
        "python/            penumbra_client (Python client of the ZeroMQ bridge), penumbra_nav,",
        "                   penumbra_rollout, examples/",
        "worlds/            bundled worlds and models",
        "```",
    ]
    return "\n".join(lines)


def table_block(order, deps, desc):
    lay = layers(deps)
    rows = ["| layer | module | may include (DEPENDENCIES) | what it does (MODULES) |",
            "|---|---|---|---|"]
    for m in sorted(order, key=lambda m: (lay[m], order.index(m))):
        d = " ".join(deps[m]) if deps[m] else "-"
        rows.append(f"| {lay[m]} | `{m}` | {d} | {desc[m]} |")
    return "\n".join(rows)


def replace_block(text, mark, block, shown):
    start = text.find(mark)
    if start < 0:
        return None, f"{shown}: no {mark} marker; expected the generated block after one"
    end = text.find(END_MARK, start)
    if end < 0:
        return None, f"{shown}: no {END_MARK} after {mark}"
    return text[:start] + mark + "\n" + block + "\n" + text[end:], None


def generate(root):
    """{path: new text} for README.md and docs/architecture.md, and [error]."""
    src = os.path.join(root, "src", "penumbra")
    table, errors = check_module_deps.read_table(os.path.join(src, "DEPENDENCIES"),
                                                 "src/penumbra/DEPENDENCIES")
    desc, derr = read_descriptions(os.path.join(src, "MODULES"))
    errors += derr
    order = list(table.deps)
    for m in order:
        if m not in desc:
            errors.append(f"src/penumbra/MODULES: no entry for module '{m}' (line "
                          f"{table.lines[m]} of DEPENDENCIES); expected '{m}: what it does'")
    for m in desc:
        if m not in table.deps:
            errors.append(f"src/penumbra/MODULES: entry '{m}' names no module of "
                          "src/penumbra/DEPENDENCIES; remove it or add the module's line there")
    if errors:
        return {}, errors
    out = {}
    for rel, mark, block in (("README.md", LAYOUT_MARK, layout_block(order, desc)),
                             ("docs/architecture.md", TABLE_MARK,
                              table_block(order, table.deps, desc))):
        with open(os.path.join(root, rel), encoding="utf-8") as f:
            text = f.read()
        new, err = replace_block(text, mark, block, rel)
        if err:
            errors.append(err)
        else:
            out[rel] = (text, new)
    return out, errors


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.dirname(HERE))
    ap.add_argument("--write", action="store_true")
    a = ap.parse_args(argv)
    out, errors = generate(a.root)
    for rel, (old, new) in sorted(out.items()):
        if old == new:
            continue
        if a.write:
            with open(os.path.join(a.root, rel), "w", encoding="utf-8") as f:
                f.write(new)
            print(f"wrote {rel}")
        else:
            errors.append(f"{rel}: the generated module block is stale; run "
                          "`python3 scripts/module_docs.py --write` (src/penumbra/DEPENDENCIES or "
                          "MODULES changed)")
    for e in errors:
        print(e)
    if not errors and not a.write:
        print("module docs OK")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
