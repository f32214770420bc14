#!/usr/bin/env python3
"""A user's VUSDFLD writing two field variables (tests/user/two_fields_vusdfld.f: field 1 = the
pressure of the start-of-increment stress read with vgetvrm('S'), field 2 = the point's height
from coordMp; both kept in SDV1, SDV2; its VUMAT copies fieldNew(:, 2) to SDV3), loaded with
--user, and vgetvrm asked for a key the material has not.

  fields_c3d8r, fields_cpe4r  held hydrostatic stress p0 (every node fixed), *USER DEFINED FIELD,
                              FIELDS=2: SDV1 = p0, SDV2 = SDV3 = the element centre's height
  fields_mpm                  a 2D column settling under gravity (FIELDS=2): the host's field
                              arrays have two columns (they had one: the VUSDFLD wrote past them)
  fields_block_cpe4r          12 x 12 CPE4R (144 elements, one solver block): the VUSDFLD, which
                              stops the run on nblock > 136 and records nblock in SDV4, is called
                              with 136 and 8 points
  bad_vgetvrm_peeq            vgetvrm('PEEQ') on a user VUMAT: exit 2 naming the key
"""
from __future__ import annotations

import argparse
import importlib.util
import shutil
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location('check_user_subroutines', HERE / 'check_user_subroutines.py')
uc = importlib.util.module_from_spec(spec)
spec.loader.exec_module(uc)
USER_FILE = HERE / 'two_fields_vusdfld.f'
P0 = 3.0e4


def material(name: str, ask_peeq: bool) -> str:
    return (f'*MATERIAL, NAME={name}\n*DENSITY\n{uc.RHO!r}\n*USER MATERIAL, CONSTANTS=3\n'
            f'{uc.E!r}, {uc.NU!r}, {1.0 if ask_peeq else 0.0}\n*DEPVAR\n4\n'
            '*USER DEFINED FIELD, FIELDS=2\n')


def held_elements(a, ndim: int, ask_peeq: bool = False, n: tuple | None = None):
    scene = a.work / 'held.inp'
    n = n or (1,) * ndim
    _, centroids = uc.element_scene(scene, ndim, n, [0.0, 0.0, 0.0], [0, 0, 1], 0.0, 2e-3)
    text = scene.read_text()
    start, end = text.index('*MATERIAL'), text.index('*INITIAL CONDITIONS, TYPE=TEMPERATURE')
    stress = [-P0] * 3 + [0.0] * (1 if ndim == 2 else 3)
    text = (text[:start] + material('PROBE-NEO', ask_peeq) + '*INITIAL CONDITIONS, TYPE=STRESS\nALL, '
            + ', '.join(repr(s) for s in stress) + '\n' + text[end:])
    scene.write_text(text)
    cmd = [a.bulkflow, str(scene), '--quiet', '--user', str(USER_FILE)]
    if ask_peeq:
        proc = uc.run(cmd, a.work, expect=2)
        message = proc.stdout + proc.stderr
        if ("vgetvrm('PEEQ')" not in message or 'not available' not in message
                or 'material PROBE-NEO' not in message or "vgetvrm(''SDV'')" in message
                or "vgetvrm('SDV')" not in message):
            raise uc.Failed(f'the error does not name the key: {message[-600:]}')
        print('  ' + [ln for ln in message.splitlines() if 'vgetvrm' in ln][0][:240])
        return
    uc.run(cmd, a.work)
    fr = uc.last_frame(a.work / 'held.h5', 'frames')
    sdv = np.asarray(fr['SDV'], float)
    heights = np.array([c[1] for c in centroids])
    uc.check_close('SDV1 = field 1 = pressure (vgetvrm S)', sdv[:, 0], P0, 1e-9 * P0)
    uc.check_close('SDV2 = field 2 = height (coordMp)', sdv[:, 1], heights, 1e-12)
    uc.check_close('SDV3 = fieldNew(:, 2) seen by the VUMAT', sdv[:, 2], heights, 1e-12)
    sizes = sorted(set(sdv[:, 3].astype(int)))
    print(f'  {len(sdv)} elements, VUSDFLD nblock seen: {sizes}')
    if max(sizes) > 136:
        raise uc.Failed(f'the VUSDFLD got nblock {max(sizes)} > 136')
    if len(sdv) == 144 and sizes != [8, 136]:
        raise uc.Failed(f'144 elements in one block: expected VUSDFLD calls of 136 and 8 points, got {sizes}')


def fields_mpm(a):
    scene = a.work / 'column.inp'
    scene.write_text(f"""*HEADING
two field variables from a user VUSDFLD on particles
*MPM GRID, CELL=0.05, SHAPE=GIMP
-0.2, -0.2
0.4, 1.4
*MPM CONTROLS, FLIP=0.99, CFL=0.3, DAMPING=0.2
{material('SOIL', False)}*PARTICLES, MATERIAL=SOIL, PPC=2
0., 0.
0.25, 1.0
*MPM WALL, NAME=AXIS, TYPE=SYMMETRY
0., 1.4, 0., -0.2
*MPM WALL, NAME=SIDE, TYPE=SYMMETRY
0.25, -0.2, 0.25, 1.4
*MPM WALL, NAME=FLOOR, TYPE=SYMMETRY
-0.2, 0., 0.4, 0.
*STEP, NAME=SETTLE
*DYNAMIC, EXPLICIT
, 0.1
*DLOAD
, GRAV, 9.81, 0., -1.
*OUTPUT, FIELD, NUMBER INTERVAL=1
*ELEMENT OUTPUT
S, SDV
*END STEP
""")
    uc.run([a.bulkflow, str(scene), '--quiet', '--user', str(USER_FILE)], a.work)
    fr = uc.last_frame(a.work / 'column.h5', 'particles')
    y = fr['coordinates'][:, 1]
    sdv = fr['SDV']
    # SDV2 is coordMp of the increment's start, the frame holds the end: one increment of motion.
    uc.check_close('SDV2 = SDV3 = field 2 = height (coordMp)', sdv[:, 2], sdv[:, 1], 0.0)
    uc.check_close('SDV2 = particle height', sdv[:, 1], y, 1e-3)
    p = -fr['S'][:, :3].mean(axis=1)
    uc.check_close('SDV1 = field 1 = pressure (vgetvrm S)', sdv[:, 0], p, 0.05 * float(np.max(np.abs(p))))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('case')
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--work', type=Path, required=True)
    a = p.parse_args()
    if a.work.exists():
        shutil.rmtree(a.work)
    a.work.mkdir(parents=True)
    cases = {
        'fields_c3d8r': lambda: held_elements(a, 3),
        'fields_cpe4r': lambda: held_elements(a, 2),
        'fields_mpm': lambda: fields_mpm(a),
        'fields_block_cpe4r': lambda: held_elements(a, 2, n=(12, 12)),
        'bad_vgetvrm_peeq': lambda: held_elements(a, 3, ask_peeq=True),
    }
    if a.case not in cases:
        p.error(f'unknown case {a.case}; expected one of {", ".join(cases)}')
    try:
        cases[a.case]()
    except uc.Failed as exc:
        print(f'FAILED: {a.case}: {exc}')
        return 1
    print(f'OK: {a.case}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
