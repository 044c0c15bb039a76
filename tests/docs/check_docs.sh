#!/usr/bin/env bash
# Keeps the documentation from rotting. Checks, over README.md, CHANGELOG.md and docs/**/*.md:
#   - README.md is at most 200 lines (the front door stays short);
#   - every package the README's `apt install` line names is one .ci/setup installs;
#   - no issue numbers in user-facing text (the word issue followed by a number);
#   - every relative link and picture resolves, and every #anchor names a heading;
#   - every `fresco VERB [SUBVERB]` in code exists, and every --option written after it is
#     one that verb's --help lists;
#   - docs/reference/cli.md is exactly what tests/docs/make_cli_reference.sh writes now;
#   - every key the project-file reader accepts (Fields() in pipeline/core/project.cc and the
#     painting settings in pipeline/settings/*.h) is in
#     docs/reference/project-file.md, and every key that page's tables name is accepted;
#   - every settings row there is the one `fresco settings --markdown` makes (default, range
#     and meaning from the declarations);
#   - docs/contract.md equals ../shared/CONTRACT.md where that file exists;
#   - no merge conflict markers in any text file of the tree.
# Usage: bash tests/docs/check_docs.sh [FRESCO]   (default build/app/fresco; run from anywhere)
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
fresco="$(realpath "${1:-$root/build/app/fresco}")"
cd "$root"
fail=0

# The CLI reference against the program's own --help text.
if ! diff -u docs/reference/cli.md <(bash tests/docs/make_cli_reference.sh "$fresco") \
    > /tmp/fresco-docs-cli.diff.$$; then
  echo "docs/reference/cli.md differs from the --help text (diff below); regenerate it with:"
  echo "  bash tests/docs/make_cli_reference.sh build/app/fresco > docs/reference/cli.md"
  head -40 /tmp/fresco-docs-cli.diff.$$
  fail=1
fi
rm -f /tmp/fresco-docs-cli.diff.$$

if [ -f ../shared/CONTRACT.md ] && ! cmp -s ../shared/CONTRACT.md docs/contract.md; then
  echo "docs/contract.md differs from ../shared/CONTRACT.md: copy the contract's text verbatim"
  fail=1
fi

/usr/bin/python3 - "$fresco" <<'PY' || fail=1
import functools, os, re, subprocess, sys

fresco = sys.argv[1]
files = ["README.md", "CHANGELOG.md"] + sorted(
    os.path.join(d, f) for d, _, fs in os.walk("docs") for f in fs if f.endswith(".md"))
errors = []

def err(msg):
    errors.append(msg)

# README length.
n = len(open("README.md").read().splitlines())
if n > 200:
    err(f"README.md: {n} lines (at most 200)")

# The README's build dependencies (its `apt install` line) are all installed by .ci/setup,
# which CI and the quick start run: a package named only in the README would go untested.
readme = open("README.md").read()
apt = re.search(r"apt install ((?:[^\n]*\\\n)*[^\n]*)", readme)
setup = open(".ci/setup").read()
listed = re.search(r"PACKAGES=\((.*?)\)", setup, re.S)
if not apt or not listed:
    err("README.md / .ci/setup: the apt install line or the PACKAGES list is missing")
else:
    wanted = set(apt.group(1).replace("\\", " ").split())
    missing = sorted(wanted - set(listed.group(1).split()))
    if missing:
        err(f"README.md: apt install names packages .ci/setup does not install: {', '.join(missing)}")

def slug(heading):  # GitHub's anchor for a heading
    s = heading.strip().lower()
    s = re.sub(r"[^\w\- ]", "", s)
    return s.replace(" ", "-")

@functools.lru_cache(maxsize=None)
def anchors(path):
    text = open(path).read()
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    return {slug(m.group(1)) for m in re.finditer(r"^#+\s+(.*)$", text, re.M)}

@functools.lru_cache(maxsize=None)
def help_text_cached(args):
    r = subprocess.run([fresco] + list(args) + ["--help"], capture_output=True, text=True)
    return r.stdout + r.stderr

def help_text(args):
    return help_text_cached(tuple(args))

main_help = help_text([])
verbs = set(re.findall(r"^  (\w+) ", main_help, re.M))
if not verbs:
    err(f"{fresco} --help lists no verbs")
helps = {}

# The contract (docs/contract.md, ../shared/CONTRACT.md verbatim) may name verbs and options
# an open issue is still building: those are listed as not implemented yet, not errors. Every
# other page may name only what `fresco` does.
pending = []

def check_command(path, line_no, cmd):
    err = (lambda msg: pending.append(msg)) if path == "docs/contract.md" else globals()["err"]
    m = re.search(r"(?:^|[\s/`(])fresco (\w+)(?: (\w+))?(.*)", cmd)
    if not m:
        return
    verb, sub, rest = m.group(1), m.group(2), m.group(3) or ""
    if not re.fullmatch(r"[a-z]+", verb):
        return  # a placeholder (VERB) or a version (fresco 0.9.0)
    if verb not in verbs:
        err(f"{path}:{line_no}: 'fresco {verb}': no such verb in fresco --help")
        return
    key = [verb]
    if verb in ("calib", "poses"):
        if sub is None or sub.startswith("-"):
            return
        if not re.search(rf"fresco {verb} {sub}\b", help_text([verb])):
            err(f"{path}:{line_no}: 'fresco {verb} {sub}': no such subverb")
            return
        key.append(sub)
    else:
        rest = (" " + sub + rest) if sub else rest
    text = helps.setdefault(tuple(key), help_text(key))
    rest = re.split(r"\s(?:#|\||&&|;|>)\s|`", rest)[0]
    for opt in re.findall(r"(?:^|\s)(--[a-z][a-z0-9-]*)", rest):
        if opt not in ("--help", "--version") and not re.search(rf"(?<![\w-]){opt}(?![\w-])", text):
            err(f"{path}:{line_no}: 'fresco {' '.join(key)} {opt}': not in its --help")

# Merge conflict markers left in any text file of the tree (a merge that was committed
# unresolved): "<<<<<<< " and ">>>>>>> " at the start of a line.
for d, dirs, fs in os.walk("."):
    dirs[:] = [x for x in dirs if not x.startswith(".") and not x.startswith("build")]
    for f in fs:
        if not f.endswith((".md", ".cc", ".h", ".txt", ".json", ".sh", ".py", ".cmake", ".1")):
            continue
        path = os.path.relpath(os.path.join(d, f))
        with open(path, errors="replace") as fh:
            for line_no, line in enumerate(fh, 1):
                if line.startswith(("<<<<<<< ", ">>>>>>> ")):
                    err(f"{path}:{line_no}: merge conflict marker")

for path in files:
    text = open(path).read()
    lines = text.splitlines()
    user_facing = path != "docs/contract.md"
    in_code = False
    joined, start = "", 0
    for i, line in enumerate(lines, 1):
        if line.lstrip().startswith("```"):
            in_code = not in_code
            continue
        if user_facing and re.search(r"\bissues? #?\d+", line, re.I):
            err(f"{path}:{i}: issue number in user-facing text: {line.strip()[:80]}")
        # Links and pictures (not inside code).
        if not in_code:
            for target in re.findall(r"\]\(([^)\s]+)\)", re.sub(r"`[^`]*`", "", line)):
                if re.match(r"[a-z]+:", target):
                    continue  # http:, https:, mailto:
                file_part, _, anchor = target.partition("#")
                dest = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
                if not os.path.exists(dest):
                    err(f"{path}:{i}: link to {target}: {dest} does not exist")
                elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                    err(f"{path}:{i}: link to {target}: no heading '#{anchor}' in {dest}")
        # Commands: code blocks (continuation lines joined) and inline code. cli.md is the
        # --help text itself, compared above.
        if path == "docs/reference/cli.md":
            continue
        if in_code:
            if not joined:
                start = i
            joined += line.rstrip("\\") + " "
            if not line.endswith("\\"):
                check_command(path, start, joined)
                joined = ""
        else:
            for code in re.findall(r"`([^`]*fresco [^`]*)`", line):
                check_command(path, i, code)

# Project-file keys: the reader's Fields() (project.cc, and the settings headers)
# against docs/reference/project-file.md.
import glob
stage_headers = "".join(open(f).read() for f in sorted(glob.glob("pipeline/settings/*.h")))
header = open("pipeline/core/project.h").read() + stage_headers
source = open("pipeline/core/project.cc").read() + stage_headers
member_type = {}
for t, name in re.findall(r"^\s+(?:std::vector<)?(\w+)>? (\w+)(?: = [^;]*)?;", header, re.M):
    member_type[name] = t
fields = {}
for t, body in re.findall(r"void Fields\((\w+)& \w+, V& v\) \{(.*?)\n\}", source, re.S):
    fields[t] = re.findall(r"v\.(Field|Enum|List|Object)\(\s*\"(\w+)\",\s*\w+\.(\w+)", body)
keys = set()
def walk(t, prefix):
    for kind, name, member in fields.get(t, []):
        path_ = prefix + name
        if kind in ("Object", "List") and member_type.get(member) in fields:
            keys.add(path_)
            walk(member_type[member], path_ + ("[]." if kind == "List" else "."))
        else:
            keys.add(path_)
walk("Project", "")
if len(keys) < 50:
    err(f"read only {len(keys)} project keys from project.cc and the settings headers: update this check")
ref = open("docs/reference/project-file.md").read()
documented = set(re.findall(r"`([a-z_]+(?:\[\])?(?:\.[a-z_]+(?:\[\])?)*)`", ref))
skip = {"streams", "pipeline", "grouping", "truth", "live"}
for k in sorted(keys - skip):
    bare = k.replace("streams[].", "")
    if k not in documented and bare not in documented:
        err(f"docs/reference/project-file.md: key '{k}' (read by project.cc) is not documented")
for k in sorted(set(re.findall(r"^\| `([a-z_][\w.\[\]]*)`", ref, re.M))):
    if k not in keys:
        err(f"docs/reference/project-file.md: key '{k}' is not one project.cc reads")

# The settings tables: every row `fresco settings --markdown` makes from the declarations
# (default, range, help) must be in the page as it is.
rows = subprocess.run([fresco, "settings", "--markdown"], capture_output=True, text=True).stdout
ref_lines = set(ref.splitlines())
if len(rows.splitlines()) < 50:
    err("fresco settings --markdown printed fewer than 50 settings")
for row in rows.splitlines():
    if row not in ref_lines:
        key = row.split("`")[1] if "`" in row else row
        err(f"docs/reference/project-file.md: the row of '{key}' differs from `fresco settings "
            f"--markdown`; paste it from there:\n  {row}")

for e in errors:
    print(e)
for p in pending:
    print("contract, not implemented yet: " + p)
print(f"check_docs: {len(files)} files, {len(keys)} project keys, {len(errors)} problems")
sys.exit(1 if errors else 0)
PY
exit $fail
