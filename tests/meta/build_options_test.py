#!/usr/bin/env python3
"""The build options of CMakeLists.txt that README "Set-up" documents: configuring with
-DPENUMBRA_BUILD_TESTS=OFF -DPENUMBRA_BUILD_BENCH=OFF gives a build whose targets are the
simulator only (no <module>_tests, fuzz corpus drivers or penumbra_microbench, and no ctest
tests), and the default configuration has them. Configures only (no compiler runs), into
temporary folders.

  python3 tests/meta/build_options_test.py CMAKE_COMMAND   (ctest -R BuildOptions)
"""

import os
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CMAKE = os.environ.get("CMAKE_COMMAND", "cmake")


def configure(build, *options):
    proc = subprocess.run([CMAKE, "-S", ROOT, "-B", build, "-G", "Ninja",
                           "-DCMAKE_BUILD_TYPE=Release", *options],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if proc.returncode != 0:
        raise AssertionError("cmake failed:\n" + proc.stdout)
    targets = subprocess.run(["ninja", "-C", build, "-t", "targets", "all"],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             check=True).stdout
    names = set()
    for line in targets.splitlines():
        name = line.split(":")[0]
        if "/" not in name and "." not in name:
            names.add(name)
    tests = subprocess.run(["ctest", "--test-dir", build, "-N"], stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True).stdout
    m = re.search(r"Total Tests: (\d+)", tests)
    return names, int(m.group(1)) if m else 0


class BuildOptionsTest(unittest.TestCase):
    def test_tests_and_benchmarks_can_be_left_out(self):
        with tempfile.TemporaryDirectory() as tmp:
            names, count = configure(os.path.join(tmp, "off"), "-DPENUMBRA_BUILD_TESTS=OFF",
                                     "-DPENUMBRA_BUILD_BENCH=OFF")
            self.assertIn("penumbra", names)
            extra = sorted(n for n in names if n.endswith("_tests") or n.endswith("_corpus")
                           or n == "penumbra_microbench")
            self.assertEqual(extra, [])
            self.assertEqual(count, 0)

    def test_the_default_builds_them(self):
        with tempfile.TemporaryDirectory() as tmp:
            names, count = configure(os.path.join(tmp, "on"))
            self.assertIn("core_tests", names)
            self.assertIn("penumbra_microbench", names)
            self.assertGreater(count, 10)  # gtest cases are discovered at build time


if __name__ == "__main__":
    if len(sys.argv) > 1:
        CMAKE = sys.argv.pop(1)
    unittest.main()
