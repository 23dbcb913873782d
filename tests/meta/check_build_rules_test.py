#!/usr/bin/env python3
"""Tests of scripts/check_build_rules.py and scripts/module_docs.py: each test writes a small
tree (src/penumbra, scripts/build_rules.json, README.md, docs/architecture.md) to a temporary
folder, plants one violation (a yaml-cpp include outside config/ or in a test, a whole-file read
by hand outside core/input_file.cc, json.hpp in a header, an 11th
module dep, a translation unit above the preprocessed-lines budget, a stale module table, a
module without a MODULES entry), runs the script and asserts its exit status and message; and
the same tree without the violation passes.

  python3 tests/meta/check_build_rules_test.py   (ctest -R BuildRules.CheckerTests)
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RULES = os.path.join(ROOT, "scripts", "check_build_rules.py")
DOCS = os.path.join(ROOT, "scripts", "module_docs.py")
CXX = shutil.which("g++") or shutil.which("c++")


def run(script, *args):
    proc = subprocess.run([sys.executable, script, *args], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True)
    return proc.returncode, proc.stdout


BASE_RULES = {
    "yaml_cpp_files": [],
    "whole_file_reads": [],
    "json_headers": [],
    "max_module_deps": 10,
    "module_deps_exempt": ["app", "main"],
    "module_deps_allowed": {},
    "preprocessed_lines": {"per_unit": 1000000, "total": 10000000},
}

TABLE = "core:\nscene: core\napp: scene core\nmain: app\n"
MODULES = ("core: the bottom\nscene: what the renderer sees\n  over two lines\n"
           "app: the command line\nmain: the executable\n")


class Tree:
    def __init__(self, files, rules=None, table=TABLE, modules=MODULES):
        self.dir = tempfile.TemporaryDirectory()
        self.root = self.dir.name
        r = dict(BASE_RULES)
        r.update(rules or {})
        self.write("scripts/build_rules.json", json.dumps(r))
        self.write("src/penumbra/DEPENDENCIES", table)
        self.write("src/penumbra/MODULES", modules)
        self.write("README.md", "# x\n\n<!-- modules:layout -->\n<!-- /modules -->\n\nend\n")
        self.write("docs/architecture.md", "# a\n\n<!-- modules:table -->\nold\n<!-- /modules -->\n")
        for path, text in files.items():
            self.write(path, text)

    def write(self, rel, text):
        full = os.path.join(self.root, rel)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w", encoding="utf-8") as f:
            f.write(text)

    def rules(self, *args):
        return run(RULES, "--root", self.root, *args)

    def docs(self, *args):
        return run(DOCS, "--root", self.root, *args)


class BuildRulesTest(unittest.TestCase):
    def tree(self, files, **kw):
        t = Tree(files, **kw)
        self.addCleanup(t.dir.cleanup)
        return t

    def test_clean_tree_passes(self):
        t = self.tree({"src/penumbra/core/a.cc": '#include "penumbra/core/a.h"\n',
                       "src/penumbra/config/reader.cc": "#include <yaml-cpp/yaml.h>\n",
                       "src/penumbra/scene/s.cc": "#include <nlohmann/json.hpp>\n"})
        rc, out = t.rules()
        self.assertEqual(rc, 0, out)
        self.assertIn("build rules OK", out)

    def test_yaml_cpp_outside_config_fails(self):
        t = self.tree({"src/penumbra/scene/s.cc": "// x\n#include <yaml-cpp/yaml.h>\n"})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("src/penumbra/scene/s.cc:2: includes yaml-cpp", out)

    def test_yaml_cpp_in_a_config_header_fails(self):
        t = self.tree({"src/penumbra/config/reader.h": "#include <yaml-cpp/yaml.h>\n"})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("config/reader.h:1: includes yaml-cpp", out)

    def test_allow_listed_yaml_file_passes_and_a_stale_entry_fails(self):
        files = {"src/penumbra/scene/s.cc": "#include <yaml-cpp/yaml.h>\n"}
        t = self.tree(files, rules={"yaml_cpp_files": ["scene/s.cc"]})
        self.assertEqual(t.rules()[0], 0)
        t = self.tree({"src/penumbra/scene/s.cc": "// no yaml\n"},
                      rules={"yaml_cpp_files": ["scene/s.cc"]})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("yaml_cpp_files lists scene/s.cc, which no longer includes yaml-cpp", out)

    def test_yaml_cpp_in_tests_or_bench_fails(self):
        t = self.tree({"tests/scene/s_test.cc": '#include "penumbra/config/yaml_document.h"\n',
                       "bench/b.cc": "// x\n"})
        self.assertEqual(t.rules()[0], 0)
        t = self.tree({"tests/scene/s_test.cc": "#include <yaml-cpp/yaml.h>\n"})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("tests/scene/s_test.cc:1: includes yaml-cpp", out)
        t = self.tree({"bench/b.cc": "// b\n#include <yaml-cpp/yaml.h>\n"})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("bench/b.cc:2: includes yaml-cpp", out)

    def test_whole_file_read_by_hand_fails(self):
        body = "std::string f(std::ifstream& in) {\n  std::ostringstream s;\n  s << in.rdbuf();\n}\n"
        t = self.tree({"src/penumbra/core/input_file.cc": body})
        self.assertEqual(t.rules()[0], 0)
        t = self.tree({"src/penumbra/scene/s.cc": body})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("src/penumbra/scene/s.cc:3: reads a file whole by hand; expected files read "
                      "whole through core/input_file.h", out)
        it = "auto b = std::string(std::istreambuf_iterator<char>(in), {});\n"
        t = self.tree({"src/penumbra/scene/s.cc": it})
        self.assertEqual(t.rules()[0], 1)
        # the allow-list passes it and may only shrink
        t = self.tree({"src/penumbra/scene/s.cc": body},
                      rules={"whole_file_reads": ["scene/s.cc"]})
        self.assertEqual(t.rules()[0], 0)
        t = self.tree({"src/penumbra/scene/s.cc": "// read through core/input_file.h\n"},
                      rules={"whole_file_reads": ["scene/s.cc"]})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("whole_file_reads lists scene/s.cc, which no longer reads a file whole by "
                      "hand", out)

    def test_json_in_a_header_fails(self):
        t = self.tree({"src/penumbra/scene/s.h": "#pragma once\n#include <nlohmann/json.hpp>\n"})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("src/penumbra/scene/s.h:2: includes nlohmann/json.hpp", out)
        t = self.tree({"src/penumbra/scene/s.h": "#include <nlohmann/json_fwd.hpp>\n"})
        self.assertEqual(t.rules()[0], 1)

    def test_eleventh_module_dep_fails_but_app_is_exempt(self):
        many = ["m%d" % i for i in range(11)]
        table = "".join(f"{m}:\n" for m in many) + "big: " + " ".join(many) + "\n"
        table += "app: big " + " ".join(many) + "\nmain: app\n"
        t = self.tree({}, table=table)
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("big has 11 module deps; expected at most 10", out)
        self.assertNotIn("app has", out)
        t = self.tree({}, table=table, rules={"module_deps_allowed": {"big": 11}})
        self.assertEqual(t.rules()[0], 0)
        # the ceiling may only shrink: a module below its ceiling asks for it to be lowered
        t = self.tree({}, table=table, rules={"module_deps_allowed": {"big": 12}})
        rc, out = t.rules()
        self.assertEqual(rc, 1)
        self.assertIn("gives big 12 but it has 11", out)

    @unittest.skipIf(CXX is None, "no g++")
    def test_preprocessed_lines_budget(self):
        t = self.tree({"src/penumbra/core/a.cc": '#include "big.h"\nint a() { return 1; }\n',
                       "src/penumbra/core/big.h": "".join(f"int v{i} = {i};\n"
                                                          for i in range(500))})
        cc = [{"directory": t.root, "file": os.path.join(t.root, "src/penumbra/core/a.cc"),
               "command": f"{CXX} -I{t.root}/src/penumbra/core -c "
                          f"{t.root}/src/penumbra/core/a.cc -o a.o"}]
        t.write("compile_commands.json", json.dumps(cc))
        path = os.path.join(t.root, "compile_commands.json")
        rc, out = t.rules("--compile-commands", path)
        self.assertEqual(rc, 0, out)
        t.write("scripts/build_rules.json",
                json.dumps(dict(BASE_RULES, preprocessed_lines={"per_unit": 400,
                                                                "total": 10000000})))
        rc, out = t.rules("--compile-commands", path)
        self.assertEqual(rc, 1)
        self.assertIn("a.cc: ", out)
        self.assertIn("expected at most 400 per translation unit", out)
        t.write("scripts/build_rules.json",
                json.dumps(dict(BASE_RULES, preprocessed_lines={"per_unit": 100000,
                                                                "total": 300})))
        rc, out = t.rules("--compile-commands", path)
        self.assertEqual(rc, 1)
        self.assertIn("expected at most 300", out)


class ModuleDocsTest(unittest.TestCase):
    def tree(self, **kw):
        t = Tree({}, **kw)
        self.addCleanup(t.dir.cleanup)
        return t

    def test_stale_docs_fail_and_written_docs_pass(self):
        t = self.tree()
        rc, out = t.docs()
        self.assertEqual(rc, 1)
        self.assertIn("README.md: the generated module block is stale", out)
        self.assertIn("docs/architecture.md: the generated module block is stale", out)
        self.assertEqual(t.docs("--write")[0], 0)
        rc, out = t.docs()
        self.assertEqual(rc, 0, out)
        with open(os.path.join(t.root, "README.md"), encoding="utf-8") as f:
            readme = f.read()
        self.assertIn("  scene/           what the renderer sees over two lines", readme)
        self.assertIn("  main.cc          the executable", readme)
        self.assertTrue(readme.endswith("<!-- /modules -->\n\nend\n"))
        with open(os.path.join(t.root, "docs/architecture.md"), encoding="utf-8") as f:
            arch = f.read()
        self.assertIn("| 1 | `scene` | core | what the renderer sees over two lines |", arch)
        self.assertIn("| 3 | `main` | app | the executable |", arch)
        self.assertNotIn("old", arch)
        # a new edge in DEPENDENCIES makes the table stale again
        t.write("src/penumbra/DEPENDENCIES", "core:\nscene: core\napp: scene core\nmain: app core\n")
        rc, out = t.docs()
        self.assertEqual(rc, 1)
        self.assertIn("docs/architecture.md: the generated module block is stale", out)

    def test_module_without_entry_fails(self):
        t = self.tree(table=TABLE + "extra: core\n")
        rc, out = t.docs()
        self.assertEqual(rc, 1)
        self.assertIn("no entry for module 'extra'", out)

    def test_entry_without_module_fails(self):
        t = self.tree(modules=MODULES + "ghost: gone\n")
        rc, out = t.docs()
        self.assertEqual(rc, 1)
        self.assertIn("entry 'ghost' names no module", out)

    def test_missing_marker_fails(self):
        t = self.tree()
        t.write("README.md", "# no markers\n")
        rc, out = t.docs("--write")
        self.assertEqual(rc, 1)
        self.assertIn("README.md: no <!-- modules:layout --> marker", out)


if __name__ == "__main__":
    unittest.main()
