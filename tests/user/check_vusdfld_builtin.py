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
  keys_cpe4r, keys_c3d8r
      the same scene with a temperature ramp (*TEMPERATURE, AMPLITUDE=: 20 -> 80 while compressing,
      then held), *DEPVAR 3 and tests/user/vgetvrm_keys.f, which reads every documented vgetvrm
      key: FV2..FV6 = TEMP, PEEQ, LE22, S22, PE22 at the start of the last increment (the element
      is held: the final values). The VUSDFLD gets the 3 *DEPVAR state variables only (it checks
      nstatev and SDV == stateOld itself), SDV9..SDV11 after our model's SDV1..8: SDV9 = its call
      count = the increment count, SDV10 = PEEQ; our PEEQ (SDV1) is not touched by its writes.
  bad_vgetvrm_sp
      the same VUSDFLD asking for 'SP' (principal stresses, not provided): exit 2, the message
      names the key and the material.
"""
from __future__ import annotations

import argparse
import importlib.util
import math
import sys
from pathlib import Path

import h5py
import numpy as np

HERE = Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location('check_user_subroutines', HERE / 'check_user_subroutines.py')
uc = importlib.util.module_from_spec(spec)
spec.loader.exec_module(uc)
USER_FILE = HERE / 'vusdfld_only.f'
KEYS_FILE = HERE / 'vgetvrm_keys.f'
T_START, T_END = 20.0, 80.0
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


def keys_scene(ndim: int, ask_sp: bool = False) -> str:
    """scene_text with six fields, the VUSDFLD's one property and a temperature ramp."""
    text = scene_text(ndim, fields=6)
    text = text.replace('*USER DEFINED FIELD, FIELDS=6\n',
                        f'*USER DEFINED FIELD, FIELDS=6, PROPERTIES=2\n{1.0 if ask_sp else 0.0}, 3.\n')
    text = text.replace('*DEPVAR\n8\n', '*DEPVAR\n3\n')
    text = text.replace('*STEP, NAME=COMPRESS\n',
                        f'*INITIAL CONDITIONS, TYPE=TEMPERATURE\nNALL, {T_START!r}\n'
                        f'*AMPLITUDE, NAME=TRAMP\n0., {T_START!r}, 0.03, {T_END!r}, 0.05, {T_END!r}\n'
                        '*STEP, NAME=COMPRESS\n')
    text = text.replace('*DYNAMIC, EXPLICIT\n, 0.05\n', '*DYNAMIC, EXPLICIT\n, 0.05\n*TEMPERATURE, AMPLITUDE=TRAMP\nNALL, 1.0\n')
    text = text.replace('S, LE, SDV, FV\n', 'S, LE, PEEQ, SDV, FV\n')
    return text


def keys(a, ndim: int):
    scene = a.work / 'keys.inp'
    scene.write_text(keys_scene(ndim))
    uc.run([a.bulkflow, str(scene), '--quiet', '--user', str(KEYS_FILE)], a.work)
    fr = uc.last_frame(a.work / 'keys.h5', 'frames')
    s = np.asarray(fr['S'][0], float)
    le = np.asarray(fr['LE'][0], float)
    peeq = float(np.ravel(fr['PEEQ'])[0])
    fv = [float(fr[f'FV{j}'][0]) for j in range(1, 7)]
    if not peeq > 1e-4:
        raise uc.Failed(f'the element did not yield (PEEQ = {peeq:.3e})')
    uc.check_close('FV1 = 0.5', fv[0], 0.5, 0.0)
    uc.check_close("FV2 = vgetvrm('TEMP') = the held temperature", fv[1], T_END, 1e-12 * T_END)
    uc.check_close("FV3 = vgetvrm('PEEQ') = PEEQ output", fv[2], peeq, 1e-12 * peeq)
    uc.check_close("FV4 = vgetvrm('LE') LE22", fv[3], le[1], 1e-12 * abs(le[1]))
    uc.check_close("FV5 = vgetvrm('S') S22", fv[4], s[1], 1e-12 * abs(s[1]))
    lam, g = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    tr = s[0] + s[1] + s[2]
    pe22 = le[1] - (s[1] / (2 * g) - lam * tr / (2 * g * (3 * lam + 2 * g)))
    uc.check_close("FV6 = vgetvrm('PE') PE22 = LE22 - C^-1:sigma", fv[5], pe22, 1e-9 * abs(pe22))
    with h5py.File(a.work / 'keys.h5', 'r') as f:
        frames = f['frames']
        increments = int(frames[sorted(frames)[-1]].attrs['increment'])
    sdv = np.ravel(fr['SDV'])
    if len(sdv) != 11:
        raise uc.Failed(f'{len(sdv)} state variables; expected our 8 + *DEPVAR 3')
    uc.check_close('SDV1 = PEEQ (ours, not the VUSDFLD\'s)', sdv[0], peeq, 0.0)
    uc.check_close('SDV9 = the VUSDFLD\'s SDV1 = its calls = increments', sdv[8], increments, 0.0)
    uc.check_close('SDV10 = the VUSDFLD\'s SDV2 = PEEQ', sdv[9], peeq, 1e-12 * peeq)
    print(f'  PEEQ {peeq:.6e}, TEMP {fv[1]}, LE22 {le[1]:.6e}, S22 {s[1]:.6e}, PE22 {pe22:.6e}')


def bad_sp(a):
    scene = a.work / 'keys_sp.inp'
    scene.write_text(keys_scene(2, ask_sp=True))
    proc = uc.run([a.bulkflow, str(scene), '--quiet', '--user', str(KEYS_FILE)], a.work, expect=2)
    message = proc.stdout + proc.stderr
    for must in ("vgetvrm('SP')", 'material SAND', 'not available', 'S, LE, SDV, TEMP, PE, PEEQ'):
        if must not in message:
            raise uc.Failed(f'the error does not say {must!r}: {message[-600:]}')
    print('  ' + [ln for ln in message.splitlines() if 'vgetvrm' in ln][0][:200])


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('case', choices=['builtin_cpe4r', 'builtin_c3d8r', 'keys_cpe4r', 'keys_c3d8r', 'bad_vgetvrm_sp'])
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--work', type=Path, required=True)
    a = p.parse_args()
    a.work.mkdir(parents=True, exist_ok=True)
    cases = {
        'builtin_cpe4r': lambda: builtin(a, 2),
        'builtin_c3d8r': lambda: builtin(a, 3),
        'keys_cpe4r': lambda: keys(a, 2),
        'keys_c3d8r': lambda: keys(a, 3),
        'bad_vgetvrm_sp': lambda: bad_sp(a),
    }
    try:
        cases[a.case]()
    except uc.Failed as exc:
        print(f'FAILED: {exc}')
        return 1
    print('passed')
    return 0


if __name__ == '__main__':
    sys.exit(main())
