#!/usr/bin/env python3
"""One output schedule for elements and MPM (issue 18; src/output/output_schedule.f90).

    check_schedule.py --bulkflow EXE --workdir DIR ELEMENT.inp MPM.inp

Runs the element scene and the MPM scene, which carry the same steps and *OUTPUT requests
(several field and history requests, NUMBER INTERVAL, TIME INTERVAL, FREQUENCY, OP=NEW, fixed
increments), and checks that
  1. both write their field frames and history rows at the same (step, step time, increment);
  2. those are the times of the rule, computed here independently from the requests: every
     request has its own schedule (TIME INTERVAL=t: the first increment end at or past each
     multiple of t; NUMBER INTERVAL=n: t = period/n; FREQUENCY=n: every n-th increment), each
     also at the step's start and end, and an output is written when any request is due.
"""
import argparse
import csv
import subprocess
import sys
from pathlib import Path

import h5py

# (period, fixed increment, field requests, history requests); a request: ('T', t) | ('N', n) | ('F', n)
STEPS = [
    (0.1, 1.0e-3, [('N', 4), ('T', 0.03)], [('T', 0.04), ('F', 7)]),
    (0.06, 1.5e-3, [('F', 15)], [('N', 3)]),
]


def expected(kind):
    out = []
    for s, (period, dt, field, history) in enumerate(STEPS, start=1):
        requests = field if kind == 'field' else history
        n = round(period / dt)
        nxt = [(period / v if k == 'N' else v) if k in 'NT' else None for k, v in requests]
        interval = list(nxt)
        out.append((s, 0))
        for i in range(1, n + 1):
            t = i * dt
            due = i == n
            for j, (k, v) in enumerate(requests):
                if k == 'F':
                    due |= i % v == 0
                else:
                    due |= t >= nxt[j] - 1e-9 * max(period, dt)
            if due:
                out.append((s, i))
                for j, (k, v) in enumerate(requests):
                    if k != 'F':
                        while nxt[j] <= t + 1e-9 * period:
                            nxt[j] += interval[j]
    return out


def run(exe, scene, base):
    r = subprocess.run([exe, str(scene), '--output', str(base), '--quiet'], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout, r.stderr)
        sys.exit(f'FAIL: {scene} exit status {r.returncode}')


def frames(h5, group):
    with h5py.File(h5, 'r') as f:
        g = f[group]
        return [(int(g[k].attrs['step'][()] if g[k].attrs['step'].shape == () else g[k].attrs['step'][0]),
                 float(g[k].attrs['step_time'][()] if g[k].attrs['step_time'].shape == () else g[k].attrs['step_time'][0]))
                for k in sorted(g)]


def rows(path):
    with open(path) as f:
        r = list(csv.DictReader(f))
    return [(int(float(x['step'])), float(x['step_time'])) for x in r]


def main():
    p = argparse.ArgumentParser()
    p.add_argument('element', type=Path)
    p.add_argument('mpm', type=Path)
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--workdir', required=True, type=Path)
    a = p.parse_args()
    a.workdir.mkdir(parents=True, exist_ok=True)
    run(a.bulkflow, a.element, a.workdir / 'element')
    run(a.bulkflow, a.mpm, a.workdir / 'mpm')
    got = {
        ('field', 'element'): frames(a.workdir / 'element.h5', 'frames'),
        ('field', 'mpm'): frames(a.workdir / 'mpm.h5', 'particles'),
        ('history', 'element'): rows(a.workdir / 'element_history.csv'),
        ('history', 'mpm'): rows(a.workdir / 'mpm_history.csv'),
    }
    failed = False
    for kind in ('field', 'history'):
        want = [(s, i * STEPS[s - 1][1]) for s, i in expected(kind)]
        for solver in ('element', 'mpm'):
            have = got[(kind, solver)]
            same = len(have) == len(want) and all(
                hs == ws and abs(ht - wt) <= 1e-9 * STEPS[ws - 1][0] for (hs, ht), (ws, wt) in zip(have, want))
            print(f"{'ok  ' if same else 'FAIL'} {solver:7s} {kind:7s}: {len(have)} outputs "
                  f"{'at the rule' if same else 'differ from the rule'}: " +
                  ' '.join(f'{s}:{t:.4f}' for s, t in have))
            if not same:
                print('      expected: ' + ' '.join(f'{s}:{t:.4f}' for s, t in want))
                failed = True
    sys.exit(1 if failed else 0)


if __name__ == '__main__':
    main()
