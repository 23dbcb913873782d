#!/usr/bin/env python3
"""Tests of scripts/check_transport_once.py: each test writes a small src/penumbra tree to a
temporary folder with a transport function, plants a second definition of it in a backend
folder (or a harmless look-alike: a call, a declaration, a member function, another name), runs
the check on it and asserts what it reports; the real tree passes.

  python3 tests/meta/check_transport_once_test.py   (ctest -R TransportOnce.CheckerTests)
"""

import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHECKER = os.path.join(ROOT, "scripts", "check_transport_once.py")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import check_transport_once  # noqa: E402

TRANSPORT_H = """#pragma once
namespace penumbra::transport {
/// shades a pixel
PB_HOST_DEVICE inline Float3 ShadePixel(const FrameView& f, int u,
                                        int v) {
  return Float3{};
}
struct Helper {
  PB_HOST_DEVICE float Size() const { return 1; }
};
}  // namespace penumbra::transport
"""


class CheckTransportOnceTest(unittest.TestCase):
    def tree(self, files):
        d = tempfile.TemporaryDirectory()
        self.addCleanup(d.cleanup)
        base = {"render/transport/shade.h": TRANSPORT_H}
        base.update(files)
        for path, text in base.items():
            full = os.path.join(d.name, "src", "penumbra", path)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, "w", encoding="utf-8") as f:
                f.write(text)
        return os.path.join(d.name, "src", "penumbra")

    def check(self, files, known=None):
        return check_transport_once.check(self.tree(files), known={} if known is None else known)

    def test_second_definition_in_a_backend_fails(self):
        for where in ("render/cpu/shade_lanes.cc", "render/cuda/kernels.cu"):
            problems, _ = self.check(
                {where: "namespace penumbra {\nnamespace {\nFloat3 ShadePixel(const Frame& f,\n"
                        "                  int u, int v) const {\n  return {};\n}\n}\n}\n"})
            self.assertEqual(len(problems), 1, problems)
            self.assertIn(f"src/penumbra/{where}:3: transport-once: ShadePixel is defined again",
                          problems[0])
            self.assertIn("render/transport/shade.h:4", problems[0])

    def test_device_qualified_copy_fails(self):
        problems, _ = self.check({"render/cuda/k.cuh": "__device__ __forceinline__ Float3 "
                                                       "ShadePixel(int u, int v) { return {}; }\n"})
        self.assertEqual(len(problems), 1, problems)

    def test_calls_declarations_members_and_comments_pass(self):
        problems, notes = self.check({
            "render/cuda/kernels.cu": "__global__ void ShadeKernel(FrameView f) {\n"
                                      "  out[i] = ShadePixel(f, u, v);\n"
                                      "  if (ShadePixel(f, 0, 0).x > 0) { return; }\n}\n"
                                      "Float3 ShadePixel(const FrameView& f, int u, int v);\n",
            "render/cpu/integrator.cc": "// Float3 ShadePixel(int u) { old }\n"
                                        "const char* s = \"Float3 ShadePixel(int u) {\";\n"
                                        "struct Lanes { float Size() const { return 16; } };\n"})
        self.assertEqual(problems, [])
        self.assertEqual(notes, [])

    def test_known_second_definition_is_a_note_and_must_exist(self):
        copy = {"render/cpu/mirror.cc": "int64_t ShadePixel(const Ctx& c) { return 0; }\n"}
        known = {("render/cpu/mirror.cc", "ShadePixel"): "not yet moved"}
        problems, notes = self.check(copy, known)
        self.assertEqual(problems, [])
        self.assertEqual(len(notes), 1)
        self.assertIn("known: ShadePixel: not yet moved", notes[0])
        problems, _ = self.check({}, known)
        self.assertEqual(len(problems), 1)
        self.assertIn("is gone: remove it from KNOWN", problems[0])

    def test_missing_or_empty_transport_fails(self):
        d = tempfile.TemporaryDirectory()
        self.addCleanup(d.cleanup)
        problems, _ = check_transport_once.check(d.name, known={})
        self.assertIn("the transport folder is missing", problems[0])
        problems, _ = self.check({"render/transport/shade.h": "#pragma once\n"})
        self.assertIn("no function is defined", problems[0])

    def test_real_tree_passes(self):
        proc = subprocess.run([sys.executable, CHECKER], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
        self.assertEqual(proc.returncode, 0, proc.stdout)


if __name__ == "__main__":
    unittest.main()
