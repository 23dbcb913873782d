#!/usr/bin/env python3
"""Tests of scripts/check_state_rules.py: each test writes a small src/penumbra tree to a
temporary folder, plants a violation of one rule (a third file naming qacc_warmstart, a
dynamic_cast to a concrete controller outside control/) or a harmless look-alike, runs the
checker on it and asserts its exit status and messages; the real tree passes.

  python3 tests/meta/check_state_rules_test.py   (ctest -R ArchitectureChecks.StateRules)
"""

import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHECKER = os.path.join(ROOT, "scripts", "check_state_rules.py")

CONTROLLER_H = """#pragma once
namespace penumbra {
class Controller { public: virtual ~Controller() = default; };
class TwistTarget { public: virtual ~TwistTarget() = default; };
class TrotGait final : public Controller, public TwistTarget {};
class JointPdController final
    : public Controller {};
class GaitBase : public Controller {};
class FancyGait final : public GaitBase {};
}  // namespace penumbra
"""
STATE_H = "struct SimState { std::vector<double> qacc_warmstart; };\n"
MUJOCO_STATE_CC = "case StateField::kQaccWarmstart: return d->qacc_warmstart;\n"


def run_checker(root):
    proc = subprocess.run([sys.executable, CHECKER, "--root", root], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True)
    return proc.returncode, proc.stdout


class CheckStateRulesTest(unittest.TestCase):
    def tree(self, files):
        d = tempfile.TemporaryDirectory()
        self.addCleanup(d.cleanup)
        base = {"control/controller.h": CONTROLLER_H, "scene/sim_state.h": STATE_H,
                "physics/mujoco_state.cc": MUJOCO_STATE_CC}
        base.update(files)
        for path, text in base.items():
            full = os.path.join(d.name, "src", "penumbra", path)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, "w", encoding="utf-8") as f:
                f.write(text)
        return run_checker(d.name)

    def test_clean_tree_passes(self):
        status, out = self.tree({
            # casts to capabilities and inside control/ are fine
            "command/dispatch.cc": "auto* t = dynamic_cast<TwistTarget*>(&c);\n",
            "control/factory.cc": "auto* g = dynamic_cast<TrotGait*>(&c);\n",
        })
        self.assertEqual(status, 0, out)
        self.assertIn("OK", out)

    def test_third_file_naming_the_state_field_fails(self):
        status, out = self.tree({"output/recorder.cc": "r.qacc_warmstart = s.qacc_warmstart;\n"})
        self.assertEqual(status, 1, out)
        self.assertIn("src/penumbra/output/recorder.cc:1: state-fields:", out)
        self.assertIn("file 3 of 3; expected at most 2", out)

    def test_comment_naming_the_state_field_counts_too(self):
        status, out = self.tree({"pipeline/source.h": "// copies qpos, qacc_warmstart, ...\n"})
        self.assertEqual(status, 1, out)
        self.assertIn("pipeline/source.h:1: state-fields", out)

    def test_cast_to_concrete_controller_outside_control_fails(self):
        status, out = self.tree({
            "viewer/bridge.cc": "x;\nif (const auto* pd = dynamic_cast<const JointPdController*>(&c))\n",
            "session/session.cc": "auto* g = dynamic_cast< penumbra::TrotGait *>(&c);\n",
        })
        self.assertEqual(status, 1, out)
        self.assertIn("src/penumbra/viewer/bridge.cc:2: controller-casts: dynamic_cast to the "
                      "concrete controller JointPdController", out)
        self.assertIn("src/penumbra/session/session.cc:1: controller-casts", out)
        self.assertIn("2 problem(s)", out)

    def test_indirect_controller_subclass_is_concrete(self):
        status, out = self.tree({"ros/bridge.cc": "dynamic_cast<FancyGait&>(c);\n"})
        self.assertEqual(status, 1, out)
        self.assertIn("concrete controller FancyGait", out)

    def test_missing_tree_is_bad_usage(self):
        with tempfile.TemporaryDirectory() as d:
            status, out = run_checker(d)
        self.assertEqual(status, 2, out)

    def test_real_tree_passes(self):
        status, out = run_checker(ROOT)
        self.assertEqual(status, 0, out)


if __name__ == "__main__":
    unittest.main()
