#!/usr/bin/env python3
"""A discrete rigid wall (R2D2 elements of a *RIGID BODY, ELSET=, REF NODE=, contact on their SPOS
side) behaves as the analytic wall it describes.

    check_discrete_rigid.py SCENE --bulkflow BIN --workdir DIR

SCENE is the incline verification scene (inputs/verification/incline_slide_2d.inp: a block sliding on
an analytic TYPE=SEGMENTS line at 30 degrees, mu = 0.3). Two decks are written from it, both with the
wall on a reference node held by *BOUNDARY:
  * analytic: the scene's own *SURFACE, TYPE=SEGMENTS + *RIGID BODY, ANALYTICAL SURFACE=;
  * discrete: the same line meshed as three R2D2 elements (nodes 101-104, node 1 -> node 2 along the
    travel, so SPOS is the material side) in ELSET=WALL, *SURFACE, NAME=SLOPE: WALL, SPOS and
    *RIGID BODY, ELSET=WALL, REF NODE=100 (Abaqus/CAE writes ISOTHERMAL=YES too).
The discrete deck must pass the scene's closed-form check (check_scene.py verify: acceleration
g (sin a - mu cos a), energy balance, wall force) and follow the analytic deck's history: the
block's displacements and the wall force within 1e-6 of their largest magnitude (not bit for bit:
the two split points are on the line only to round-off, and the .h5 holds the wall's 4 extra nodes).
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scene_tools import run_deck as run, verify_deck  # noqa: E402



def decks(text: str) -> tuple[str, str]:
    m = re.search(r'\*SURFACE, TYPE=SEGMENTS, NAME=SLOPE\nSTART, ([^,]+), ([^\n]+)\nLINE, ([^,]+), ([^\n]+)\n', text)
    x0, y0, x1, y1 = (float(v) for v in m.groups())
    held = '*BOUNDARY\n100, ENCASTRE\n*DLOAD'
    analytic = text.replace('*NODE\n', '*NODE\n100, 0., -2.\n').replace(
        m.group(0), m.group(0) + '*RIGID BODY, REF NODE=100, ANALYTICAL SURFACE=SLOPE\n').replace('*DLOAD', held, 1)
    # the same line through 4 nodes: ends exactly as the analytic one, two points between
    pts = [(x0, y0), (x0 + (x1 - x0) * 0.25, y0 + (y1 - y0) * 0.25), (x0 + (x1 - x0) * 0.5, y0 + (y1 - y0) * 0.5),
           (x1, y1)]
    nodes = ''.join(f'{101 + k}, {x!r}, {y!r}\n' for k, (x, y) in enumerate(pts))
    wall = ('*ELEMENT, TYPE=R2D2, ELSET=WALL\n1001, 101, 102\n1002, 102, 103\n1003, 103, 104\n'
            '*SURFACE, NAME=SLOPE\nWALL, SPOS\n*RIGID BODY, ELSET=WALL, REF NODE=100, ISOTHERMAL=YES\n')
    discrete = text.replace('*NODE\n', '*NODE\n100, 0., -2.\n' + nodes).replace(m.group(0), wall).replace(
        '*DLOAD', held, 1)
    return analytic, discrete


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument('scene', type=Path)
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--workdir', type=Path, required=True)
    a = p.parse_args()
    a.workdir.mkdir(parents=True, exist_ok=True)
    analytic, discrete = decks(a.scene.read_text())
    (a.workdir / 'incline_analytic.inp').write_text(analytic)
    deck = a.workdir / 'incline_r2d2.inp'
    deck.write_text(discrete)
    failures = int(not verify_deck(a.bulkflow, deck, a.workdir / 'verify'))
    run(a.bulkflow, a.workdir / 'incline_analytic.inp', a.workdir / 'analytic')
    run(a.bulkflow, deck, a.workdir / 'discrete')
    h1 = np.genfromtxt(a.workdir / 'analytic_history.csv', delimiter=',', names=True)
    h2 = np.genfromtxt(a.workdir / 'discrete_history.csv', delimiter=',', names=True)
    for group in (('U1_BLOCKN', 'U2_BLOCKN'), ('WALLF1_SLOPE', 'WALLF2_SLOPE')):
        ref = np.stack([h1[c] for c in group])
        got = np.stack([h2[c] for c in group])
        worst = float(np.max(np.abs(got - ref)) / np.max(np.abs(ref))) if ref.shape == got.shape else float('inf')
        ok = worst <= 1e-6
        print(f'  {"ok  " if ok else "FAIL"} R2D2 wall vs analytic wall, {"/".join(group)}: largest difference '
              f'{worst:.2e} of the largest magnitude (limit 1e-6), {h2.size} rows')
        failures += not ok
    print('OK' if not failures else f'FAIL ({failures})')
    return 0 if not failures else 1


if __name__ == '__main__':
    raise SystemExit(main())
