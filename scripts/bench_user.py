#!/usr/bin/env python3
"""What loading the material at run time costs: --user (our single Abaqus file, compiled and
loaded with dlopen) against --user-linked (the same VUMAT linked into the executable), on the
same scenes, the same user path through the host. Runs alternate (linked, loaded, loaded, linked, ...)
so that a busy machine slows both alike; the figure is the median of the time-loop seconds
the solver reports (element scenes: the 'total' of the timing table; MPM: 'time loop').

    python3 scripts/bench_user.py [--build build] [--repeats 5] [--n-across 60]

Prints per scene the two medians, the ratio loaded/linked (target: within 1.02), the median of
the per-pair ratios, and the load average before and after (a shared machine: read the ratios
against it).
"""
from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def loop_seconds(text: str) -> float:
    m = re.search(r'time loop\s+([0-9.eE+-]+) s', text)
    if m:
        return float(m.group(1))
    m = re.search(r'^\s*total\s+([0-9.eE+-]+)\s*$', text, re.M)
    if m:
        return float(m.group(1))
    raise RuntimeError('no timing in the solver output:\n' + text[-2000:])


def run(cmd: list[str], cwd: Path, env: dict) -> float:
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout + proc.stderr)
        raise SystemExit(f'failed: {" ".join(cmd)}')
    return loop_seconds(proc.stdout)


def load_average() -> str:
    """The 1-, 5- and 15-minute load averages (the machine may be shared)."""
    try:
        return ' '.join(Path('/proc/loadavg').read_text().split()[:3])
    except OSError:
        return 'unknown'


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--build', type=Path, default=REPO / 'build')
    p.add_argument('--repeats', type=int, default=5)
    p.add_argument('--n-across', type=int, default=60, help='elements across the hopper outlet (size)')
    a = p.parse_args()
    build = a.build.resolve()   # the runs start in a scratch folder: a relative --build must not follow them
    bulkflow = build / 'bin' / 'bulkflow'
    single = build / 'abaqus' / 'bulkflow_abaqus.f'
    work = Path(tempfile.mkdtemp(prefix='bench_user_'))
    env = dict(os.environ, BULKFLOW_CACHE_DIR=str(work / 'cache'))
    make_hopper = REPO / '.venv' / 'bin' / 'bulkflow-make-hopper'
    scenes = []
    hopper = work / 'hopper_mc.inp'
    subprocess.run([str(make_hopper), '-o', str(hopper), '--n-across', str(a.n_across), '--initial-k', '0.4903',
                    '--ramp', '0', '--hold', '0.013', '--field-frames', '0', '--history-points', '20'],
                   check=True, capture_output=True)
    scenes.append(('CPE4R Mohr-Coulomb hopper', hopper, []))
    # The MPM hopper of the ch. 4 layout, 3000 increments (a time loop of about 3 s): in the
    # 0.2 s loop of hopper_small_2d a fixed cost of 10-20 ms (the loaded library's pages touched
    # and its symbols bound on the first calls) read as a 7-11 % slower loaded path, which a
    # run of useful length does not show.
    scenes.append(('MPM hopper (wedge_hopper_mpm, 3000 inc)', REPO / 'inputs' / 'mpm' / 'wedge_hopper_mpm.inp',
                   ['--stop-after', '3000']))
    # Compile once before timing (the cache then serves every run).
    subprocess.run([str(bulkflow), str(scenes[1][1]), '--check', '--user', str(single)], cwd=work, env=env,
                   check=True, capture_output=True)
    print(f'bench_user: {bulkflow}, {a.repeats} alternated runs each, median time-loop seconds; '
          f'load average {load_average()} at the start')
    worst = 0.0
    for name, scene, limit in scenes:
        linked, loaded = [], []
        for k in range(a.repeats):
            # alternate which goes first, so a load that drifts within a pair favours neither
            pair = [('linked', ['--user-linked']), ('loaded', ['--user', str(single)])]
            for kind, extra in (pair if k % 2 == 0 else pair[::-1]):
                seconds = run([str(bulkflow), str(scene), '--output', kind] + extra + limit, work, env)
                (linked if kind == 'linked' else loaded).append(seconds)
        ml, mo = statistics.median(linked), statistics.median(loaded)
        ratio = mo / ml
        pairwise = statistics.median(o / l for o, l in zip(loaded, linked))
        worst = max(worst, ratio)
        print(f'  {name:32s} linked {ml:8.3f} s   loaded {mo:8.3f} s   ratio {ratio:6.3f}'
              f'   (min {min(linked):.3f} / {min(loaded):.3f}; median of pair ratios {pairwise:.3f})')
    print(f'  largest ratio loaded/linked: {worst:.3f} (target <= 1.02); load average {load_average()} at the end')
    return 0


if __name__ == '__main__':
    sys.exit(main())
