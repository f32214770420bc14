#!/usr/bin/env python3
"""Particle field outputs FV and TEMP (issue 15; src/mpm/mpm_output.f90).

    check_fields.py --bulkflow EXE --workdir DIR SCENE.inp

SCENE (scenes/fields_mpm.inp) asks for `*ELEMENT OUTPUT` S, FV, TEMP. Checks:
  1. every particle frame holds FV1 and TEMP, one value per particle, and BASE.xmf shows them;
  2. SOFT (our VUSDFLD: field 1 = tr LE read at the start of each increment): FV1 = 0 in the
     initial frame, afterwards within 5 % of max |tr LE| of the frame's tr LE (one increment's lag)
     and not zero; HARD (built-in, no VUSDFLD): FV1 = 0;
  3. TEMP: SOFT 100 x RAMP(step time) (RAMP linear 0 -> 1 over 0.4 s) to 1e-12, HARD 30 exactly;
  4. the same scene without FV and TEMP in the request writes neither (datasets or XDMF).
"""
import argparse
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np


def run(exe, scene, base):
    r = subprocess.run([exe, str(scene), '--output', str(base), '--quiet'], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout, r.stderr)
        sys.exit(f'FAIL: {scene} exit status {r.returncode}')


def main():
    p = argparse.ArgumentParser()
    p.add_argument('scene', type=Path)
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--workdir', required=True, type=Path)
    a = p.parse_args()
    a.workdir.mkdir(parents=True, exist_ok=True)
    failures = []

    def check(ok, what):
        print(f"{'ok  ' if ok else 'FAIL'} {what}")
        if not ok:
            failures.append(what)

    base = a.workdir / 'fields'
    run(a.bulkflow, a.scene, base)
    with h5py.File(f'{base}.h5', 'r') as f:
        frames = sorted(f['particles'])
        check(len(frames) == 5, f'{len(frames)} frames (5 expected)')
        for k in frames:
            g = f['particles'][k]
            t = float(g.attrs['step_time'][0])
            n = int(g.attrs['count'][0])
            has = 'FV1' in g and 'TEMP' in g
            check(has and g['FV1'].shape == (n,) and g['TEMP'].shape == (n,), f'frame {k}: FV1, TEMP of {n} particles')
            if not has:
                continue
            mat, fv, temp = g['material'][()], g['FV1'][()], g['TEMP'][()]
            le = g['LE'][()]
            tr = le[:, 0] + le[:, 1] + le[:, 2]
            soft, hard = mat == 1, mat == 2
            if t == 0:
                check(np.all(fv == 0), f'frame {k}: FV1 = 0 before the first increment')
            else:
                lag = np.abs(fv[soft] - tr[soft]).max()
                scale = np.abs(tr[soft]).max()
                check(scale > 0 and lag <= 0.05 * scale and np.abs(fv[soft]).max() > 0,
                      f'frame {k}: SOFT FV1 = tr LE of the VUSDFLD (max |diff| {lag:.2e} of max |tr LE| {scale:.2e})')
            check(np.all(fv[hard] == 0), f'frame {k}: HARD FV1 = 0 (no VUSDFLD)')
            want = 100.0 * min(t / 0.4, 1.0)
            check(np.allclose(temp[soft], want, rtol=1e-12, atol=1e-12), f'frame {k}: SOFT TEMP = {want:.6g}')
            check(np.all(temp[hard] == 30.0), f'frame {k}: HARD TEMP = 30')
    xmf = Path(f'{base}.xmf').read_text()
    check(xmf.count('Name="FV1"') == 5 and xmf.count('Name="TEMP"') == 5, 'BASE.xmf shows FV1 and TEMP in every frame')

    plain = a.workdir / 'fields_plain.inp'
    text = a.scene.read_text()
    assert 'S, FV, TEMP' in text
    plain.write_text(text.replace('S, FV, TEMP', 'S'))
    base = a.workdir / 'plain'
    run(a.bulkflow, plain, base)
    with h5py.File(f'{base}.h5', 'r') as f:
        extra = [k for k in f['particles'] if 'FV1' in f['particles'][k] or 'TEMP' in f['particles'][k]]
    xmf = Path(f'{base}.xmf').read_text()
    check(not extra and 'FV1' not in xmf and 'TEMP' not in xmf, 'without the request: no FV1, TEMP')
    sys.exit(1 if failures else 0)


if __name__ == '__main__':
    main()
