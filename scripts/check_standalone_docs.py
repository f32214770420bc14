#!/usr/bin/env python3
"""Fail when a tracked file cites a note that is not in the repository.

The repository must stand on its own: facts the code and docs rely on live in docs/ (mostly
docs/theory/) with their primary sources named, and every citation points there or at the
primary source. This check finds citations of outside notes: the working notes the project
started from (numerics.md, hopper_theory.md, abaqus_interfaces.md, anchors.md, design.md,
thesis.md, anything under reference/ or shared/), and any path that leaves the tree through
../shared or names /work/. A note of that name inside docs/theory/ is ours and allowed.
It also keeps the section anchors of docs/theory/ stable: a citation such as
`docs/theory/mpm.md §4.2` (or `mpm.md §4.2` from inside docs/theory/) must name a section
heading that exists in that file ("## 4. MPM", "### 4.2 ...", "## (d) ...", "### d.3 ...").

Usage: check_standalone_docs.py [--root DIR] [FILE ...]
  With no FILE, every file git tracks under DIR (default: the repository holding this script)
  is checked; without git, every file below DIR except build trees. Prints file:line: text for
  each hit and exits 1 if there is one, 0 otherwise (2 on a usage error). Standard library only.
"""
import argparse
import os
import re
import subprocess
import sys

#: (pattern, what it means). Each pattern is searched on every line of every checked file.
PATTERNS = [
    (re.compile(r"(?:\.\./)+shared\b"), "path leaving the repository (../shared)"),
    (re.compile(r"/work/"), "absolute path of the working machine (/work/)"),
    (re.compile(r"\bshared/(?:reference|seed)\b|\bshared/design\.md"), "outside note under shared/"),
    (re.compile(r"(?<![\w/])reference/[\w./-]*"), "outside note under reference/"),
    (re.compile(r"\bthesis\.md\b"), "the thesis as a file (cite it by author, title, year)"),
    # Our own docs/theory/hopper_theory.md etc. are allowed; a bare note name is not.
    (re.compile(r"(?<!docs/theory/)(?<!\w)(?:numerics|hopper_theory|abaqus_interfaces|anchors|design)"
                r"\.md\b"), "outside note (cite docs/theory/<file>.md §n or the primary source)"),
    (re.compile(r"(?<![\w/.])hopper_theory\s*§"), "outside note (cite docs/theory/hopper_theory.md §n)"),
]

#: Files that must spell the forbidden patterns out: this check and its test.
SELF = {"scripts/check_standalone_docs.py", "tests/docs/test_check_standalone_docs.py"}

THEORY = "docs/theory"
CITATION = re.compile(r"(docs/theory/)?\b(\w+\.md)`?\)?\s*((?:§\s*[\w.]+(?:[–-][\w.]+)?(?:,\s*|/)?)+)")
HEADING = re.compile(r"#+\s*(?:\((\w+)\)|(\w+(?:\.\w+)*)\.?)\s")

SKIP_DIRS = {".git", "build", "build-debug", ".venv", "__pycache__"}


def tracked_files(root):
    """Files git tracks under root (relative paths), or all files when git is not available."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], check=True,
                             capture_output=True).stdout
        names = [n for n in out.decode("utf-8", "surrogateescape").split("\0") if n]
        if names:
            return names
    except (OSError, subprocess.CalledProcessError):
        pass
    names = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS and not d.startswith("build"))
        for f in sorted(filenames):
            names.append(os.path.relpath(os.path.join(dirpath, f), root))
    return names


def is_sibling(root, rel, cited):
    """True when `cited` is a bare file name that exists beside the citing file (a relative link
    inside the repository, e.g. docs/theory/mpm.md citing hopper_theory.md)."""
    if "/" in cited or not cited.endswith(".md"):
        return False
    return os.path.isfile(os.path.join(root, os.path.dirname(rel), cited))


def theory_sections(root):
    """{file name: set of section labels} of the docs/theory/*.md files under root."""
    sections = {}
    folder = os.path.join(root, THEORY)
    if os.path.isdir(folder):
        for name in sorted(os.listdir(folder)):
            if name.endswith(".md"):
                with open(os.path.join(folder, name), encoding="utf-8", errors="replace") as fh:
                    sections[name] = {(m.group(1) or m.group(2)) for m in map(HEADING.match, fh) if m}
    return sections


def missing_sections(rel, line, sections):
    """Citations of docs/theory sections on this line whose section heading does not exist."""
    missing = []
    for m in CITATION.finditer(line):
        prefixed, name, secs = m.group(1), m.group(2), m.group(3)
        if not prefixed and os.path.dirname(rel) != THEORY:
            continue  # a bare file name outside docs/theory is some other file
        if name not in sections:
            if prefixed:
                missing.append(f"{THEORY}/{name} (no such file)")
            continue
        for sec in re.findall(r"§\s*([\w.]+)", secs):
            sec = sec.rstrip(".")
            if sec not in sections[name]:
                missing.append(f"{THEORY}/{name} §{sec}")
    return missing


def check_file(root, rel, sections=None):
    """(line number, text, reason) of every outside citation in one file; binary files give none."""
    path = os.path.join(root, rel)
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError:
        return []
    if b"\0" in data[:8192]:
        return []
    hits = []
    for number, line in enumerate(data.decode("utf-8", "replace").splitlines(), start=1):
        for cited in missing_sections(rel, line, sections or {}):
            hits.append((number, line.strip(), f"cited section does not exist: {cited}"))
        for pattern, reason in PATTERNS:
            if any(not is_sibling(root, rel, m.group(0)) for m in pattern.finditer(line)):
                hits.append((number, line.strip(), reason))
                break
    return hits


def main(argv=None):
    default_root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=default_root, help="repository root (default: %(default)s)")
    parser.add_argument("files", nargs="*", help="files relative to the root (default: all tracked)")
    args = parser.parse_args(argv)
    root = os.path.abspath(args.root)
    if not os.path.isdir(root):
        print(f"check_standalone_docs: {root}: not a directory", file=sys.stderr)
        return 2
    files = args.files or tracked_files(root)
    sections = theory_sections(root)
    count = 0
    for rel in files:
        rel = os.path.relpath(os.path.join(root, rel), root).replace(os.sep, "/")
        if rel in SELF:
            continue
        for number, text, reason in check_file(root, rel, sections):
            print(f"{rel}:{number}: {reason}: {text}")
            count += 1
    if count:
        print(f"check_standalone_docs: {count} citation(s) of notes outside the repository or of "
              "missing docs/theory sections; "
              "write the fact in docs/theory/ (with its primary source) and cite a section that exists",
              file=sys.stderr)
        return 1
    print(f"check_standalone_docs: {len(files)} files, no citation of notes outside the repository")
    return 0


if __name__ == "__main__":
    sys.exit(main())
