#!/usr/bin/env python3
"""Tests of scripts/check_module_deps.py: each test writes a small src/penumbra tree (or a copy
of the real one) to a temporary folder, plants a cycle, a stray include, an unused edge or a
malformed line, runs the checker on it and asserts its exit status and messages. Also checks
that CMake (cmake/module_dependencies.cmake) reads the table as the checker does.

  python3 tests/meta/check_module_deps_test.py   (ctest -R ModuleDependencies)
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHECKER = os.path.join(ROOT, "scripts", "check_module_deps.py")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import check_module_deps  # noqa: E402


def run_checker(root, *args):
    proc = subprocess.run([sys.executable, CHECKER, "--root", root, *args],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return proc.returncode, proc.stdout


class FakeTree:
    """A temporary root with src/penumbra/<module>/<file> sources and a DEPENDENCIES table."""

    def __init__(self, table, files):
        self.dir = tempfile.TemporaryDirectory()
        self.root = self.dir.name
        self.src = os.path.join(self.root, "src", "penumbra")
        os.makedirs(self.src)
        self.write("DEPENDENCIES", table)
        for path, text in files.items():
            self.write(path, text)

    def write(self, path, text):
        full = os.path.join(self.src, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w", encoding="utf-8") as f:
            f.write(text)

    def check(self):
        return run_checker(self.root)

    def close(self):
        self.dir.cleanup()


def inc(module, name="x.h"):
    return f'#include "penumbra/{module}/{name}"\n'


class CheckModuleDepsTest(unittest.TestCase):
    def tree(self, table, files):
        t = FakeTree(table, files)
        self.addCleanup(t.close)
        return t

    def test_clean_tree_passes(self):
        t = self.tree("core:\nscene: core\nrender: scene core\n", {
            "core/x.h": "#pragma once\n",
            "scene/x.h": inc("core") + "#include <vector>\n",
            "render/x.cc": inc("scene") + inc("core") + inc("render"),
        })
        rc, out = t.check()
        self.assertEqual(rc, 0, out)
        self.assertIn("OK: 3 modules, 3 includes of other modules", out)

    def test_planted_cycle_fails_naming_the_cycle(self):
        # a -> b -> c -> a, in the table and in the includes
        t = self.tree("a: b\nb: c\nc: a\nd:\n", {
            "a/x.h": inc("b"), "b/x.h": inc("c"), "c/x.h": inc("a"), "d/x.h": "",
        })
        rc, out = t.check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/penumbra/DEPENDENCIES: cycle: a -> b -> c -> a (lines 1, 2, 3)", out)
        self.assertNotIn("unused", out)

    def test_include_that_closes_a_cycle_names_file_line_and_cycle(self):
        # the table is acyclic; scene's second include points back up at physics
        t = self.tree("core:\nscene: core\nphysics: scene core\n", {
            "core/x.h": "",
            "scene/x.h": inc("core"),
            "scene/y.cc": "// a comment\n" + inc("physics", "simulation.h"),
            "physics/x.h": inc("scene") + inc("core"),
        })
        rc, out = t.check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/penumbra/scene/y.cc:2: scene -> physics: 'physics' is not on the "
                      "'scene:' line (src/penumbra/DEPENDENCIES:2: scene: core)", out)
        self.assertIn("would form a cycle: scene -> physics -> scene", out)

    def test_undeclared_edge_without_cycle_fails(self):
        t = self.tree("core:\nscene: core\nrender: scene\n", {
            "core/x.h": "", "scene/x.h": inc("core"),
            "render/deep/x.h": "\n\n" + inc("scene") + inc("core"),
        })
        rc, out = t.check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/penumbra/render/deep/x.h:4: render -> core: 'core' is not on the "
                      "'render:' line", out)
        self.assertIn("add 'core' to the line if the dependency is intended", out)

    def test_unused_edge_fails(self):
        t = self.tree("core:\nscene: core\nrender: scene core\n", {
            "core/x.h": "", "scene/x.h": inc("core"), "render/x.h": inc("scene"),
        })
        rc, out = t.check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/penumbra/DEPENDENCIES:3: render -> core is unused: no file of "
                      "src/penumbra/render/ includes penumbra/core/; remove 'core' from the line",
                      out)

    def test_planned_module_without_folder_is_noted_and_cycle_checked(self):
        t = self.tree("core:\npipeline: core\n", {"core/x.h": ""})
        rc, out = t.check()
        self.assertEqual(rc, 0, out)
        self.assertIn("module 'pipeline' has no folder src/penumbra/pipeline/ yet", out)
        t.write("DEPENDENCIES", "core: pipeline\npipeline: core\n")
        rc, out = t.check()
        self.assertEqual(rc, 1, out)
        self.assertIn("cycle: core -> pipeline -> core", out)

    def test_folder_without_line_and_unknown_module_fail(self):
        t = self.tree("core:\n", {"core/x.h": inc("nowhere"), "extra/x.cc": inc("core")})
        rc, out = t.check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/penumbra/extra/: module 'extra' has no line in "
                      "src/penumbra/DEPENDENCIES", out)
        self.assertIn("src/penumbra/core/x.h:1: includes penumbra/nowhere/, which is no module",
                      out)

    def test_top_level_files_are_module_main(self):
        files = {"core/x.h": "", "app/x.h": inc("core"), "main.cc": inc("app")}
        rc, out = self.tree("core:\napp: core\nmain: app\n", files).check()
        self.assertEqual(rc, 0, out)
        rc, out = self.tree("core:\napp: core\n", files).check()
        self.assertEqual(rc, 1, out)
        self.assertIn("module 'main' has no line", out)

    def test_malformed_tables_fail_naming_the_line(self):
        cases = {
            "core:\nscene core\n": "DEPENDENCIES:2: got 'scene core'; expected 'module: dep",
            "core:\ncore: \n": "DEPENDENCIES:2: module 'core' has a second line",
            "core: core\n": "DEPENDENCIES:1: core lists itself",
            "core: scene\n": "DEPENDENCIES:1: core lists 'scene', which has no line of its own",
            "Core:\n": "DEPENDENCIES:1: got 'Core:'",
        }
        for table, message in cases.items():
            rc, out = self.tree(table, {"core/x.h": ""}).check()
            self.assertEqual(rc, 1, table + out)
            self.assertIn(message, out, table)

    def test_commented_out_includes_do_not_count(self):
        t = self.tree("core:\nscene: core\n", {
            "core/x.h": "// #include \"penumbra/scene/x.h\"\n",
            "scene/x.h": "  #  include <penumbra/core/x.h>\n",
        })
        rc, out = t.check()
        self.assertEqual(rc, 0, out)

    def test_cycle_planted_in_a_copy_of_the_real_tree(self):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        src = os.path.join(tmp.name, "src", "penumbra")
        shutil.copytree(os.path.join(ROOT, "src", "penumbra"), src)
        rc, out = run_checker(tmp.name)
        self.assertEqual(rc, 0, out)  # the copy is clean, as the real tree
        # physics includes scene; a scene header now includes physics back
        with open(os.path.join(src, "scene", "world_snapshot.h"), "a", encoding="utf-8") as f:
            f.write('#include "penumbra/physics/simulation.h"\n')
        rc, out = run_checker(tmp.name)
        self.assertEqual(rc, 1, out)
        self.assertRegex(out, r"src/penumbra/scene/world_snapshot\.h:\d+: scene -> physics: "
                              r".*would form a cycle: scene -> physics -> scene")
        # adding the edge to the table turns it into a cycle of the table
        table = os.path.join(src, "DEPENDENCIES")
        with open(table, encoding="utf-8") as f:
            text = f.read()
        with open(table, "w", encoding="utf-8") as f:
            f.write(re.sub(r"(?m)^scene: core$", "scene: physics core", text))
        rc, out = run_checker(tmp.name)
        self.assertEqual(rc, 1, out)
        self.assertIn("cycle: scene -> physics -> scene", out)

    def test_sub_modules_own_their_folders(self):
        # render/cpu and render/embree have lines: their files are theirs; render/deep has none,
        # so its files are render's
        table = ("core:\nrender: core\nrender/embree: render core\n"
                 "render/cpu: render/embree render\n")
        t = self.tree(table, {
            "core/x.h": "",
            "render/x.h": inc("core"),
            "render/deep/y.h": inc("render") + inc("core"),
            "render/embree/x.cc": inc("render") + inc("core") + inc("render/embree", "y.h"),
            "render/cpu/x.cc": inc("render/embree") + inc("render") + inc("render/cpu", "y.h"),
        })
        rc, out = t.check()
        self.assertEqual(rc, 0, out)
        self.assertIn("OK: 4 modules, 6 includes of other modules", out)
        # render/cpu including core directly is an edge of render/cpu, not of render
        t.write("render/cpu/z.h", "\n" + inc("core"))
        rc, out = t.check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/penumbra/render/cpu/z.h:2: render/cpu -> core: 'core' is not on the "
                      "'render/cpu:' line", out)
        self.assertEqual(check_module_deps.owner("render/cpu/a", {"render/cpu"}), "render/cpu")
        self.assertEqual(check_module_deps.owner("render/cpux", {"render/cpu"}), "render")

    def test_root_including_its_sub_module_fails(self):
        table = ("core:\nrender: core\nrender/embree: render core\n"
                 "render/cpu: render/embree render\n")
        files = {
            "core/x.h": "",
            "render/x.h": inc("core") + inc("render/embree", "ray_scene.h"),
            "render/embree/x.cc": inc("render") + inc("core"),
            "render/cpu/x.cc": inc("render/embree") + inc("render"),
        }
        rc, out = self.tree(table, files).check()
        self.assertEqual(rc, 1, out)
        self.assertIn("src/penumbra/render/x.h:2: render -> render/embree: render/ includes its "
                      "own sub-module render/embree/; the root of a module must not include its "
                      "sub-modules", out)
        # listing the edge is refused too (and closes a cycle)
        rc, out = self.tree(table.replace("render: core", "render: render/embree core"),
                            files).check()
        self.assertEqual(rc, 1, out)
        self.assertIn("DEPENDENCIES:2: render -> render/embree: a module must not depend on its "
                      "own sub-module", out)
        self.assertIn("cycle: render -> render/embree -> render", out)

    def test_render_root_of_the_real_tree_includes_neither_cpu_nor_embree(self):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        src = os.path.join(tmp.name, "src", "penumbra")
        shutil.copytree(os.path.join(ROOT, "src", "penumbra"), src)
        with open(os.path.join(src, "DEPENDENCIES"), encoding="utf-8") as f:
            self.assertRegex(f.read(), r"(?m)^render: scene core$")
        rc, out = run_checker(tmp.name)
        self.assertEqual(rc, 0, out)
        for header, planted, sub in (("camera/camera.h", "embree/ray_scene.h", "render/embree"),
                                     ("ray_query.h", "cpu/integrator.h", "render/cpu")):
            path = os.path.join(src, "render", header)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            with open(path, "a", encoding="utf-8") as f:
                f.write(f'#include "penumbra/render/{planted}"\n')
            rc, out = run_checker(tmp.name)
            self.assertEqual(rc, 1, out)
            self.assertRegex(out, rf"src/penumbra/render/{re.escape(header)}:\d+: render -> "
                                  rf"{sub}: render/ includes its own sub-module {sub}/")
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)

    def test_cmake_reads_the_table_as_the_checker_does(self):
        cmake = os.environ.get("CMAKE_COMMAND") or shutil.which("cmake")
        if not cmake:
            self.skipTest("no cmake")
        tricky = ("# comment; with [brackets] and a: colon\n\ncore:   # trailing\n"
                  "scene:core\n  render :  scene   core  \n\t\napp: render scene core # [x;y]\n"
                  "render/cpu: render scene\n")
        with tempfile.TemporaryDirectory() as tmp:
            tricky_path = os.path.join(tmp, "DEPENDENCIES")
            with open(tricky_path, "w", encoding="utf-8") as f:
                f.write(tricky)
            for path in (os.path.join(ROOT, "src", "penumbra", "DEPENDENCIES"), tricky_path):
                proc = subprocess.run(
                    [cmake, f"-DPENUMBRA_DEPENDENCIES={path}", "-P",
                     os.path.join(ROOT, "cmake", "module_dependencies.cmake")],
                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                self.assertEqual(proc.returncode, 0, proc.stderr)
                from_cmake = [line.rstrip() for line in proc.stderr.splitlines() if line]
                table, errors = check_module_deps.read_table(path, "DEPENDENCIES")
                self.assertEqual(errors, [])
                from_checker = [f"{m}: {' '.join(d)}".rstrip() for m, d in table.deps.items()]
                self.assertEqual(from_cmake, from_checker, path)
                self.assertGreaterEqual(len(from_checker), 4)


if __name__ == "__main__":
    unittest.main(verbosity=2)
