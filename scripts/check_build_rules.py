#!/usr/bin/env python3
"""Checks the rules that keep the build small, beside
scripts/check_module_deps.py. The rules and their allow-lists live in scripts/build_rules.json:

  yaml-cpp        `#include <yaml-cpp/...>` only in src/penumbra/config/*.cc, or in a file of the
                  allow-list "yaml_cpp_files" (the list may only shrink: an entry whose file no
                  longer includes yaml-cpp is an error too, remove it); the C++ of tests/, bench/,
                  fuzz/, tools/ and python/ is held to it too (a test parses YAML through
                  config/yaml_document.h)
  whole-file      no hand-written whole-file read in src/ (`<< in.rdbuf()`,
                  `std::istreambuf_iterator`): read a file whole through core/input_file.h
                  (ReadInputFile: size checked before allocation, errors naming the file), or list
                  the file in the allow-list "whole_file_reads" (it may only shrink)
  json-header     no `#include <nlohmann/json.hpp>` (or json_fwd.hpp) in a header of src/, except
                  the allow-list "json_headers" (same rule: it may only shrink)
  module-deps     at most "max_module_deps" modules on a line of src/penumbra/DEPENDENCIES;
                  "module_deps_exempt" (app, main) have no limit and "module_deps_allowed" holds
                  today's larger modules with their count as a ceiling (lower it when a module
                  sheds deps; the checker says so)
  sensor-kinds    no string literal that is a sensor type's name ("lidar", "imu", ...: the kTypeName
                  of each src/penumbra/sensors/types/*.h) in src/penumbra outside sensors/types/
                  and world/ (go through the registry, sensors/sensor_types.h: SensorKind,
                  SensorKindName, the types' kOutputFolder); comments do not count. the
                  allow-list "sensor_kind_literals" maps a file to the literals it may hold
                  with another meaning (an MJCF <mujoco> element, a CLI option); it may only
                  shrink
  preprocessed    with --compile-commands: `g++ -E -fdirectives-only` of every C++ translation
                  unit of the build; fails when one is above "preprocessed_lines.per_unit" or all together above
                  "preprocessed_lines.total" (scripts/build_stats/preprocessed_lines.py measures
                  them; raise the budget only with a reason in the commit)

  python3 scripts/check_build_rules.py [--root DIR] [--compile-commands build/compile_commands.json]
      [--jobs N]

exit 0 when every rule holds, 1 with one line per violation (file:line and what was expected).
Standard library only; g++ runs without a shell.
"""

import argparse
import json
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import check_module_deps  # noqa: E402

YAML_RE = re.compile(r'^\s*#\s*include\s*[<"]yaml-cpp/')
WHOLE_FILE_RE = re.compile(r'^.*?((<<\s*\w+(\.|->)rdbuf\(\))|istreambuf_iterator)')
# folders beside src/penumbra whose C++ the yaml-cpp rule covers too (relative to the root)
OTHER_CODE = ("tests", "bench", "fuzz", "tools", "python")
JSON_RE = re.compile(r'^\s*#\s*include\s*[<"]nlohmann/json(_fwd)?\.hpp[>"]')
HEADER_EXTS = (".h", ".hpp", ".hh")
SOURCE_EXTS = (".h", ".hpp", ".hh", ".cc", ".cpp", ".cu", ".cuh")


def load_rules(root):
    path = os.path.join(root, "scripts", "build_rules.json")
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def source_files(src):
    """paths relative to src (forward slashes) of every C++ source and header, sorted."""
    out = []
    for folder, dirs, files in os.walk(src):
        dirs.sort()
        for name in sorted(files):
            if name.endswith(SOURCE_EXTS):
                rel = os.path.relpath(os.path.join(folder, name), src).replace(os.sep, "/")
                out.append(rel)
    return out


def first_match(path, regex):
    """1-based line of the first line of path matching regex, or 0."""
    with open(path, encoding="utf-8", errors="replace") as f:
        for n, line in enumerate(f, start=1):
            if regex.match(line):
                return n
    return 0


def check_includes(src, files, regex, allowed, allowed_key, is_subject, what, expected,
                   verb="includes"):
    errors = []
    found = set()
    for rel in files:
        if not is_subject(rel):
            continue
        n = first_match(os.path.join(src, rel), regex)
        if not n:
            continue
        found.add(rel)
        if rel not in allowed:
            errors.append(f"src/penumbra/{rel}:{n}: {verb} {what}; expected {expected}")
    for rel in sorted(set(allowed) - found):
        errors.append(f"scripts/build_rules.json: {allowed_key} lists {rel}, which no longer "
                      f"{verb} {what}; remove it from the list (it may only shrink)")
    return errors


def check_other_code(root):
    """yaml-cpp includes in the C++ outside src/penumbra (tests, benchmarks, fuzz targets, ...)."""
    errors = []
    for folder in OTHER_CODE:
        base = os.path.join(root, folder)
        if not os.path.isdir(base):
            continue
        for rel in source_files(base):
            n = first_match(os.path.join(base, rel), YAML_RE)
            if n:
                errors.append(f"{folder}/{rel}:{n}: includes yaml-cpp; expected yaml-cpp only in "
                              "src/penumbra/config/*.cc (parse YAML with "
                              "penumbra/config/yaml_document.h)")
    return errors


def check_sources(root, rules):
    src = os.path.join(root, "src", "penumbra")
    files = source_files(src)
    errors = []
    errors += check_includes(
        src, files, YAML_RE, rules.get("yaml_cpp_files", []), "yaml_cpp_files",
        lambda rel: not (rel.startswith("config/") and rel.endswith(".cc")), "yaml-cpp",
        "yaml-cpp only in src/penumbra/config/*.cc (read parameters through config/)")
    errors += check_other_code(root)
    errors += check_includes(
        src, files, WHOLE_FILE_RE, rules.get("whole_file_reads", []), "whole_file_reads",
        lambda rel: rel != "core/input_file.cc", "a file whole by hand",
        "files read whole through core/input_file.h (ReadInputFile: size checked before "
        "allocation, errors naming the file)", verb="reads")
    errors += check_includes(
        src, files, JSON_RE, rules.get("json_headers", []), "json_headers",
        lambda rel: rel.endswith(HEADER_EXTS), "nlohmann/json.hpp",
        "no json.hpp in headers (include it in the .cc; pass a forward-declared type or a "
        "string across the header)")
    errors += check_module_deps_count(root, rules)
    errors += check_sensor_kind_literals(src, files, rules)
    return errors


TYPE_NAME_RE = re.compile(r'\bkTypeName\s*=\s*"([^"]*)"')
# a C++ string literal (no raw strings in this code base), or a comment to skip
TOKEN_RE = re.compile(r'//[^\n]*|/\*.*?\*/|"((?:[^"\\\n]|\\.)*)"|\'(?:[^\'\\\n]|\\.)*\'',
                      re.S)
SENSOR_KIND_HOMES = ("sensors/types/", "world/")


def sensor_type_names(src, files):
    """the kTypeName of every sensor type header (sensors/types/*.h)."""
    names = set()
    for rel in files:
        if rel.startswith("sensors/types/") and rel.endswith(HEADER_EXTS):
            with open(os.path.join(src, rel), encoding="utf-8", errors="replace") as f:
                names.update(TYPE_NAME_RE.findall(f.read()))
    return names


def string_literals(text):
    """(1-based line, content) of every string literal of C++ source `text`, comments skipped."""
    out = []
    for m in TOKEN_RE.finditer(text):
        if m.group(1) is not None:
            out.append((text.count("\n", 0, m.start()) + 1, m.group(1)))
    return out


def check_sensor_kind_literals(src, files, rules):
    names = sensor_type_names(src, files)
    allowed = rules.get("sensor_kind_literals", {})
    if not names:
        return [] if not allowed else [
            "src/penumbra/sensors/types/: no sensor type (kTypeName) found; expected the "
            "registry of sensor types there"]
    errors = []
    found = set()
    for rel in files:
        if rel.startswith(SENSOR_KIND_HOMES):
            continue
        with open(os.path.join(src, rel), encoding="utf-8", errors="replace") as f:
            text = f.read()
        for line, literal in string_literals(text):
            if literal not in names:
                continue
            if literal in allowed.get(rel, []):
                found.add((rel, literal))
                continue
            errors.append(f'src/penumbra/{rel}:{line}: sensor type name "{literal}" as a string '
                          "literal; expected the sensor registry (sensors/sensor_types.h: "
                          "SensorKind, SensorKindName, the type's kOutputFolder) outside "
                          "sensors/types/ and world/")
    for rel in sorted(allowed):
        if rel.startswith("_"):
            continue
        for literal in allowed[rel]:
            if (rel, literal) not in found:
                errors.append(f'scripts/build_rules.json: sensor_kind_literals lists "{literal}" '
                              f"in {rel}, which no longer holds it; remove it (the list may "
                              "only shrink)")
    return errors


def check_module_deps_count(root, rules):
    table_path = os.path.join(root, "src", "penumbra", "DEPENDENCIES")
    table, table_errors = check_module_deps.read_table(table_path, "src/penumbra/DEPENDENCIES")
    if table_errors:
        return table_errors
    limit = int(rules.get("max_module_deps", 10))
    exempt = set(rules.get("module_deps_exempt", []))
    allowed = rules.get("module_deps_allowed", {})
    errors = []
    for module, deps in table.deps.items():
        if module in exempt:
            continue
        ceiling = int(allowed.get(module, limit))
        n = len(deps)
        where = f"src/penumbra/DEPENDENCIES:{table.lines[module]}"
        if n > ceiling:
            if module in allowed:
                errors.append(f"{where}: {module} has {n} module deps; its allow-list ceiling "
                              f"is {ceiling} (scripts/build_rules.json module_deps_allowed) and "
                              "may only shrink: split the module instead")
            else:
                errors.append(f"{where}: {module} has {n} module deps; expected at most "
                              f"{limit}: cut the module by job")
        elif module in allowed and n < ceiling:
            errors.append(f"scripts/build_rules.json: module_deps_allowed gives {module} "
                          f"{ceiling} but it has {n}; lower the ceiling to {max(n, limit)} "
                          "(or remove the entry at or below the limit)")
    for module in sorted(set(allowed) - set(table.deps)):
        errors.append(f"scripts/build_rules.json: module_deps_allowed lists {module}, which "
                      "has no line in src/penumbra/DEPENDENCIES; remove it")
    return errors


def check_preprocessed(compile_commands, rules, jobs):
    sys.path.insert(0, os.path.join(HERE, "build_stats"))
    import preprocessed_lines  # noqa: E402

    budget = rules["preprocessed_lines"]
    records = preprocessed_lines.run(compile_commands, jobs, headers=False)
    errors = []
    per_unit = int(budget["per_unit"])
    for r in sorted(records, key=lambda r: -r["lines"]):
        if r["lines"] > per_unit:
            errors.append(f"{r['file']}: {r['lines']} preprocessed lines; expected at most "
                          f"{per_unit} per translation unit (scripts/build_rules.json): keep "
                          "heavy includes out of headers")
    total = sum(r["lines"] for r in records)
    if total > int(budget["total"]):
        errors.append(f"{compile_commands}: {total} preprocessed lines in {len(records)} "
                      f"translation units; expected at most {budget['total']} "
                      "(scripts/build_rules.json preprocessed_lines.total)")
    print(f"preprocessed lines: {total} in {len(records)} translation units (budget "
          f"{budget['total']}, at most {per_unit} each; largest "
          f"{max((r['lines'] for r in records), default=0)})")
    return errors


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.dirname(HERE))
    ap.add_argument("--compile-commands")
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args(argv)
    rules = load_rules(a.root)
    if a.compile_commands:
        errors = check_preprocessed(a.compile_commands, rules, a.jobs)
    else:
        errors = check_sources(a.root, rules)
    for e in errors:
        print(e)
    if not errors:
        print("build rules OK")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
