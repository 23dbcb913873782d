#!/usr/bin/env python3
"""Checks that source comments state facts, not their history: no branch names (`branch gpuN`,
`since gpuN`, a bare `gpuN`) and no issue numbers of this project (`issue N`, `issues N and M`,
`(issue N, item M)`, `before issue N`). The history of a change belongs in docs/journal/ and
the commit log; a comment says what the code does and why.

Scanned: the files git tracks under src, tests, bench, fuzz, tools, python, scripts, cmake,
web and train, and every CMakeLists.txt: C, C++ and CUDA (// and /* */ comments), JavaScript
(the same), Python (# comments and string statements: docstrings), CMake and shell (#
comments). Only comment text is read, never code or string literals, and a comment may wrap a
reference over two lines (`(branch` / `gpuN)`). Not flagged: links to other projects' issues
(`.../issues/123`, or `issue N` after "upstream", "github", "gitlab" or a URL on the same
line) and the verb (`may issue 2 requests`: `issue` after to, can, may, will, ...).

Each hit is printed as `file:line: text` (the source line).

  python3 scripts/check_source_comments.py             # check this repository
  python3 scripts/check_source_comments.py --root DIR  # check the git checkout DIR
  python3 scripts/check_source_comments.py FILE...     # check these files (paths under --root)

Standard library only. Exit status: 0 clean, 1 hits found, 2 bad usage.
"""

import argparse
import ast
import io
import os
import re
import subprocess
import string
import sys
import tokenize

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOLDERS = ("src", "tests", "bench", "fuzz", "tools", "python", "scripts", "cmake", "web",
           "train")
C_EXTS = (".h", ".hh", ".hpp", ".hxx", ".c", ".cc", ".cpp", ".cxx", ".cu", ".cuh", ".inl",
          ".inc", ".ipp", ".js", ".mjs")
PY_EXTS = (".py",)
HASH_EXTS = (".sh", ".bash", ".cmake")
HEX = string.hexdigits

# a branch name of the GPU work (gpu and a number), with or without the word "branch" before it
BRANCH_RE = re.compile(r"\b(?:branch(?:es)?\s+)?gpu\d+\b", re.IGNORECASE)
# this project's issue numbers: issue N, issues N and M, issue #N
ISSUE_RE = re.compile(r"\bissues?\s*#?\d+\b", re.IGNORECASE)
# before one of these, `issue N` is the verb (`may issue 2 requests`)
VERB_CONTEXT = {"to", "can", "cannot", "may", "might", "will", "would", "should", "could",
                "must", "then", "we", "they", "it", "i", "you", "not", "and", "or"}
# before one of these on the same line, `issue N` is another project's
FOREIGN_RE = re.compile(r"upstream|github|gitlab|https?://|bugs\.", re.IGNORECASE)


def language(path):
    """'c', 'py', 'hash' or None (not scanned) for a path; a trailing .in is looked through."""
    name = os.path.basename(path)
    if name == "CMakeLists.txt":
        return "hash"
    if name.endswith(".in"):
        name = name[:-3]
    if name.endswith(C_EXTS):
        return "c"
    if name.endswith(PY_EXTS):
        return "py"
    if name.endswith(HASH_EXTS):
        return "hash"
    return None


def c_comments(text, backtick_strings=False):
    """(line, comment text) of every // and /* */ comment line of C-like source text; string,
    character and raw string literals are skipped (and JavaScript's `template` strings)."""
    out = []
    i, n, line = 0, len(text), 1
    quotes = "\"'`" if backtick_strings else "\"'"
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            out.append((line, text[i:end].lstrip("/!")))
            i = end
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end
            for k, part in enumerate(text[i + 2:end].split("\n")):
                out.append((line + k, part.strip().lstrip("*!")))
            line += text.count("\n", i, end)
            i = end + 2
        elif c == "R" and text.startswith('R"', i) and re.search(r"(?:^|[^\w])(?:L|u8|u|U)?$",
                                                                text[max(0, i - 3):i]):
            m = re.match(r'R"([^()\\\s]{0,16})\(', text[i:])
            if not m:
                i += 1
                continue
            close = ")" + m.group(1) + '"'
            end = text.find(close, i + m.end())
            end = n if end < 0 else end + len(close)
            line += text.count("\n", i, end)
            i = end
        elif c == "'" and 0 < i < n - 1 and text[i - 1] in HEX and text[i + 1] in HEX:
            i += 1  # a digit separator (1'000'000) or a suffix, not a character literal
        elif c in quotes:
            j = i + 1
            while j < n and text[j] != c:
                if text[j] == "\\":
                    j += 1
                elif text[j] == "\n" and c != "`":
                    break  # an unterminated literal ends at its line
                j += 1
            line += text.count("\n", i, min(j, n))
            i = j + 1 if j < n and text[j] == c else j
        else:
            i += 1
    return out


def hash_comments(text, cmake=False):
    """(line, comment text) of every # comment of shell or CMake text: a # outside quotes (in
    shell also at a word's start only, so $# and ${#x} are not comments); CMake's #[[ ]]
    bracket comments span lines."""
    out = []
    lines = text.split("\n")
    k = 0
    while k < len(lines):
        s = lines[k]
        quote = None
        j = 0
        while j < len(s):
            c = s[j]
            if quote:
                if c == "\\" and quote == '"':
                    j += 1
                elif c == quote:
                    quote = None
            elif c in "\"'" and not (cmake and c == "'"):
                quote = c
            elif c == "#" and (cmake or j == 0 or s[j - 1] in " \t;(|&"):
                m = re.match(r"#\[(=*)\[", s[j:]) if cmake else None
                if m:
                    close = "]" + m.group(1) + "]"
                    rest = s[j + m.end():]
                    while close not in rest and k + 1 < len(lines):
                        out.append((k + 1, rest))
                        k += 1
                        rest = lines[k]
                    out.append((k + 1, rest.split(close)[0]))
                else:
                    out.append((k + 1, s[j:].lstrip("#")))
                break
            j += 1
        k += 1
    return out


def py_comments(text):
    """(line, comment text) of every # comment and every string statement (docstrings) of
    Python source; source that does not parse is read as # comments only."""
    out = []
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type == tokenize.COMMENT:
                out.append((tok.start[0], tok.string.lstrip("#")))
        tree = ast.parse(text)
    except (SyntaxError, tokenize.TokenError, ValueError):
        return hash_comments(text)
    lines = text.split("\n")
    for node in ast.walk(tree):
        if (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
                and isinstance(node.value.value, str)):
            for number in range(node.lineno, node.end_lineno + 1):
                out.append((number, lines[number - 1]))
    return sorted(out)


def comment_blocks(comments):
    """Runs of comment text on consecutive lines, each as (text joined by newlines, the line
    of each character offset's line start)."""
    blocks = []
    for number, text in comments:
        if blocks and blocks[-1][-1][0] in (number, number - 1):
            blocks[-1].append((number, text))
        else:
            blocks.append([(number, text)])
    for block in blocks:
        starts, parts, offset = [], [], 0
        for number, text in block:
            starts.append((offset, number))
            parts.append(text)
            offset += len(text) + 1
        yield "\n".join(parts), starts


def line_of(starts, offset):
    number = starts[0][1]
    for start, n in starts:
        if start > offset:
            break
        number = n
    return number


def is_ours(block, m):
    """Whether an ISSUE_RE match is this project's issue, not the verb or another project's."""
    before = block[:m.start()]
    word = re.search(r"([A-Za-z']+)\s*$", before)
    if word and word.group(1).lower() in VERB_CONTEXT:
        return False
    line_start = before.rfind("\n") + 1
    return not FOREIGN_RE.search(block[line_start:m.start()])


def hits_in(text, lang):
    """Line numbers (sorted, unique) of the history references in the comments of text."""
    if lang == "c":
        comments = c_comments(text)
    elif lang == "js":
        comments = c_comments(text, backtick_strings=True)
    elif lang == "py":
        comments = py_comments(text)
    else:
        comments = hash_comments(text, cmake=lang == "cmake")
    found = set()
    for block, starts in comment_blocks(comments):
        for m in BRANCH_RE.finditer(block):
            found.add(line_of(starts, m.start()))
        for m in ISSUE_RE.finditer(block):
            if is_ours(block, m):
                found.add(line_of(starts, m.start()))
    return sorted(found)


def file_language(path):
    lang = language(path)
    name = os.path.basename(path)
    if lang == "c" and name.endswith((".js", ".mjs")):
        return "js"
    if lang == "hash" and (name == "CMakeLists.txt" or name.endswith((".cmake", ".cmake.in"))):
        return "cmake"
    return lang


def tracked_files(root):
    """Paths (relative to root) of the scanned files git tracks in root."""
    proc = subprocess.run(["git", "-C", root, "ls-files", "-z", "--", *FOLDERS,
                           "CMakeLists.txt"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if proc.returncode != 0:
        raise RuntimeError(f"git ls-files in {root} failed: "
                           f"{proc.stderr.decode(errors='replace').strip()}")
    paths = [p for p in proc.stdout.decode().split("\0") if p]
    return sorted(p for p in paths if language(p))


def check(root, paths=None):
    """`file:line: text` of every history reference in the comments of paths (relative to
    root; default: the tracked files to scan)."""
    problems = []
    for rel in (paths if paths is not None else tracked_files(root)):
        lang = file_language(rel)
        if not lang:
            continue
        full = os.path.join(root, rel)
        if not os.path.isfile(full):
            continue  # deleted in the working tree, not yet in the index
        with open(full, encoding="utf-8", errors="replace") as f:
            text = f.read()
        lines = text.split("\n")
        for number in hits_in(text, lang):
            problems.append(f"{rel}:{number}: {lines[number - 1].strip()}")
    return problems


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=ROOT, help="the git checkout to check")
    parser.add_argument("files", nargs="*", help="files to check (default: the tracked sources)")
    args = parser.parse_args(argv)
    if not os.path.isdir(args.root):
        print(f"{args.root}: no such folder", file=sys.stderr)
        return 2
    try:
        problems = check(args.root, args.files or None)
    except RuntimeError as e:
        print(e, file=sys.stderr)
        return 2
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} comment line(s) name an issue number or a branch: state the fact "
              f"without its history (history belongs in docs/journal/ and commit messages)")
        return 1
    print("OK: no issue numbers or branch names in source comments")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
