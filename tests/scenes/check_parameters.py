#!/usr/bin/env python3
"""Abaqus parametric input: a deck written with *PARAMETER and <name> must give the results of the
same deck written out by hand (every <name> replaced by the value Python computes) bit for bit.

    check_parameters.py --bulkflow BIN --workdir DIR

The deck is the 2 x 2 block sliding on a 30 degree incline (inputs/verification/incline_slide_2d.inp)
with its geometry, material, friction, loads, step and output written through parameters:
integers, reals, a string (the material name, in keyword lines), math functions (sin, cos, tan,
radians), a negated parameter `-<x>` and parameters defined after a use (Abaqus reads every
definition first). The written-out deck is made here with Python's own evaluation (`eval` with the
math module), so the test also checks that our evaluator gives Python's doubles: the history CSV
must be byte-identical and every .h5 dataset and attribute identical (h5py, bytes), no NaN.
"""
from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'scripts'))
from compare_binaries import h5_differences  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scene_tools import run_deck as run  # noqa: E402

DEFINITIONS = """\
alpha_deg = 30
alpha = alpha_deg*pi/180.          # radians
h = 0.1/2                          # element size
c = h*cos(alpha)
s = h*sin(alpha)
mu = 0.3*tan(alpha)/tan(radians(30.0))
rho = 2.e3
young = 1.0e7
nu = 0.3
g = 9.81
period = 0.4
ramp = period/8
scale = 4/5.
frames = 2**2
rows = 200
mat = 'SOL' + "ID"
sx0 = -0.5*cos(alpha)
sy0 = 0.5*sin(alpha)
sx1 = 2*cos(alpha)
sy1 = 2.0*sin(alpha)
"""

DECK = """\
** parameterized incline (tests/scenes/check_parameters.py)
*HEADING
parametric input: block on an incline (a heading is free text: <alpha_deg> stays as written)
*PARAMETER
{definitions}*NODE
{nodes}*ELEMENT, TYPE=CPE4R, ELSET=BLOCK
1, 1, 2, 5, 4
2, 2, 3, 6, 5
3, 4, 5, 8, 7
4, 5, 6, 9, 8
*NSET, NSET=BLOCKN
1, 2, 3, 4, 5, 6, 7, 8, 9
*ELSET, ELSET=BASE
1, 2
*SECTION CONTROLS, NAME=HOURGLASS, HOURGLASS=STIFFNESS
*SOLID SECTION, ELSET=BLOCK, MATERIAL=<mat>, CONTROLS=HOURGLASS
1.0
*MATERIAL, NAME=<mat>
*DENSITY
<rho>
*ELASTIC
<young>, <nu>
*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP
0., 0., <ramp>, 1.
*SURFACE, NAME=BOTTOM
BASE, S1
*SURFACE, TYPE=SEGMENTS, NAME=SLOPE
START, <sx0>, <sy0>
LINE, <sx1>, -<sy1>
*SURFACE INTERACTION, NAME=ROUGH
*FRICTION
<mu>
*CONTACT PAIR, INTERACTION=ROUGH
BOTTOM, SLOPE
*STEP, NAME=SLIDE
*DYNAMIC, EXPLICIT, SCALE FACTOR=<scale>
, <period>
*DLOAD, AMPLITUDE=RAMP
, GRAV, <g>, 0., -1.
*OUTPUT, FIELD, NUMBER INTERVAL=<frames>
*NODE OUTPUT
U, V
*ELEMENT OUTPUT
S
*OUTPUT, HISTORY, NUMBER INTERVAL=<rows>
*ENERGY OUTPUT
*NODE OUTPUT, NSET=BLOCKN
U, V
*END STEP
*PARAMETER
** defined after its use: the <sy0> above is this value (Abaqus reads every definition first)
sy0 = 0.5*sin(alpha) + 0.0
"""


def parameterized() -> str:
    """Node n = 1 + i + 3 j of the 3 x 3 grid at x = i c + j s, y = -i s + j c."""
    nodes, node_defs = '', ''
    for j in range(3):
        for i in range(3):
            n = 1 + i + 3 * j
            nodes += f'{n}, <x_{n}>, <y_{n}>\n'
            node_defs += f'x_{n} = {i}*c + {j}*s\ny_{n} = -{i}*s + {j}*c\n'
    return DECK.format(definitions=DEFINITIONS + node_defs, nodes=nodes)


def written_out(deck: str) -> str:
    """What Python makes of the deck: definitions evaluated in order, every <name> replaced by
    repr(value) (str for strings), *PARAMETER blocks removed."""
    values: dict[str, object] = {}
    namespace = {k: getattr(math, k) for k in dir(math) if not k.startswith('_')}
    out: list[str] = []
    in_parameter = in_heading = False
    for line in deck.splitlines():
        if line.startswith('*') and not line.startswith('**'):
            in_parameter = line.upper().startswith('*PARAMETER')
            in_heading = line.upper().startswith('*HEADING')
            if in_parameter:
                continue
        if in_parameter:
            if not line.startswith('**'):
                name, expression = line.split('=', 1)
                values[name.strip()] = eval(expression.split('#')[0], dict(namespace), dict(values))  # noqa: S307
            continue
        out.append(line if in_heading else re.sub(r'<([A-Za-z_]\w*)>', lambda m: text_of(values[m.group(1)]), line))
    return '\n'.join(out) + '\n'


def text_of(value: object) -> str:
    return value if isinstance(value, str) else repr(value)


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--workdir', type=Path, required=True)
    a = p.parse_args()
    a.workdir.mkdir(parents=True, exist_ok=True)
    deck = parameterized()
    param_deck = a.workdir / 'incline_parameters.inp'
    param_deck.write_text(deck)
    flat_deck = a.workdir / 'incline_written_out.inp'
    flat_deck.write_text(written_out(deck))
    run(a.bulkflow, flat_deck, a.workdir / 'written_out')
    run(a.bulkflow, param_deck, a.workdir / 'parameters')
    reference = (a.workdir / 'written_out_history.csv').read_text()
    history = (a.workdir / 'parameters_history.csv').read_text()
    rows = len(reference.splitlines()) - 1
    diffs = h5_differences(a.workdir / 'written_out.h5', a.workdir / 'parameters.h5')
    nonfinite = 'nan' in reference.lower() or 'inf' in reference.lower().replace('info', '')
    header, last = reference.splitlines()[0].split(','), reference.splitlines()[-1].split(',')
    moved = {k: float(last[header.index(k)]) for k in ('time', 'U1_BLOCKN', 'U2_BLOCKN')}
    print(f'history {"identical" if history == reference else "DIFFERS"} ({rows} rows); '
          f'.h5 {"identical" if not diffs else "DIFFERS: " + ", ".join(diffs[:5])}; '
          f'NaN/Inf {"found" if nonfinite else "none"}; the block slid {moved}')
    failures = (history != reference) + bool(diffs) + nonfinite + (rows < 100)
    print('OK' if failures == 0 else f'FAIL ({failures})')
    return 0 if failures == 0 else 1


if __name__ == '__main__':
    raise SystemExit(main())
