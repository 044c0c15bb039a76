#!/usr/bin/env python3
"""Runs the commands of the user guide (docs/guide/*.md), so the guide cannot rot.

Every ```bash / ```sh block in the guide is preceded by a marker that says what to do with it:

    <!-- doc-test: run -->                the block runs (bash -e) and must exit 0
    <!-- doc-test: output "TEXT" -->      the block runs (no -e); its output must contain TEXT
    <!-- doc-test: skip: REASON -->       not run here; REASON says why (and what covers it)

A block without a marker fails this test: a new command in the guide has to say whether it
runs. Blocks run in a scratch folder holding copies of projects/ and docs/images/ (so the
guide's relative paths and outputs work without touching the repository) and `build/app/fresco`
pointing at the program under test; the files run in the order below, the blocks of a file in
their order (later blocks use earlier outputs, as a reader would).

Usage: run_guide_commands.py FRESCO [--list]
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ORDER = ["painting.md", "automation.md", "calibration.md", "poses.md", "live.md"]
MARKER = re.compile(r"<!--\s*doc-test:\s*(run|output\s+\"([^\"]*)\"|skip:\s*(.+?))\s*-->")


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
            elif m.group(1) == "run":
                out.append((start + 1, "run", None, code))
            elif m.group(2) is not None:
                out.append((start + 1, "output", m.group(2), code))
            else:
                out.append((start + 1, "skip", m.group(3), code))
            i = j + 1
        else:
            i += 1
    return out


def main():
    fresco = os.path.realpath(sys.argv[1])
    guide = os.path.join(ROOT, "docs", "guide")
    files = ORDER + sorted(f for f in os.listdir(guide) if f.endswith(".md") and f not in ORDER)
    scratch = tempfile.mkdtemp(prefix="fresco-guide-")
    errors, ran, skipped = [], 0, 0
    started = time.time()
    try:
        shutil.copytree(os.path.join(ROOT, "projects"), os.path.join(scratch, "projects"),
                        symlinks=True)
        os.makedirs(os.path.join(scratch, "docs"))
        shutil.copytree(os.path.join(ROOT, "docs", "images"), os.path.join(scratch, "docs", "images"))
        os.makedirs(os.path.join(scratch, "build", "app"))
        os.symlink(fresco, os.path.join(scratch, "build", "app", "fresco"))
        for name in files:
            path = os.path.join(guide, name)
            if not os.path.exists(path):
                continue
            for line, kind, arg, code in blocks(path):
                where = f"docs/guide/{name}:{line}"
                if kind is None:
                    errors.append(f"{where}: a command block without a doc-test marker "
                                  "(<!-- doc-test: run --> or <!-- doc-test: skip: REASON -->)")
                    continue
                if kind == "skip":
                    skipped += 1
                    print(f"skip {where}: {arg}")
                    continue
                if "--list" in sys.argv:
                    print(f"run  {where}")
                    continue
                script = ("set -e\n" if kind == "run" else "") + code + "\n"
                start = time.time()
                r = subprocess.run(["bash", "-c", script], cwd=scratch, capture_output=True,
                                   text=True, timeout=600)
                output = r.stdout + r.stderr
                ran += 1
                print(f"run  {where}: exit {r.returncode} in {time.time() - start:.1f} s")
                if kind == "run" and r.returncode != 0:
                    errors.append(f"{where}: exit {r.returncode}\n{code}\n--- output:\n{output[-2000:]}")
                if kind == "output" and arg not in output:
                    errors.append(f"{where}: output lacks '{arg}'\n{code}\n--- output:\n{output[-2000:]}")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    for e in errors:
        print("FAIL " + e)
    print(f"run_guide_commands: {ran} blocks run, {skipped} skipped (each with its reason), "
          f"{len(errors)} problems, {time.time() - started:.0f} s")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
