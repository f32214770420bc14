#!/usr/bin/env python3
"""*TIME POINTS and *OUTPUT, TIME POINTS=: field frames and history rows at exactly the listed times.

    check_time_points.py SCENE --bulkflow BIN --workdir DIR

SCENE is the incline verification scene (inputs/verification/incline_slide_2d.inp). Its output
requests are replaced by a field request at an irregular list (0, 0.013, 0.05, 0.1234, 0.3999 s: none
a multiple of the stable increment) and a history request at a GENERATE list (0 to 0.4 s every
5 ms), then:
  * the frames' step times must equal the listed times exactly (the increments are cut to land on
    them), one frame per time, nothing else;
  * the history rows' times must be the generated times (to the 16 digits the CSV prints), no other row;
  * the scene's own closed-form check (check_scene.py verify: acceleration on the incline, energy
    balance, wall force) must still hold on the cut increments.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scene_tools import verify_deck  # noqa: E402

FRAMES = [0.0, 0.013, 0.05, 0.1234, 0.3999]
OUTPUTS = """\
*OUTPUT, FIELD, TIME POINTS=frames
*NODE OUTPUT
U, V
*ELEMENT OUTPUT
S
*OUTPUT, HISTORY, TIME POINTS=ROWS
*ENERGY OUTPUT
*NODE OUTPUT, NSET=BLOCKN
U, V
*END STEP
"""
DEFINITIONS = """\
*TIME POINTS, NAME=FRAMES
0., 0.013, 0.05
0.1234, 0.3999
*TIME POINTS, NAME=ROWS, GENERATE
0., 0.4, 0.005
"""


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument('scene', type=Path)
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--workdir', type=Path, required=True)
    a = p.parse_args()
    a.workdir.mkdir(parents=True, exist_ok=True)
    text = a.scene.read_text()
    head, _ = text.split('*OUTPUT, FIELD', 1)
    head = head.replace('*STEP, NAME=SLIDE', DEFINITIONS + '*STEP, NAME=SLIDE')
    deck = a.workdir / 'incline_time_points.inp'
    deck.write_text(head + OUTPUTS)
    failures = not verify_deck(a.bulkflow, deck, a.workdir / 'verify')
    base = next((a.workdir / 'verify').glob('*.h5')).with_suffix('')
    with h5py.File(f'{base}.h5', 'r') as f:
        times = [float(f['frames'][k].attrs['step_time']) for k in sorted(f['frames'])]
    same = times == FRAMES
    print(f'frame step times {times}: {"exactly" if same else "NOT"} the listed {FRAMES}')
    failures += not same
    history = np.genfromtxt(f'{base}_history.csv', delimiter=',', names=True)
    rows = np.atleast_1d(history['time'])
    expected = np.array([0.0 + k * 0.005 for k in range(81)])
    close = rows.shape == expected.shape and bool(np.all(np.abs(rows - expected) <= 1e-15 * 0.4))
    worst = float(np.max(np.abs(rows - expected))) if rows.shape == expected.shape else float('nan')
    print(f'history: {rows.size} rows, expected 81 at 0, 5 ms, ..., 0.4 s; largest time difference {worst:.3g} s')
    failures += not close
    print('OK' if not failures else f'FAIL ({int(failures)})')
    return 0 if not failures else 1


if __name__ == '__main__':
    raise SystemExit(main())
