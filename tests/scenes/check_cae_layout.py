#!/usr/bin/env python3
"""The default wedge hopper written as Abaqus/CAE writes decks (parts, an assembly, instances, the
analytic rigid walls as parts of their own) must give the results of the flat deck bit for bit.

    check_cae_layout.py FLAT.inp --bulkflow BIN --workdir DIR [--period T] [--committed CAE.inp]

The flat deck (its step period shortened to T for a short run) and two CAE-layout versions
written by bulkflow.scenes.cae_layout are run: walls at the assembly level (same names: the
history CSV must be byte-identical) and walls as instances of their own parts (names qualified,
`WALL-1.WALL`: the history must be identical once the wall columns are renamed). In both, every
dataset and attribute of the .h5 must be identical (h5py, exact), and nothing may be NaN.
--committed: the CAE-layout deck kept in the repository (inputs/demo/wedge_hopper_cae.inp) must be
exactly what bulkflow.scenes.cae_layout writes from FLAT, and it is run too (period shortened).
"""
from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'scripts'))
from bulkflow.scenes.cae_layout import convert, with_period  # noqa: E402
from compare_binaries import h5_differences  # noqa: E402


def run(bulkflow: str, deck: Path, base: Path) -> str:
    p = subprocess.run([bulkflow, str(deck), '--output', str(base)], capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        raise SystemExit(f'FAIL: {deck.name} exited {p.returncode}:\n{p.stdout}\n{p.stderr}')
    return p.stdout


def nonfinite_datasets(path: Path) -> list[str]:
    found: list[str] = []

    def visit(name, obj) -> None:
        if isinstance(obj, h5py.Dataset):
            data = np.asarray(obj[()])
            if np.issubdtype(data.dtype, np.floating) and not np.all(np.isfinite(data)):
                found.append(f'non-finite values in /{name}')

    with h5py.File(path, 'r') as f:
        f.visititems(visit)
    return found


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument('flat', type=Path)
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--workdir', type=Path, required=True)
    p.add_argument('--period', type=float, default=0.01)
    p.add_argument('--committed', type=Path, help='the CAE-layout deck in the repository (walls as instances)')
    a = p.parse_args()
    a.workdir.mkdir(parents=True, exist_ok=True)
    flat = with_period(a.flat, a.workdir / 'flat.inp', a.period)
    run(a.bulkflow, flat, a.workdir / 'flat')
    reference = (a.workdir / 'flat_history.csv').read_text()
    if 'nan' in reference.lower():
        print('FAIL: NaN in the flat run history')
        return 1
    failures = 0
    variants = ['assembly', 'instance']
    if a.committed:
        written = convert(a.flat, a.workdir / a.committed.name, walls='instance').read_text()
        current = written == a.committed.read_text()
        print(f'{a.committed.name}: {"is" if current else "is NOT"} what bulkflow.scenes.cae_layout writes from '
              f'{a.flat.name}' + ('' if current else ' (regenerate it)'))
        failures += not current
        variants.append('committed')
    for walls in variants:
        if walls == 'committed':
            deck = with_period(a.committed, a.workdir / 'cae_committed.inp', a.period)
        else:
            deck = convert(a.flat, a.workdir / f'cae_{walls}.inp', period=a.period, walls=walls)
        stdout = run(a.bulkflow, deck, a.workdir / f'cae_{walls}')
        history = (a.workdir / f'cae_{walls}_history.csv').read_text()
        if walls in ('instance', 'committed'):
            header, rest = history.split('\n', 1)
            header = header.replace('_WALL-1.WALL', '_WALL').replace('_PLATE-1.PLATE', '_PLATE')
            history = header + '\n' + rest
        same_history = history == reference
        diffs = (h5_differences(a.workdir / 'flat.h5', a.workdir / f'cae_{walls}.h5')
                 + nonfinite_datasets(a.workdir / f'cae_{walls}.h5'))
        noted = 'note: *PREPRINT' in stdout
        print(f'walls={walls}: history {"identical" if same_history else "DIFFERS"} '
              f'({len(reference.splitlines()) - 1} rows); .h5 {"identical" if not diffs else "DIFFERS: " + ", ".join(diffs[:5])}; '
              f'*PREPRINT note {"printed" if noted else "MISSING"}')
        failures += (not same_history) + bool(diffs) + (not noted)
    print('OK' if failures == 0 else f'FAIL ({failures})')
    return 0 if failures == 0 else 1


if __name__ == '__main__':
    raise SystemExit(main())
