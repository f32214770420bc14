#!/usr/bin/env python3
"""Prescribed conditions across steps (docs/keywords.md, "Prescribed conditions across steps"):
one small two-step scene per rule, run with the element driver or the MPM, its velocity history
checked against the rule's closed form.

    check_steps.py RULE element|mpm --bulkflow BIN --workdir DIR
    check_steps.py --list

Every scene is a body in free fall (no support, no wall): its velocity is v2(t) = -g ∫ f dt, with f
the factor the rule gives the gravity load at each time, so the history shows which factor the
solver applied, step by step. Steps: 0.1 s each; amplitudes: LONG (tabular, step time, 0 -> 1 over
0.2 s: at the end of step 1 it is at 0.5), TOTAL (the same in total time), SHORT (smooth step in
step time, 0 -> 1 over 0.05 s: it ends before step 1 does). The rule `velocity_bc` (element only:
the MPM has no *BOUNDARY) holds a prescribed velocity instead, checked on U1. Each rule also says
whether the scene builder must warn of a gravity jump at the start of step 2, naming the line.
"""
from __future__ import annotations

import argparse
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

G = 10.0          # gravity magnitude [m/s^2]
T1 = T2 = 0.1     # step periods [s]


def ramp_long(t):
    return np.clip(t / 0.2, 0.0, 1.0)


def smooth_short(t):
    x = np.clip(t / 0.05, 0.0, 1.0)
    return x**3 * (10 - 15 * x + 6 * x**2)


# rule: (step 1 loads, step 2 loads, f(total time), warning expected, what it shows)
RULES = {
    'carried_step_time': (
        ['*DLOAD, AMPLITUDE=LONG', ', GRAV, {g}, 0., -1.'], [],
        lambda t: np.where(t <= T1, ramp_long(t), ramp_long(T1)), False,
        'carried over, step-time amplitude: held at its value at the end of step 1 (0.5)'),
    'carried_total_time': (
        ['*DLOAD, AMPLITUDE=TOTAL', ', GRAV, {g}, 0., -1.'], [],
        lambda t: ramp_long(t), False,
        'carried over, total-time amplitude: goes on following it (0.5 -> 1 in step 2)'),
    'carried_no_amplitude': (
        ['*DLOAD', ', GRAV, {g}, 0., -1.'], [],
        lambda t: np.ones_like(t), False,
        'carried over, no amplitude (Explicit step variation): the full magnitude throughout'),
    'amplitude_ends': (
        ['*DLOAD, AMPLITUDE=SHORT', ', GRAV, {g}, 0., -1.'], [],
        lambda t: np.where(t <= T1, smooth_short(t), 1.0), False,
        'step-time amplitude ending before the step: its last value, then carried on across '
        'the step boundary (gravity continuous, no restart)'),
    'op_mod_restart': (
        ['*DLOAD, AMPLITUDE=LONG', ', GRAV, {g}, 0., -1.'],
        ['*DLOAD, AMPLITUDE=LONG, OP=MOD', ', GRAV, {g}, 0., -1.'],
        lambda t: np.where(t <= T1, ramp_long(t), ramp_long(t - T1)), True,
        'defined again with OP=MOD and a step-time amplitude: restarts in step 2 (0.5 -> 0)'),
    'op_mod_no_amplitude': (
        ['*DLOAD, AMPLITUDE=LONG', ', GRAV, {g}, 0., -1.'],
        ['*DLOAD', ', GRAV, {g2}, 0., -1.'],
        lambda t: np.where(t <= T1, ramp_long(t), 2.0), True,
        'defined again without an amplitude (step variation): the new magnitude at once'),
    'op_new_removed': (
        ['*DLOAD', ', GRAV, {g}, 0., -1.'],
        ['*DLOAD, OP=NEW'],
        lambda t: np.where(t <= T1, 1.0, 0.0), True,
        'OP=NEW without data lines: every gravity load removed at the start of step 2'),
    'op_new_redefined': (
        ['*DLOAD, AMPLITUDE=TOTAL', ', GRAV, {g}, 0., -1.'],
        ['*DLOAD, OP=NEW, AMPLITUDE=TOTAL', ', GRAV, {g}, 0., -1.'],
        lambda t: ramp_long(t), False,
        'OP=NEW defining the same load in total time: continuous, no warning'),
}
VELOCITY_BC = 'velocity_bc'   # element only


def amplitudes() -> list[str]:
    return ['*AMPLITUDE, NAME=LONG', '0., 0., 0.2, 1.',
            '*AMPLITUDE, NAME=TOTAL, TIME=TOTAL TIME', '0., 0., 0.2, 1.',
            '*AMPLITUDE, NAME=SHORT, DEFINITION=SMOOTH STEP', '0., 0., 0.05, 1.']


def fill(lines: list[str]) -> list[str]:
    return [x.format(g=f'{G:g}', g2=f'{2 * G:g}') for x in lines]


def element_scene(rule: str) -> str:
    L = ['*HEADING', f'steps rule {rule}: one free CPE4R element (element driver)',
         '*NODE', '1, 0., 0.', '2, 0.1, 0.', '3, 0.1, 0.1', '4, 0., 0.1',
         '*ELEMENT, TYPE=CPE4R, ELSET=BODY', '1, 1, 2, 3, 4',
         '*NSET, NSET=ALL, GENERATE', '1, 4, 1',
         '*SOLID SECTION, ELSET=BODY, MATERIAL=SOLID', '1.',
         '*MATERIAL, NAME=SOLID', '*DENSITY', '1000.', '*ELASTIC', '1.e8, 0.3'] + amplitudes()
    if rule == VELOCITY_BC:
        step1 = ['*BOUNDARY, TYPE=VELOCITY, AMPLITUDE=LONG', 'ALL, 1, 1, 1.']
        step2 = []
    else:
        step1, step2 = fill(RULES[rule][0]), fill(RULES[rule][1])
    out = ['*OUTPUT, HISTORY, TIME INTERVAL=0.005', '*NODE OUTPUT, NSET=ALL', 'U1, V1, V2']
    for k, (period, loads) in enumerate([(T1, step1), (T2, step2)], start=1):
        L += [f'*STEP, NAME=STEP{k}', '*DYNAMIC, EXPLICIT', f', {period:g}'] + loads + out + ['*END STEP']
    return '\n'.join(L) + '\n'


def mpm_scene(rule: str) -> str:
    L = ['*HEADING', f'steps rule {rule}: a free block of material points (MPM)',
         '*MPM GRID, CELL=0.05, SHAPE=GIMP', '-0.3, -0.6', '0.4, 0.4',
         '*MPM CONTROLS, FLIP=0.99, CFL=0.3',
         '*MATERIAL, NAME=SOLID', '*DENSITY', '1000.', '*ELASTIC', '1.e8, 0.3',
         '*PARTICLES, MATERIAL=SOLID, PPC=2, TYPE=POLYGON',
         '0., 0.', '0.1, 0.', '0.1, 0.1', '0., 0.1'] + amplitudes()
    out = ['*OUTPUT, HISTORY, TIME INTERVAL=0.005', '*ENERGY OUTPUT']
    for k, (period, loads) in enumerate([(T1, fill(RULES[rule][0])), (T2, fill(RULES[rule][1]))], start=1):
        L += [f'*STEP, NAME=STEP{k}', '*DYNAMIC, EXPLICIT', f', {period:g}'] + loads + out + ['*END STEP']
    return '\n'.join(L) + '\n'


def read_history(path: Path) -> dict[str, np.ndarray]:
    text = path.read_text().splitlines()
    names = [n.strip() for n in text[0].split(',')]
    data = np.array([[float(x) for x in line.split(',')] for line in text[1:] if line.strip()])
    return {n: data[:, k] for k, n in enumerate(names)}


def integral(f, t: np.ndarray) -> np.ndarray:
    """∫_0^t f, on a fine grid (f is piecewise smooth; jumps sit at the step boundary)."""
    fine = np.linspace(0.0, T1 + T2, 40001)
    vals = f(fine)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (vals[1:] + vals[:-1]) * np.diff(fine))])
    return np.interp(t, fine, cum)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('rule', nargs='?')
    ap.add_argument('solver', nargs='?', choices=['element', 'mpm'])
    ap.add_argument('--bulkflow')
    ap.add_argument('--workdir')
    ap.add_argument('--list', action='store_true')
    a = ap.parse_args()
    if a.list:
        for name, r in RULES.items():
            print(f'{name}: {r[4]}')
        print(f'{VELOCITY_BC}: carried-over velocity boundary condition, step-time amplitude: held (element)')
        return 0
    if a.rule not in RULES and a.rule != VELOCITY_BC:
        ap.error(f'unknown rule {a.rule}')
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    scene = work / f'{a.rule}_{a.solver}.inp'
    scene.write_text(element_scene(a.rule) if a.solver == 'element' else mpm_scene(a.rule))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1')
    p = subprocess.run([str(Path(a.bulkflow).resolve()), scene.name], cwd=work, capture_output=True, text=True, env=env)
    print(p.stderr, end='')
    if p.returncode != 0:
        print(p.stdout[-2000:])
        print(f'FAIL: bulkflow exit status {p.returncode}')
        return 1
    h = read_history(work / f'{scene.stem}_history.csv')
    t = h['time']
    failures = []

    # the warning: expected exactly when the rule makes gravity jump, naming the step-2 *DLOAD line
    warned = [line for line in p.stderr.splitlines() if 'warning' in line and 'gravity' in line]
    expect_warning = RULES[a.rule][3] if a.rule in RULES else False
    if expect_warning:
        lines = scene.read_text().splitlines()
        dload2 = max(i for i, x in enumerate(lines, start=1) if x.startswith('*DLOAD'))
        target = dload2 + (0 if a.rule == 'op_new_removed' else 1)
        if a.rule == 'op_new_removed':   # the dropped load's line, in step 1
            target = min(i for i, x in enumerate(lines, start=1) if x.startswith('*DLOAD')) + 1
        want = f'{scene.name}:{target}:'
        if not any(want in w for w in warned):
            failures.append(f'no gravity-jump warning naming {want} (got {warned})')
        else:
            print(f'  warning names {want} as expected')
    elif warned:
        failures.append(f'unexpected warning: {warned}')

    if a.rule == VELOCITY_BC:
        u = h['U1_ALL'] if 'U1_ALL' in h else h['U1']
        exp = integral(lambda s: np.where(s <= T1, ramp_long(s), ramp_long(T1)), t)
        err = np.max(np.abs(u - exp))
        tol = 0.005 * np.max(np.abs(exp)) + 1e-3
        print(f'  U1: max |u - u_rule| = {err:.3e} m (tolerance {tol:.3e}), u(0.2) = {u[-1]:.5f} (rule {exp[-1]:.5f})')
        if not err <= tol:
            failures.append('U1 does not follow the held velocity')
    else:
        key = 'VCM2' if a.solver == 'mpm' else ('V2_ALL' if 'V2_ALL' in h else 'V2')
        v = h[key]
        f = RULES[a.rule][2]
        exp = -G * integral(f, t)
        err = np.max(np.abs(v - exp))
        tol = 0.005 * np.max(np.abs(exp)) + 1e-3
        # the slope in each half of step 2 tells the factor applied there
        in2 = (t > T1 + 0.01) & (t < T1 + T2 - 0.005)
        slope = np.polyfit(t[in2], v[in2], 1)[0] if np.count_nonzero(in2) > 2 else math.nan
        print(f'  {RULES[a.rule][4]}')
        print(f'  {key}: max |v - v_rule| = {err:.3e} m/s (tolerance {tol:.3e}); v(0.1) = '
              f'{np.interp(T1, t, v):.5f} (rule {np.interp(T1, t, exp):.5f}), v(0.2) = {v[-1]:.5f} '
              f'(rule {exp[-1]:.5f}); mean acceleration in step 2 {slope:.4f} m/s^2')
        if not err <= tol:
            failures.append(f'{key} does not follow the rule')
    for msg in failures:
        print('FAIL:', msg)
    if not failures:
        print('OK')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
