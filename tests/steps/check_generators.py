#!/usr/bin/env python3
"""The scenes our generators write, and the committed scenes of inputs/, say what they mean:
gravity that stays on. Each is read with `bulkflow --check`; none may draw the scene builder's
warning of a gravity jump at a step start (src/input/scene_step_continuity.f90).

    check_generators.py --bulkflow BIN --workdir DIR --inputs INPUTS_DIR

Generators: bulkflow-make-mpm-hopper (bulkflow.mpm.hopper_scene, default and without inflow),
bulkflow-make-hopper (bulkflow.scenes.wedge_hopper, default and --dim 3), bulkflow-make-arching
(bulkflow.arching.scene). The check itself is shown to work by a scene that restarts its gravity
ramp in the discharge step (the pattern of issue 22): it must draw the warning.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

GENERATORS = [
    ('mpm_hopper', ['-m', 'bulkflow.mpm.hopper_scene']),
    ('mpm_hopper_no_inflow', ['-m', 'bulkflow.mpm.hopper_scene', '--no-inflow']),
    ('element_hopper', ['-m', 'bulkflow.scenes.wedge_hopper']),
    ('element_hopper_3d', ['-m', 'bulkflow.scenes.wedge_hopper', '--dim', '3']),
    ('arching', ['-m', 'bulkflow.arching.scene', '--outlet-width', '0.1']),
]


def check(exe: str, scene: Path) -> tuple[int, list[str]]:
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1')
    p = subprocess.run([exe, str(scene), '--check'], capture_output=True, text=True, env=env)
    return p.returncode, [x for x in p.stderr.splitlines() if 'warning' in x and 'gravity' in x]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--bulkflow', required=True)
    ap.add_argument('--workdir', required=True)
    ap.add_argument('--inputs', required=True)
    a = ap.parse_args()
    exe = str(Path(a.bulkflow).resolve())
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    failures = []
    scenes = []
    for name, args in GENERATORS:
        out = work / f'{name}.inp'
        p = subprocess.run([sys.executable, *args, '-o', str(out)], capture_output=True, text=True)
        if p.returncode != 0 or not out.exists():
            failures.append(f'generator {name} failed: {p.stderr[-500:]}')
            continue
        scenes.append(out)
    # every solver scene of inputs/ (inputs/matpoint/ holds material-point driver decks, not scenes)
    scenes += sorted(x for x in Path(a.inputs).rglob('*.inp') if 'matpoint' not in x.parts)
    for scene in scenes:
        rc, warned = check(exe, scene)
        print(f'  {"OK  " if rc == 0 and not warned else "FAIL"} {scene}')
        if rc != 0:
            failures.append(f'{scene}: bulkflow --check exit status {rc}')
        failures += [f'{scene}: {w}' for w in warned]
    # the check can fail: the issue-22 pattern (ramp in step time, defined again in the discharge)
    text = (work / 'mpm_hopper.inp').read_text() if (work / 'mpm_hopper.inp').exists() else ''
    if '*STEP, NAME=DISCHARGE' in text:
        bad = work / 'restarted_ramp.inp'
        bad.write_text(text.replace('TIME=TOTAL TIME', 'TIME=STEP TIME').replace(
            '*MPM WALL, NAME=OUTLET, OP=DELETE', '*MPM WALL, NAME=OUTLET, OP=DELETE\n*DLOAD, AMPLITUDE=RAMP\n'
            ', GRAV, 9.81, 0., -1.', 1))
        rc, warned = check(exe, bad)
        print(f'  restarted ramp (must warn): {warned[0] if warned else "no warning"}')
        if not warned:
            failures.append('a scene that restarts its gravity ramp drew no warning')
    for f in failures:
        print('FAIL:', f)
    print('OK' if not failures else f'{len(failures)} failure(s)')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
