#!/usr/bin/env python3
"""Tests of scripts/check_source_comments.py: each test writes a small git checkout to a
temporary folder, with files whose comments name an issue number or a branch and files whose
code, string literals and links only look like one, runs the checker on it and asserts its exit
status and the file:line it names.

  python3 tests/meta/check_source_comments_test.py   (ctest -R SourceComments)
"""

import os
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHECKER = os.path.join(ROOT, "scripts", "check_source_comments.py")

# each file names a history reference in a comment, on the line given
BAD = {
    "src/a/trailing.cc": ("int x = 1;  // drawn on the host (branch gpu23)\n", 1),
    "src/a/wrapped.h": ("#pragma once\n// slower on an H100 (docs/notes.md, \"Local memory\n"
                        "// (branch\n// gpu29)\").\nint y;\n", 3),
    "src/a/block.cu": ("/* the sun's disc\n * as both backends call it (issue 35, item 3) */\n", 2),
    "src/a/digits.cc": ("int n = 10'000;  // issue 33: a bounded count\n", 1),
    "src/a/raw.cc": ('const char* s = R"(a "quoted" // text)";  // issues 19 and 22\n', 1),
    "tests/b/test_x.py": ("x = 1\n# issue 33: a steps chunk of 2^64 - 4 bytes\n", 2),
    "tests/b/test_doc.py": ('"""Acceptance: 1000 lockstep steps\n(issue 19)."""\n', 2),
    "scripts/c.sh": ("#!/bin/sh\necho hi  # as since branch gpu14\n", 2),
    "cmake/d.cmake": ("set(X 1)\n#[[ a bracket comment\n  of issue #34 ]]\n", 3),
    "CMakeLists.txt": ("add_test(NAME A COMMAND a)\n  # issue 34's state rules\n", 2),
    "web/e.js": ("const s = `a\n// not a comment`;  // before issue 36: one point\n", 2),
}

# code, strings, links and the verb: nothing to flag
GOOD = {
    "src/a/code.cc": ('int issue = 36;\nconst char* s = "issue 36, branch gpu23";\n'
                      '// see https://github.com/google-deepmind/mujoco/issues/1234\n'
                      "// upstream issue #12 of embree: rays with a NaN abort\n"
                      "// a client may issue 2 requests at once\n"
                      "char c = '/'; int n = 1'000;  // a bounded count\n"
                      'const char* r = R"x(// issue 3)x";\n'),
    "src/a/gpu.cc": ('// the gpu path and the GPU; gpu-notes\nint gpu = 0;  // gpu_count\n'),
    "tests/b/test_y.py": ('"""a test of the checker."""\nMSG = "issue 3"\n'
                          'URL = "https://example.org/x#issue-3"  # a link\n'
                          'def f():\n    return f"issue {3}"\n'),
    "scripts/c2.sh": ('#!/bin/sh\necho "# issue 3" \'# branch gpu2\'\nn=$#\nm=${#n}\n'),
    "cmake/d2.cmake": ('message(STATUS "# issue 3")\n'),
    "web/e2.js": ("const t = `x\n// issue 3 in a template`;  // a template string\n"),
    # not scanned: docs, other folders, other file types
    "docs/notes.md": "issue 36 (branch gpu23)\n",
    "other/f.cc": "// issue 36\n",
    "src/a/world.yaml": "# issue 36\n",
}


class FakeCheckout:
    """A temporary git checkout holding the given files (path -> text), all tracked."""

    def __init__(self, files, untracked=None):
        self.dir = tempfile.TemporaryDirectory()
        self.root = self.dir.name
        subprocess.run(["git", "init", "-q", self.root], check=True)
        for path, text in files.items():
            self.write(path, text)
        subprocess.run(["git", "-C", self.root, "add", "."], check=True)
        for path, text in (untracked or {}).items():
            self.write(path, text)

    def write(self, path, text):
        full = os.path.join(self.root, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w", encoding="utf-8") as f:
            f.write(text)

    def check(self, *args):
        proc = subprocess.run([sys.executable, CHECKER, "--root", self.root, *args],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        return proc.returncode, proc.stdout

    def close(self):
        self.dir.cleanup()


class CheckSourceCommentsTest(unittest.TestCase):
    def checkout(self, files, untracked=None):
        c = FakeCheckout(files, untracked)
        self.addCleanup(c.close)
        return c

    def test_clean_tree_passes(self):
        rc, out = self.checkout(GOOD).check()
        self.assertEqual(rc, 0, out)
        self.assertIn("OK:", out)

    def test_each_planted_reference_fails_naming_its_file_and_line(self):
        rc, out = self.checkout({**GOOD, **{p: text for p, (text, _) in BAD.items()}}).check()
        self.assertEqual(rc, 1, out)
        named = set(re.findall(r"^(\S+:\d+): ", out, re.MULTILINE))
        expected = {f"{path}:{line}" for path, (_, line) in BAD.items()}
        self.assertEqual(named, expected, out)

    def test_each_language_alone_fails(self):
        # one bad file at a time, so no language's reader passes on another's hit
        for path, (text, line) in BAD.items():
            with self.subTest(path=path):
                rc, out = self.checkout({path: text}).check()
                self.assertEqual(rc, 1, out)
                self.assertIn(f"{path}:{line}: ", out)

    def test_the_hit_prints_the_source_line(self):
        rc, out = self.checkout({"src/x.cc": "int a;\nint b;  // (issue 36)\n"}).check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/x.cc:2: int b;  // (issue 36)", out)

    def test_untracked_files_are_not_scanned_but_named_files_are(self):
        c = self.checkout(GOOD, untracked={"src/new.cc": "// issue 36\n"})
        rc, out = c.check()
        self.assertEqual(rc, 0, out)
        rc, out = c.check("src/new.cc")
        self.assertEqual(rc, 1, out)
        self.assertIn("src/new.cc:1: ", out)

    def test_missing_root_is_bad_usage(self):
        proc = subprocess.run([sys.executable, CHECKER, "--root", "/nonexistent/checkout"],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.assertEqual(proc.returncode, 2, proc.stdout)


if __name__ == "__main__":
    unittest.main()
