#!/usr/bin/env python3
"""One rule for the outputs of a --stop-after stop, elements and MPM alike (issue 18; src/run/run_loop.f90).

    check_stop_outputs.py --bulkflow EXE --workdir DIR ELEMENT.inp MPM.inp

The rule: a run stopped by --stop-after N writes a history row and a field frame of increment N
unless the output schedule wrote them there already (never twice); the stop's outputs come after
its checkpoint, so a --restart continues as if there had been no stop. For the element scene and
the MPM scene of check_schedule.py (same steps, same *OUTPUT requests, fixed increments) this
checks, for each technique:
  1. --stop-after 37 (step 1, 0.037 s: no request is due there): the rows and frames of the rule
     up to 0.037 s, then one row and one frame at 0.037 s;
  2. --stop-after 35 (the history request FREQUENCY=7 is due, no field request): the row of the
     schedule at 0.035 s once, and the stop's frame there;
  3. --restart from the stop at 37, to the end: rows and frames (times and every value) equal to
     an uninterrupted run's (the stop's extra row and frame are dropped at the restart).
"""
import argparse
import csv
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_schedule import expected, run  # noqa: E402  (the schedule rule, computed independently)

GROUP = {'element': 'frames', 'mpm': 'particles'}
PERIOD_1 = 0.1


def frame_times(h5, group):
    with h5py.File(h5, 'r') as f:
        g = f[group]
        return [(int(np.ravel(g[k].attrs['step'])[0]), float(np.ravel(g[k].attrs['step_time'])[0])) for k in sorted(g)]


def row_table(path):
    with open(path) as f:
        return list(csv.reader(f))


def row_times(path):
    with open(path) as f:
        return [(int(float(x['step'])), float(x['step_time'])) for x in csv.DictReader(f)]


def frame_data(h5, group):
    """Every dataset of every frame, by frame name and dataset path."""
    out = {}
    with h5py.File(h5, 'r') as f:
        def take(name, obj):
            if isinstance(obj, h5py.Dataset):
                out[name] = obj[()]
        f[group].visititems(take)
    return out


def close(have, want):
    return len(have) == len(want) and all(hs == ws and abs(ht - wt) <= 1e-9 * PERIOD_1
                                          for (hs, ht), (ws, wt) in zip(have, want))


def main():
    p = argparse.ArgumentParser()
    p.add_argument('element', type=Path)
    p.add_argument('mpm', type=Path)
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--workdir', required=True, type=Path)
    a = p.parse_args()
    a.workdir.mkdir(parents=True, exist_ok=True)
    failed = False

    def report(ok, text):
        nonlocal failed
        print(f"{'ok  ' if ok else 'FAIL'} {text}")
        failed |= not ok

    for solver, scene in (('element', a.element), ('mpm', a.mpm)):
        for stop in (37, 35):
            t_stop = stop * 1.0e-3
            base = a.workdir / f'{solver}_stop{stop}'
            run(a.bulkflow, scene, base, '--stop-after', str(stop))
            rule = {kind: [o for o in expected(kind) if o[0] == 1 and o[1] <= t_stop + 1e-12] for kind in ('field', 'history')}
            want = {kind: rule[kind] + ([] if rule[kind][-1][1] > t_stop - 1e-12 else [(1, t_stop)])
                    for kind in rule}
            rows = row_times(f'{base}_history.csv')
            frames = frame_times(f'{base}.h5', GROUP[solver])
            scheduled_row = rule['history'][-1][1] > t_stop - 1e-12
            report(close(rows, want['history']),
                   f'{solver:7s} --stop-after {stop}: {len(rows)} history rows, the last at {rows[-1][1]:.4f} '
                   f'(want {len(want["history"])}, the last at {t_stop:.4f}: '
                   f'{"the schedule" + chr(39) + "s, not repeated" if scheduled_row else "the stop" + chr(39) + "s"})')
            report(close(frames, want['field']),
                   f'{solver:7s} --stop-after {stop}: {len(frames)} frames, the last at {frames[-1][1]:.4f} '
                   f'(want {len(want["field"])}, the last the stop\'s at {t_stop:.4f})')
        # restart from the stop at 37 to the end == an uninterrupted run
        full = a.workdir / f'{solver}_full'
        run(a.bulkflow, scene, full)
        resumed = a.workdir / f'{solver}_stop37'
        run(a.bulkflow, scene, resumed, '--restart')
        same_rows = row_table(f'{full}_history.csv') == row_table(f'{resumed}_history.csv')
        d_full = frame_data(f'{full}.h5', GROUP[solver])
        d_res = frame_data(f'{resumed}.h5', GROUP[solver])
        same_frames = d_full.keys() == d_res.keys() and all(
            np.asarray(d_full[k]).tobytes() == np.asarray(d_res[k]).tobytes() for k in d_full)
        report(same_rows and same_frames,
               f'{solver:7s} --restart from the stop at 37: {len(row_table(f"{resumed}_history.csv")) - 1} rows and '
               f'{len(frame_times(f"{resumed}.h5", GROUP[solver]))} frames, identical to the uninterrupted run')
    sys.exit(1 if failed else 0)


if __name__ == '__main__':
    main()
