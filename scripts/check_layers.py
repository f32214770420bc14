#!/usr/bin/env python3
"""Check that every Fortran `use` of bulkflow goes down the layers (issue 18, docs/architecture.md).

    python3 scripts/check_layers.py [--root DIR] [--strict-kinds] [--list]

Reads every Fortran source under src/ and umat/ (.f90, .inc, .f90.in), maps each module it
defines to the folder that holds the file, and each folder to a layer (LAYERS below, the same
table as docs/architecture.md). A `use` of one of our modules is allowed when the used module
lives in the same folder or in a folder of a LOWER layer; a use of a higher layer (upward) or of
another folder of the same layer (sideways) is an error reported as `file:line: ...`, and the
script exits 1. Modules not defined in the tree (mpi_f08, hdf5, iso_fortran_env...) are outside
the layers. A folder missing from LAYERS, or a module defined twice, is an error too.

--strict-kinds also reports every `use material_kinds` outside umat/: the solver takes its kinds
from base_kinds (src/base); material_kinds stays the kinds module of the self-contained material
kernels. (The mechanical rename of those lines is done when the branches of issue 18 meet.)
--list prints the layer table and the number of uses checked.

Standard library only. Exit status: 0 clean, 1 violations, 2 bad invocation.
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

# Layers, lowest first. A folder may use its own modules and those of lower layers only; folders
# of one layer are peers and do not use each other.
LAYERS: list[tuple[str, list[str], str]] = [
    ('base', ['src/base'], 'kinds, error reporting: used by everyone, uses nothing of ours'),
    ('kernels', ['umat'], 'material kernels (return mapping, tables, flow function); '
                          'self-contained, shipped alone to Abaqus and CalculiX'),
    ('model', ['src/model'], 'the scene as data: mesh, sets, surfaces, materials, steps, MPM scene'),
    ('services', ['src/material', 'src/fem', 'src/contact', 'src/parallel', 'src/output'],
     'the VUMAT door, element kernels and continuum kinematics, rigid-wall contact, '
     'partitioning and shared-node sums, HDF5/XDMF/CSV/checkpoint writers'),
    ('input', ['src/input'], 'the keyword reader and the scene builder (fills the model, '
                             'validates it with the element kernels)'),
    ('techniques', ['src/driver', 'src/mpm', 'src/matpoint'],
     'the element solver, the material point method and the material-point driver: '
     'peers, none uses another'),
    ('run', ['src/run'], 'the run skeleton: one step loop (output schedule, stop conditions, '
                         'checkpoints, progress, end report) over the abstract technique, and the '
                         'element solver and the MPM as its two extensions'),
    ('app', ['src/app'], 'main programs'),
]

# Temporary exceptions: (file, used module) -> why. Empty: every use goes down the layers. An
# entry is for a use that cannot move yet (say a file another branch is splitting); remove it as
# soon as its use is gone (the script warns about entries that match nothing).
ALLOWED: dict[tuple[str, str], str] = {}

KINDS_MODULE = 'material_kinds'

SUFFIXES = ('.f90', '.inc', '.f90.in')
MODULE_RE = re.compile(r'^\s*module\s+(?!procedure\b)(\w+)\s*(?:!.*)?$', re.IGNORECASE)
USE_RE = re.compile(r'^\s*use\b\s*(?:,\s*(?:non_)?intrinsic\s*)?(?:::)?\s*(\w+)', re.IGNORECASE)


def folder_layers() -> dict[str, tuple[int, str]]:
    table = {}
    for rank, (name, folders, _) in enumerate(LAYERS):
        for folder in folders:
            table[folder] = (rank, name)
    return table


def source_files(root: Path) -> list[Path]:
    files = []
    for top in ('src', 'umat'):
        base = root / top
        if base.is_dir():
            files += [p for p in base.rglob('*') if p.is_file() and p.name.endswith(SUFFIXES)]
    return sorted(files)


def folder_of(rel: str, table: dict[str, tuple[int, str]]) -> str | None:
    """The longest folder of the table that holds rel (umat/abaqus/x.f90 -> umat)."""
    best = None
    for folder in table:
        if rel.startswith(folder + '/') and (best is None or len(folder) > len(best)):
            best = folder
    return best


def code_lines(path: Path):
    """(line number, text) of each line, without comments; continuation lines are not joined
    (a `use` statement names its module on its first line)."""
    for number, line in enumerate(path.read_text(errors='replace').splitlines(), 1):
        yield number, line.split('!', 1)[0]


def check(root: Path, strict_kinds: bool) -> tuple[list[str], list[str], int]:
    table = folder_layers()
    errors: list[str] = []
    files = source_files(root)
    rel = {p: p.relative_to(root).as_posix() for p in files}
    owner: dict[str, str] = {}       # module -> file that defines it
    for path in files:
        if folder_of(rel[path], table) is None:
            errors.append(f'{rel[path]}:1: folder {Path(rel[path]).parent.as_posix()} is in no '
                          f'layer (add it to LAYERS in scripts/check_layers.py and to '
                          f'docs/architecture.md)')
            continue
        for number, text in code_lines(path):
            m = MODULE_RE.match(text)
            if m:
                name = m.group(1).lower()
                if name in owner:
                    errors.append(f'{rel[path]}:{number}: module {name} is also defined in {owner[name]}')
                else:
                    owner[name] = rel[path]
    used_allowances: set[tuple[str, str]] = set()
    checked = 0
    for path in files:
        here = folder_of(rel[path], table)
        if here is None:
            continue
        rank, layer = table[here]
        for number, text in code_lines(path):
            m = USE_RE.match(text)
            if not m:
                continue
            name = m.group(1).lower()
            if strict_kinds and name == KINDS_MODULE and here != 'umat':
                errors.append(f'{rel[path]}:{number}: use {name}: the solver takes its kinds from '
                              f'base_kinds (--strict-kinds)')
            if name not in owner:
                continue             # intrinsic or external module
            checked += 1
            there = folder_of(owner[name], table)
            if there == here:
                continue
            their_rank, their_layer = table[there]
            if their_rank < rank:
                continue
            key = (rel[path], name)
            if key in ALLOWED:
                used_allowances.add(key)
                continue
            direction = 'upward' if their_rank > rank else 'sideways'
            errors.append(f'{rel[path]}:{number}: forbidden {direction} use of {name} '
                          f'({owner[name]}, layer {their_layer}) from layer {layer} ({here})')
    warnings = [f'allow-list entry {f} -> {m} matches no use any more: remove it from '
                f'scripts/check_layers.py' for (f, m) in ALLOWED if (f, m) not in used_allowances]
    return errors, warnings, checked


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--root', type=Path, default=Path(__file__).resolve().parent.parent,
                        help='repository root (default: this script\'s repository)')
    parser.add_argument('--strict-kinds', action='store_true',
                        help='also report use material_kinds outside umat/')
    parser.add_argument('--list', action='store_true', help='print the layer table')
    args = parser.parse_args(argv)
    if not (args.root / 'src').is_dir():
        print(f'check_layers.py: {args.root}: no src/ folder', file=sys.stderr)
        return 2
    if args.list:
        for rank, (name, folders, what) in enumerate(LAYERS):
            print(f'{rank} {name:10s} {" ".join(folders):55s} {what}')
    errors, warnings, checked = check(args.root, args.strict_kinds)
    for w in warnings:
        print(f'check_layers.py: warning: {w}', file=sys.stderr)
    for e in errors:
        print(e)
    allowed = len(ALLOWED) - sum(1 for w in warnings)
    if errors:
        print(f'check_layers.py: {len(errors)} forbidden use(s) among {checked} uses of our modules',
              file=sys.stderr)
        return 1
    print(f'check_layers.py: {checked} uses of our modules go down the layers '
          f'({allowed} temporary exception(s) listed in the script)')
    return 0


if __name__ == '__main__':
    sys.exit(main())
