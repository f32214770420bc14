#!/usr/bin/env python3
"""Check the size rules of the brief: no source file over 700 lines, no routine over 150 lines,
apart from the exceptions listed below with their reason (issue 18).

    python3 scripts/check_sizes.py [--root DIR] [--list]

Reads every Fortran source under src/ and umat/ (.f90, .inc, .f90.in; generated files live in
the build tree and are not read). A routine is a subroutine or function from its first line to
its `end subroutine` / `end function`, comments and blank lines included; an internal routine
(after `contains` inside a routine) counts for itself and for its host. Prints `file:line: ...`
for each file or routine over its limit and exits 1; --list also prints the ten longest files
and routines. Standard library only.
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

# The same files as the layer check: every Fortran source under src/ and umat/.
sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_layers import source_files  # noqa: E402

MAX_FILE_LINES = 700
MAX_ROUTINE_LINES = 150

# Files allowed over MAX_FILE_LINES: path -> reason.
FILE_EXCEPTIONS: dict[str, str] = {
}

# Routines allowed over MAX_ROUTINE_LINES: (path, routine) -> reason. The fused, vectorised
# kernels: one pass over a block whose arrays stay in registers or L1; splitting them would
# store and reload the intermediate arrays (the reason each is fused is in its header comment).
ROUTINE_EXCEPTIONS: dict[tuple[str, str], str] = {
    ('umat/material_update.f90', 'update_mohr_coulomb_block'):
        'fused Mohr-Coulomb update of a chunk: trial, principal split, return, rotation back, '
        'state and energies as unit-stride vectorised passes over fixed-size work arrays kept in L1',
    ('umat/principal_stress.f90', 'principal_3d_block'):
        'fused, vectorised 3D eigen-decomposition of a chunk (scaling, invariants, roots, vectors '
        'in one branch-free pass per step; a call per step would spill the chunk arrays)',
}

START_RE = re.compile(
    r'^\s*(?:(?:pure|elemental|impure|recursive|module|non_recursive)\s+)*'
    r'(?:(?:integer|logical|real|complex|character|double\s+precision|type\s*\([^)]*\)|class\s*\([^)]*\))'
    r'(?:\s*\([^)]*\))?(?:\s*\*\s*\d+)?\s+)?'
    r'(?:(?:pure|elemental|impure|recursive|module)\s+)*'
    r'(subroutine|function)\s+(\w+)', re.IGNORECASE)
END_RE = re.compile(r'^\s*end\s*(subroutine|function)\b|^\s*end\s*$', re.IGNORECASE)


def routines(lines: list[str]):
    """(name, first line, line count) of every subroutine and function."""
    stack: list[tuple[str, int]] = []
    for number, raw in enumerate(lines, 1):
        text = raw.split('!', 1)[0]
        if not text.strip():
            continue
        if END_RE.match(text) and stack:
            name, first = stack.pop()
            yield name, first, number - first + 1
            continue
        m = START_RE.match(text)
        if m and not re.match(r'^\s*end\b', text, re.IGNORECASE):
            stack.append((m.group(2).lower(), number))


def check(root: Path) -> tuple[list[str], list[tuple[int, str]], list[tuple[int, str]]]:
    problems: list[str] = []
    file_sizes: list[tuple[int, str]] = []
    routine_sizes: list[tuple[int, str]] = []
    for path in source_files(root):
        rel = path.relative_to(root).as_posix()
        lines = path.read_text(errors='replace').splitlines()
        file_sizes.append((len(lines), rel))
        if len(lines) > MAX_FILE_LINES and rel not in FILE_EXCEPTIONS:
            problems.append(f'{rel}:1: {len(lines)} lines (limit {MAX_FILE_LINES}): split it into '
                            f'modules of one concept each')
        for name, first, count in routines(lines):
            routine_sizes.append((count, f'{rel}:{first}: {name}'))
            if count <= MAX_ROUTINE_LINES:
                continue
            if (rel, name) in ROUTINE_EXCEPTIONS or (rel, '*') in ROUTINE_EXCEPTIONS:
                continue
            problems.append(f'{rel}:{first}: routine {name} has {count} lines (limit '
                            f'{MAX_ROUTINE_LINES})')
    return problems, file_sizes, routine_sizes


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--root', type=Path, default=Path(__file__).resolve().parent.parent)
    parser.add_argument('--list', action='store_true', help='print the longest files and routines')
    args = parser.parse_args(argv)
    if not (args.root / 'src').is_dir():
        print(f'check_sizes.py: {args.root}: no src/ folder', file=sys.stderr)
        return 2
    problems, file_sizes, routine_sizes = check(args.root)
    if args.list:
        print('longest files:')
        for count, rel in sorted(file_sizes, reverse=True)[:10]:
            print(f'  {count:5d} {rel}')
        print('longest routines:')
        for count, where in sorted(routine_sizes, reverse=True)[:10]:
            print(f'  {count:5d} {where}')
    for p in problems:
        print(p)
    excepted = len(FILE_EXCEPTIONS) + len(ROUTINE_EXCEPTIONS)
    if problems:
        print(f'check_sizes.py: {len(problems)} file(s)/routine(s) over the limits', file=sys.stderr)
        return 1
    print(f'check_sizes.py: {len(file_sizes)} files <= {MAX_FILE_LINES} lines, '
          f'{len(routine_sizes)} routines <= {MAX_ROUTINE_LINES} lines '
          f'({excepted} listed exception(s))')
    return 0


if __name__ == '__main__':
    sys.exit(main())
