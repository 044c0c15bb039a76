#!/usr/bin/env python3
"""Runs the commands of the documentation (the user guide docs/guide/*.md, then README.md and
the rest of docs/), so the docs cannot rot.

Every ```bash / ```sh block is preceded by a marker that says what to do with it:

    <!-- doc-test: run -->                the block runs (bash -e) and must exit 0
    <!-- doc-test: output "TEXT" -->      the block runs (no -e); its output must contain TEXT
    <!-- doc-test: run given: SETUP -->   SETUP (shell) first makes what the block says is the
                                          reader's own (a capture, photos, control points) from
                                          bundled, synthetic or ../shared/data files; then the
                                          block runs (bash -e) and must exit 0
    <!-- doc-test: mirror: T1, T2: WHY --> not run here (WHY: a window, two programs at once,
                                          minutes); the tests T1, T2 (GoogleTest Suite.Name or
                                          CTest names) do what it does, and must exist
    <!-- doc-test: ci: WHY -->            CI's own commands (the quick start, the test and
                                          sanitizer scripts: running them here would run CI
                                          inside CI); checked instead: its first `bash .ci/X`
                                          is one .ci/run reaches (CI runs it on every change),
                                          every script and test program it names exists and
                                          every `ctest -R NAME` names a test
    <!-- doc-test: skip: REASON -->       not run and not mirrored; REASON says why

A block without a marker fails this test: a new command in the guide has to say whether it
runs. Blocks run in a scratch folder holding copies of projects/ and docs/images/ (so the
guide's relative paths and outputs work without touching the repository), `build/app/fresco`
pointing at the program under test and, beside it, `../shared` when the repository has it
(the bundled projects that paint real data name it so); a block whose SETUP or code names
`shared/data` is skipped, saying so, when that folder is absent. The files run in the order
below, the blocks of a file in their order (later blocks use earlier outputs, as a reader
would).

Usage: run_guide_commands.py FRESCO [--list]
"""
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ORDER = ["painting.md", "automation.md", "calibration.md", "poses.md", "live.md"]
MARKER = re.compile(r"<!--\s*doc-test:\s*(run given:\s*(.+?)|run|output\s+\"([^\"]*)\"|"
                    r"mirror:\s*(.+?)|skip:\s*(.+?)|ci:\s*(.+?))\s*-->")
SHARED = os.path.join(os.path.dirname(ROOT), "shared")
TEST_NAME = re.compile(r"^\s*(?:TEST|TEST_F|TEST_P)\(\s*(\w+)\s*,\s*(\w+)\s*\)", re.M)
CTEST_NAME = re.compile(r"add_test\(\s*NAME\s+(\w+)|fresco_add_test\(\s*(\w+)")


def known_tests():
    """GoogleTest Suite.Name of every test in tests/, and every CTest name in its CMakeLists."""
    names = set()
    for folder, _, files in os.walk(os.path.join(ROOT, "tests")):
        for f in files:
            text = open(os.path.join(folder, f), errors="replace").read()
            if f.endswith(".cc"):
                names.update(f"{a}.{b}" for a, b in TEST_NAME.findall(text))
            elif f == "CMakeLists.txt":
                names.update(a or b for a, b in CTEST_NAME.findall(text))
    return names


def ci_scripts():
    """The .ci scripts CI runs: .ci/run and every `bash .ci/X` those scripts run, in turn."""
    reached, todo = set(), [".ci/run"]
    while todo:
        script = todo.pop()
        if script in reached or not os.path.exists(os.path.join(ROOT, script)):
            continue
        reached.add(script)
        text = open(os.path.join(ROOT, script)).read()
        todo += re.findall(r"^\s*(?:[\w$(){}\"=]+\s+)*bash\s+(\.ci/[\w-]+)", text, re.M)
    return reached


def check_ci_block(code, tests):
    """What is wrong with a `ci:` block (a list of messages; empty when nothing is)."""
    problems = []
    commands = [l.split("#")[0].strip() for l in code.splitlines()]
    commands = [c for c in commands if c]
    first = next((re.search(r"bash\s+(\.ci/[\w-]+)", c) for c in commands
                  if re.search(r"bash\s+\.ci/", c)), None)
    if not first:
        problems.append("names no `bash .ci/...` script")
    elif first.group(1) not in ci_scripts():
        problems.append(f"{first.group(1)} is not run by CI (.ci/run does not reach it)")
    for c in commands:
        for path in re.findall(r"(?<![\w/])((?:\.ci|tests)/[\w/.-]+)", c):
            if not os.path.exists(os.path.join(ROOT, path)):
                problems.append(f"{path} does not exist")
        for name in re.findall(r"ctest\s+(?:-\S+\s+)*-R\s+(\w+)", c):
            if name not in tests:
                problems.append(f"no test named {name}")
        for program in re.findall(r"(?<![\w/])build[\w-]*/tests/(?:\w+/)*(\w+)", c):
            if not any(program + ".cc" in files for _, _, files in os.walk(os.path.join(ROOT, "tests"))):
                problems.append(f"no test program {program} (tests/**/{program}.cc)")
    return problems


def blocks(path):
    """(line, marker kind, argument, code) for every bash/sh block of the file."""
    lines = open(path).read().splitlines()
    out = []
    i = 0
    while i < len(lines):
        if re.match(r"^```(bash|sh)\s*$", lines[i]):
            start = i
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            code = "\n".join(lines[i + 1:j])
            k = start - 1
            while k >= 0 and not lines[k].strip():
                k -= 1
            m = MARKER.search(lines[k]) if k >= 0 else None
            if not m:
                out.append((start + 1, None, None, code))
            elif m.group(2) is not None:
                out.append((start + 1, "given", m.group(2), code))
            elif m.group(1) == "run":
                out.append((start + 1, "run", None, code))
            elif m.group(3) is not None:
                out.append((start + 1, "output", m.group(3), code))
            elif m.group(4) is not None:
                out.append((start + 1, "mirror", m.group(4), code))
            elif m.group(6) is not None:
                out.append((start + 1, "ci", m.group(6), code))
            else:
                out.append((start + 1, "skip", m.group(5), code))
            i = j + 1
        else:
            i += 1
    return out


def main():
    fresco = os.path.realpath(sys.argv[1])
    guide = os.path.join(ROOT, "docs", "guide")
    files = [os.path.join("docs", "guide", f) for f in
             ORDER + sorted(f for f in os.listdir(guide) if f.endswith(".md") and f not in ORDER)]
    # Then the README and the rest of docs/ (results, reference, architecture, contract).
    files += ["README.md"] + sorted(
        os.path.relpath(os.path.join(folder, f), ROOT)
        for folder in (os.path.join(ROOT, "docs"), os.path.join(ROOT, "docs", "reference"))
        for f in os.listdir(folder) if f.endswith(".md"))
    # The scratch repository sits in a folder of its own, with ../shared beside it when the
    # repository has one (project files name ../../../shared/data).
    outer = tempfile.mkdtemp(prefix="fresco-guide-")
    scratch = os.path.join(outer, "main")
    os.makedirs(scratch)
    has_shared = os.path.isdir(os.path.join(SHARED, "data"))
    if has_shared:
        os.symlink(SHARED, os.path.join(outer, "shared"))
    tests = known_tests()
    errors, ran, mirrored, cied, skipped = [], 0, 0, 0, 0
    started = time.time()
    try:
        shutil.copytree(os.path.join(ROOT, "projects"), os.path.join(scratch, "projects"),
                        symlinks=True)
        os.makedirs(os.path.join(scratch, "docs"))
        shutil.copytree(os.path.join(ROOT, "docs", "images"), os.path.join(scratch, "docs", "images"))
        os.makedirs(os.path.join(scratch, "build", "app"))
        os.symlink(fresco, os.path.join(scratch, "build", "app", "fresco"))
        for name in files:
            path = os.path.join(ROOT, name)
            if not os.path.exists(path):
                continue
            for line, kind, arg, code in blocks(path):
                where = f"{name}:{line}"
                if kind is None:
                    errors.append(f"{where}: a command block without a doc-test marker "
                                  "(<!-- doc-test: run --> or <!-- doc-test: skip: REASON -->)")
                    continue
                if kind == "skip":
                    skipped += 1
                    print(f"skip {where}: {arg}")
                    continue
                if kind == "ci":
                    for problem in check_ci_block(code, tests):
                        errors.append(f"{where}: CI's commands: {problem}")
                    cied += 1
                    print(f"ci   {where}: {arg}")
                    continue
                if kind == "mirror":
                    names = [n.strip() for n in arg.split(":")[0].split(",")]
                    missing = [n for n in names if n not in tests]
                    if missing:
                        errors.append(f"{where}: mirrored by tests that do not exist: "
                                      f"{', '.join(missing)}")
                    mirrored += 1
                    print(f"mirror {where}: {', '.join(names)}")
                    continue
                setup = arg if kind == "given" else ""
                if "shared/data" in setup + code and not has_shared:
                    skipped += 1
                    print(f"skip {where}: needs ../shared/data beside the repository (absent)")
                    continue
                if "--list" in sys.argv:
                    print(f"run  {where}")
                    continue
                script = (("set -e\n" if kind in ("run", "given") else "") +
                          (setup + "\n" if setup else "") + code + "\n")
                start = time.time()
                cpu_before = resource.getrusage(resource.RUSAGE_CHILDREN)
                r = subprocess.run(["bash", "-c", script], cwd=scratch, capture_output=True,
                                   text=True, timeout=600)
                output = r.stdout + r.stderr
                ran += 1
                cpu_after = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpu = (cpu_after.ru_utime + cpu_after.ru_stime -
                       cpu_before.ru_utime - cpu_before.ru_stime)
                print(f"run  {where}: exit {r.returncode} in {time.time() - start:.1f} s "
                      f"({cpu:.1f} s CPU)")
                if kind in ("run", "given") and r.returncode != 0:
                    errors.append(f"{where}: exit {r.returncode}\n{code}\n--- output:\n{output[-2000:]}")
                if kind == "output" and arg not in output:
                    errors.append(f"{where}: output lacks '{arg}'\n{code}\n--- output:\n{output[-2000:]}")
    finally:
        shutil.rmtree(outer, ignore_errors=True)
    for e in errors:
        print("FAIL " + e)
    print(f"run_guide_commands: {ran} blocks run, {mirrored} mirrored by tests, {cied} CI's "
          f"own (checked), {skipped} skipped (each with its reason), {len(errors)} problems, "
          f"{time.time() - started:.0f} s")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
