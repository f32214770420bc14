#!/usr/bin/env python3
"""Show that a change did not change results: two bulkflow binaries run the same decks, and the
exit status, the history CSV (bytes) and every dataset and attribute of the .h5 (exact, h5py)
must be identical.

    python3 scripts/compare_binaries.py OLD_BIN NEW_BIN DECK... [--stop-after 300] [--workdir DIR]
                                        [--ranks N [--mpiexec mpirun]] [--timeout S] [--stop-outputs]

--stop-after 0 runs every deck to its end. --stop-outputs compares an OLD binary from before the
--stop-after rule of issue 18 (the element solver wrote no row or frame at the stop) with a NEW one
that has it: the new history may end with one row more and the new .h5 may hold one frame more
(the stop's), everything the old wrote must be the same bytes.

OLD_BIN is typically main's build (build it from a clean checkout of main), NEW_BIN the branch's.
Prints one line per deck and exits 1 if any deck differs. A deck that neither binary ran (both exit
non-zero without writing a history, e.g. mpirun refusing to start) is "NOT COMPARED" and counts as
a difference: two failures prove nothing. Open MPI's run-as-root variables are set for --ranks > 1.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np


def h5_differences(a: Path, b: Path) -> list[str]:
    """Names of the datasets/attributes that differ (floats compared by their bytes)."""
    out: list[str] = []

    def same(x, y) -> bool:
        x, y = np.asarray(x), np.asarray(y)
        if x.shape != y.shape or x.dtype != y.dtype:
            return False
        return x.tobytes() == y.tobytes() if np.issubdtype(x.dtype, np.floating) else np.array_equal(x, y)

    def walk(g1, g2, path: str) -> None:
        for k, v in g1.attrs.items():
            if k not in g2.attrs or not same(v, g2.attrs[k]):
                out.append(f'attribute {path}@{k}')
        if set(g1.keys()) != set(g2.keys()):
            out.append(f'members of {path or "/"}')
        for k in set(g1.keys()) & set(g2.keys()):
            if isinstance(g1[k], h5py.Group):
                walk(g1[k], g2[k], f'{path}/{k}')
            elif not same(g1[k][()], g2[k][()]):
                out.append(f'dataset {path}/{k}')

    with h5py.File(a, 'r') as f1, h5py.File(b, 'r') as f2:
        walk(f1, f2, '')
    return out


def stop_frame_only(a: Path, b: Path, diffs: list[str]) -> tuple[list[str], str]:
    """With --stop-outputs: are the differences only one frame group more in b (the last of its
    frame list, the stop's) and the attributes that count frames? Returns the remaining
    differences and the added frame's name."""
    with h5py.File(a, 'r') as f1, h5py.File(b, 'r') as f2:
        for top in ('frames', 'particles', 'grid'):
            if top not in f1 or top not in f2:
                continue
            k1, k2 = sorted(f1[top].keys()), sorted(f2[top].keys())
            if len(k2) == len(k1) + 1 and k2[:-1] == k1:
                added = f'{top}/{k2[-1]}'
                rest = [d for d in diffs if d != f'members of /{top}']
                return rest, added
    return diffs, ''


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('old')
    ap.add_argument('new')
    ap.add_argument('decks', nargs='+', type=Path)
    ap.add_argument('--stop-after', type=int, default=300, help='increments per run (default 300)')
    ap.add_argument('--workdir', type=Path, help='keep the outputs here (default: a scratch directory)')
    ap.add_argument('--ranks', type=int, default=1, help='MPI ranks per run (default 1: no mpiexec)')
    ap.add_argument('--mpiexec', default='mpirun', help='launcher for --ranks > 1 (default mpirun)')
    ap.add_argument('--timeout', type=float, default=600, help='seconds per run (default 600)')
    ap.add_argument('--stop-outputs', action='store_true',
                    help='allow the new binary one extra history row and frame at the stop (see above)')
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix='bulkflow_compare_') as tmp:
        work = a.workdir or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        differ = 0
        env = dict(os.environ)
        if a.ranks > 1:
            env.update(OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1')
        for deck in a.decks:
            runs = []
            for tag, exe in (('old', a.old), ('new', a.new)):
                base = work / f'{deck.stem}_{tag}'
                launch = [a.mpiexec, '-np', str(a.ranks), '--oversubscribe'] if a.ranks > 1 else []
                stop = ['--stop-after', str(a.stop_after)] if a.stop_after > 0 else []
                p = subprocess.run(launch + [exe, str(deck.resolve()), '--output', str(base), *stop, '--quiet'],
                                   capture_output=True, text=True, timeout=a.timeout, env=env)
                runs.append((base, p.returncode, (p.stderr.strip() or p.stdout.strip()).splitlines()[-1:]))
            (b0, r0, e0), (b1, r1, e1) = runs
            h0, h1 = Path(f'{b0}_history.csv'), Path(f'{b1}_history.csv')
            if r0 != 0 and r1 != 0 and not h0.exists() and not h1.exists():
                differ += 1
                print(f'NOT COMPARED  {deck}: exit {r0}/{r1}, neither run wrote a history '
                      f'(old: {" ".join(e0) or "no output"}; new: {" ".join(e1) or "no output"})')
                continue
            same_history = h0.exists() == h1.exists() and (not h0.exists() or h0.read_bytes() == h1.read_bytes())
            extra = ''
            if a.stop_outputs and not same_history and h0.exists() and h1.exists():
                old, new = h0.read_bytes(), h1.read_bytes()
                same_history = new.startswith(old) and new[len(old):].count(b'\n') <= 1
                extra = ' (+1 row at the stop)' if same_history else ''
            f0, f1 = Path(f'{b0}.h5'), Path(f'{b1}.h5')
            if f0.exists() and f1.exists():
                diffs = h5_differences(f0, f1)
                if a.stop_outputs and diffs:
                    diffs, added = stop_frame_only(f0, f1, diffs)
                    extra += f' (+frame {added} at the stop)' if added else ''
            else:
                diffs = [] if f0.exists() == f1.exists() else ['.h5 written by one binary only']
            ok = r0 == r1 and same_history and not diffs
            differ += not ok
            print(f'{"same" if ok else "DIFFERS"}  {deck}: exit {r0}/{r1}, history '
                  f'{"identical" if same_history else "differs"}, .h5 '
                  f'{"identical" if not diffs else ", ".join(diffs[:4])}{extra}')
    print('all identical' if not differ else f'{differ} of {len(a.decks)} decks differ or were not compared')
    return 1 if differ else 0


if __name__ == '__main__':
    sys.exit(main())
