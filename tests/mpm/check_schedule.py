#!/usr/bin/env python3
"""One output schedule for elements and MPM (issue 18; src/output/output_schedule.f90).

    check_schedule.py --bulkflow EXE --workdir DIR ELEMENT.inp MPM.inp

Runs the element scene and the MPM scene, which carry the same steps and *OUTPUT requests
(several field and history requests, NUMBER INTERVAL, TIME INTERVAL, FREQUENCY, TIME POINTS,
OP=NEW, fixed increments), and checks that
  1. both write their field frames and history rows at the same (step, step time, increment);
  2. those are the times of the rule, computed here independently from the requests: every
     request has its own schedule (TIME INTERVAL=t: the first increment end at or past each
     multiple of t; NUMBER INTERVAL=n: t = period/n; FREQUENCY=n: every n-th increment), each
     also at the step's start and end, and an output is written when any request is due; a
     TIME POINTS request (step 3) at its listed times only, each reached exactly by cutting the
     increment before it (both solvers, every other increment unchanged).
"""
import argparse
import csv
import subprocess
import sys
from pathlib import Path

import h5py

# (period, fixed increment, field requests, history requests); a request: ('T', t) | ('N', n) | ('F', n)
# | ('P', [listed step times]) (TIME POINTS=: the increment before a listed time is cut to end on it,
# output at the listed times only)
STEPS = [
    (0.1, 1.0e-3, [('N', 4), ('T', 0.03)], [('T', 0.04), ('F', 7)]),
    (0.06, 1.5e-3, [('F', 15)], [('N', 3)]),
    (0.05, 2.0e-3, [('P', [0.013, 0.03, 0.0475]), ('N', 2)], [('P', [0.005, 0.013, 0.041])]),
]


def expected(kind):
    """(step, step time) of every output of `kind`, the increments simulated as the solvers take them."""
    out = []
    for s, (period, dt_fixed, field, history) in enumerate(STEPS, start=1):
        requests = field if kind == 'field' else history
        points = sorted(t for k, v in field + history if k == 'P' for t in v)
        tol = 1e-9 * period
        nxt = [(period / v if k == 'N' else v) if k in 'NT' else None for k, v in requests]
        interval = list(nxt)
        if any(k != 'P' for k, _ in requests):
            out.append((s, 0.0))
        t, i = 0.0, 0
        while t < period - 1e-12 * period:
            dt = min(dt_fixed, period - t)
            t_point = min([p for p in points if p > t + tol], default=float('inf'))
            t_prev = t
            if t_point - t <= dt:
                dt, t = t_point - t, t_point
            else:
                t += dt
            i += 1
            boundary = t >= period * (1 - 1e-12)
            due = False
            for j, (k, v) in enumerate(requests):
                if k == 'P':
                    due |= any(t_prev + tol < p <= t + tol for p in v)
                elif boundary:
                    due = True
                elif k == 'F':
                    due |= i % v == 0
                else:
                    due |= t >= nxt[j] - 1e-9 * max(period, dt)
            if due:
                out.append((s, t))
                for j, (k, v) in enumerate(requests):
                    if k in 'NT':
                        while nxt[j] <= t + 1e-9 * period:
                            nxt[j] += interval[j]
    return out


def run(exe, scene, base, *extra):
    r = subprocess.run([exe, str(scene), '--output', str(base), '--quiet', *extra], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout, r.stderr)
        sys.exit(f'FAIL: {scene} {" ".join(extra)}: exit status {r.returncode}')


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
        want = expected(kind)
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
    # listed times are reached exactly: the output's step_time is the listed number bit for bit
    for kind in ('field', 'history'):
        listed = {(s, t) for s, (_, _, field, history) in enumerate(STEPS, start=1)
                  for k, v in (field if kind == 'field' else history) if k == 'P' for t in v}
        for solver in ('element', 'mpm'):
            hit = listed & set(got[(kind, solver)])
            same = hit == listed
            print(f"{'ok  ' if same else 'FAIL'} {solver:7s} {kind:7s}: {len(hit)} of {len(listed)} TIME POINTS "
                  f"outputs at exactly the listed step time")
            failed |= not same
    sys.exit(1 if failed else 0)


if __name__ == '__main__':
    main()
