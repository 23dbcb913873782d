#!/usr/bin/env python3
"""Checks that the light transport is written once (docs/architecture.md, "render/").

The processor-neutral transport lives in src/penumbra/render/transport/: PB_HOST_DEVICE
functions over plain data that the CPU backend (render/cpu/, over Embree) and the CUDA backend
(render/cuda/, over the BVH of render/bvh/) both call. A backend folder keeps its own plumbing
(the tile loop and Embree calls; device memory, streams and kernel launches), never a second
definition of a transport function. This script fails when

  - a function defined in render/transport/ is defined again (same name, a body follows the
    parameter list) in a file under render/cpu/ or render/cuda/: a copy of the transport came
    back. Calls, declarations and kernels with other names are fine;
  - render/transport/ is missing or defines no function (the rule would pass vacuously).

KNOWN lists the second definitions that are known and documented (docs/architecture.md,
"render/"): they are printed as `known:` lines and do not fail the check; an entry that no
longer matches anything fails it, so the list can only shrink.

Each problem is printed as `file:line: transport-once: message`.

  python3 scripts/check_transport_once.py            # check this repository
  python3 scripts/check_transport_once.py --root DIR # check DIR/src/penumbra

Standard library only. Exit status: 0 clean, 1 problems found, 2 bad usage.
"""

import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_EXTS = (".h", ".hh", ".hpp", ".cc", ".cpp", ".cxx", ".inl", ".inc", ".cu", ".cuh")
TRANSPORT = os.path.join("render", "transport")
BACKENDS = (os.path.join("render", "cpu"), os.path.join("render", "cuda"))

# words that may stand before a function's return type
QUALIFIERS = r"(?:(?:PB_HOST_DEVICE|__device__|__host__|__global__|__forceinline__|inline|static|" \
             r"constexpr|extern|template\s*<[^<>]*(?:<[^<>]*>[^<>]*)*>)\s+)*"
# a definition: qualifiers, a return type, the name, a parameter list without ';' or braces,
# then (after const / noexcept / a trailing return type) an opening brace
DEFINITION_RE = re.compile(
    r"(?:^|[;}{])\s*" + QUALIFIERS +
    r"(?:[A-Za-z_][\w:]*(?:\s*<[^;{}()]*>)?[\s\*&]+)+?([A-Za-z_]\w*)\s*\(([^;{}]*)\)\s*"
    r"(?:const\s*)?(?:noexcept\s*)?(?:->\s*[\w:<>,\s\*&]+)?\{")
# (file under src/penumbra, function) -> why it is still there
KNOWN = {}
KEYWORDS = {"if", "for", "while", "switch", "return", "sizeof", "catch", "do", "else", "case"}


def strip_comments(text):
    """text with // and /* */ comments and string literals blanked, newlines kept."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif c == '"' or c == "'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


NAMESPACE_RE = re.compile(r"\bnamespace(?:\s+[A-Za-z_][\w:]*)?\s*$")


def namespace_scope(text):
    """per character of text: whether it stands at namespace scope (inside no braces but those
    of `namespace ... {` blocks)."""
    scope = [True] * (len(text) + 1)
    stack = []  # per open brace: whether it opens a namespace
    for i, c in enumerate(text):
        if c == "{":
            stack.append(bool(NAMESPACE_RE.search(text[max(0, i - 200):i])))
        elif c == "}" and stack:
            stack.pop()
        scope[i + 1] = all(stack)
    return scope


def definitions(path):
    """[(name, line)] of the free functions (namespace scope) defined in the file at path;
    member functions defined in a class body are not the transport's entry points."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = strip_comments(f.read())
    scope = namespace_scope(text)
    found = []
    for m in DEFINITION_RE.finditer(text):
        name = m.group(1)
        if name in KEYWORDS or name.startswith("operator") or not scope[m.start(1)]:
            continue
        found.append((name, text.count("\n", 0, m.start(1)) + 1))
    return found


def source_files(folder):
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames.sort()
        for name in sorted(filenames):
            if name.endswith(SOURCE_EXTS):
                yield os.path.join(dirpath, name)


def check(src, known=None):
    """(problems, notes) found under src (src/penumbra), as printed lines; `known`: KNOWN."""
    known = KNOWN if known is None else known
    problems, notes, seen = [], [], set()
    transport = os.path.join(src, TRANSPORT)
    if not os.path.isdir(transport):
        return [f"{transport}: transport-once: the transport folder is missing"], []
    defined = {}
    for path in source_files(transport):
        for name, line in definitions(path):
            defined.setdefault(name, (os.path.relpath(path, src), line))
    if not defined:
        return [f"{transport}: transport-once: no function is defined in the transport folder"], []
    for backend in BACKENDS:
        folder = os.path.join(src, backend)
        if not os.path.isdir(folder):
            continue
        for path in source_files(folder):
            for name, line in definitions(path):
                if name in defined:
                    where, at = defined[name]
                    rel = os.path.relpath(path, src).replace(os.sep, "/")
                    if (rel, name) in known:
                        seen.add((rel, name))
                        notes.append(f"src/penumbra/{rel}:{line}: known: {name}: "
                                     f"{known[(rel, name)]}")
                        continue
                    problems.append(
                        f"src/penumbra/{os.path.relpath(path, src)}:{line}: transport-once: "
                        f"{name} is defined again; the transport defines it at "
                        f"src/penumbra/{where}:{at}: call that one")
    for rel, name in sorted(set(known) - seen):
        problems.append(f"src/penumbra/{rel}: transport-once: the known second definition of "
                        f"{name} is gone: remove it from KNOWN in scripts/check_transport_once.py")
    return problems, notes


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", default=ROOT, help="repository root (default: this one)")
    args = parser.parse_args(argv)
    src = os.path.join(args.root, "src", "penumbra")
    if not os.path.isdir(src):
        print(f"{src}: not a folder; expected a repository root with src/penumbra", file=sys.stderr)
        return 2
    problems, notes = check(src)
    for line in notes + problems:
        print(line)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
