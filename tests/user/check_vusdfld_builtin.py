#!/usr/bin/env python3
"""A user file with only a VUSDFLD (tests/user/vusdfld_only.f) driving one of our built-in
materials: *MOHR COULOMB with an angle table against field 1, in a single element compressed
in uniaxial strain (CPE4R, C3D8R) and then held.

  builtin_cpe4r, builtin_c3d8r
      field 1 = 0.5 from the user's VUSDFLD (ours would write tr(LE)): the angle table gives
      phi = 30 deg, psi = 0, and on yielding the lateral stress is the Mohr-Coulomb edge value
      s_h = s_v (1 - sin phi)/(1 + sin phi) - 2 c cos phi/(1 + sin phi) (compression positive);
      field 2 = tr(PE) = 0 (psi = 0: no plastic volume change) and field 3 = PE22 = LE22 minus
      the elastic strain of the final stress (vgetvrm('PE') = LE - C^-1:sigma), written as
      FV1..FV3 in the frames.
"""
from __future__ import annotations

import argparse
import importlib.util
import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location('check_user_subroutines', HERE / 'check_user_subroutines.py')
uc = importlib.util.module_from_spec(spec)
spec.loader.exec_module(uc)
USER_FILE = HERE / 'vusdfld_only.f'
E, NU, C = 1.0e7, 0.1, 2000.0
STRAIN = -0.01
H = 0.1


def scene_text(ndim: int, e: float = E, nu: float = NU, c: float = C, density: float = 2000.0,
               strain: float = STRAIN, angles: str = '20., 0., , 0.\n40., 0., , 1.', fields: int = 3) -> str:
    """A unit element compressed in uniaxial strain (y) over 0.03 s, held to 0.05 s; material SAND:
    *ELASTIC, *MOHR COULOMB (DEPENDENCIES=1 when `angles` has a field column), *USER DEFINED FIELD."""
    if ndim == 2:
        nodes = [(0, 0), (H, 0), (H, H), (0, H)]
    else:
        nodes = [(0, 0, 0), (H, 0, 0), (H, H, 0), (0, H, 0), (0, 0, H), (H, 0, H), (H, H, H), (0, H, H)]
    top = [k + 1 for k, x in enumerate(nodes) if x[1] > 0]
    bottom = [k + 1 for k, x in enumerate(nodes) if x[1] == 0]
    lines = ['*HEADING', f'VUSDFLD-only user file on *MOHR COULOMB, {ndim}D', '*NODE']
    lines += [f'{k + 1}, ' + ', '.join(repr(float(v)) for v in x) for k, x in enumerate(nodes)]
    lines += [f'*ELEMENT, TYPE={"CPE4R" if ndim == 2 else "C3D8R"}, ELSET=ALL',
              '1, ' + ', '.join(str(k + 1) for k in range(len(nodes))),
              '*NSET, NSET=NALL', ', '.join(str(k + 1) for k in range(len(nodes))),
              '*NSET, NSET=TOP', ', '.join(map(str, top)), '*NSET, NSET=BOTTOM', ', '.join(map(str, bottom)),
              '*SOLID SECTION, ELSET=ALL, MATERIAL=SAND'] + (['1.0'] if ndim == 2 else [])
    table = ', DEPENDENCIES=1' if angles.count(',') > 1 else ''
    lines += ['*MATERIAL, NAME=SAND', '*DENSITY', repr(density), '*ELASTIC', f'{e!r}, {nu!r}',
              f'*MOHR COULOMB{table}', angles,
              '*MOHR COULOMB HARDENING', f'{c!r}, 0.', '*DEPVAR', '8', f'*USER DEFINED FIELD, FIELDS={fields}',
              '*AMPLITUDE, NAME=RAMP', '0., 0., 0.03, 1., 0.05, 1.',
              '*STEP, NAME=COMPRESS', '*DYNAMIC, EXPLICIT', ', 0.05', '*BOUNDARY', 'NALL, 1, 1, 0.']
    if ndim == 3:
        lines += ['NALL, 3, 3, 0.']
    lines += ['BOTTOM, 2, 2, 0.', '*BOUNDARY, AMPLITUDE=RAMP', f'TOP, 2, 2, {strain * H!r}',
              '*OUTPUT, FIELD, NUMBER INTERVAL=2', '*ELEMENT OUTPUT', 'S, LE, SDV, FV', '*END STEP']
    return '\n'.join(lines) + '\n'


def builtin(a, ndim: int):
    scene = a.work / 'builtin.inp'
    scene.write_text(scene_text(ndim))
    uc.run([a.bulkflow, str(scene), '--quiet', '--user', str(USER_FILE)], a.work)
    fr = uc.last_frame(a.work / 'builtin.h5', 'frames')
    s = np.asarray(fr['S'][0], float)
    le = np.asarray(fr['LE'][0], float)
    fv = [float(fr[f'FV{j}'][0]) for j in (1, 2, 3)]
    uc.check_close('FV1 = 0.5 (the user VUSDFLD, not ours)', fv[0], 0.5, 1e-15)
    phi = math.radians(30.0)
    sv, sh = -s[1], -s[0]
    want_h = sv * (1 - math.sin(phi)) / (1 + math.sin(phi)) - 2 * C * math.cos(phi) / (1 + math.sin(phi))
    if ndim == 3:
        uc.check_close('s33 = s11 (uniaxial strain)', s[2], s[0], 1e-9 * sv)
    uc.check_close('lateral stress on the Mohr-Coulomb edge, phi(field 1 = 0.5) = 30 deg', sh, want_h, 1e-7 * sv)
    lam, g = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    tr = s[0] + s[1] + s[2]
    pe22 = le[1] - (s[1] / (2 * g) - lam * tr / (2 * g * (3 * lam + 2 * g)))
    if not abs(pe22) > 1e-4:
        raise uc.Failed(f'the element did not yield (PE22 = {pe22:.3e})')
    uc.check_close('FV3 = PE22 = LE22 - C^-1:sigma (vgetvrm PE)', fv[2], pe22, 1e-9 * abs(pe22))
    uc.check_close('FV2 = tr(PE) = 0 (psi = 0)', fv[1], 0.0, 1e-9 * abs(pe22))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('case', choices=['builtin_cpe4r', 'builtin_c3d8r'])
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--work', type=Path, required=True)
    a = p.parse_args()
    a.work.mkdir(parents=True, exist_ok=True)
    try:
        builtin(a, 2 if a.case == 'builtin_cpe4r' else 3)
    except uc.Failed as exc:
        print(f'FAILED: {exc}')
        return 1
    print('passed')
    return 0


if __name__ == '__main__':
    sys.exit(main())
