#!/usr/bin/env python3
"""Self-test of scripts/check_layers.py and scripts/check_sizes.py (ctest layers_checks_selftest).

Each case copies src/ and umat/ of the repository into a temporary tree, breaks one rule there and
runs the checker on the copy: it must exit 1 and name the file and line of the break. The clean
copy must pass first, so a checker that always fails is caught too.

    python3 tests/layers/test_layer_checks.py [--root REPO]
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path


def run(script: Path, root: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(script), '--root', str(root), *extra],
                          capture_output=True, text=True)


def inject_after_module(path: Path, line: str) -> int:
    """Insert `line` right after the `module` statement of path; return its line number."""
    lines = path.read_text().splitlines()
    for i, text in enumerate(lines):
        if text.lstrip().lower().startswith('module '):
            lines.insert(i + 1, line)
            path.write_text('\n'.join(lines) + '\n')
            return i + 2
    raise SystemExit(f'no module statement in {path}')


def expect(result: subprocess.CompletedProcess, code: int, needle: str, what: str) -> list[str]:
    out = result.stdout + result.stderr
    problems = []
    if result.returncode != code:
        problems.append(f'{what}: exit {result.returncode}, expected {code}\n{out}')
    if needle not in out:
        problems.append(f'{what}: "{needle}" not in the output\n{out}')
    if not problems:
        print(f'ok: {what}: exit {result.returncode}; {needle}')
    return problems


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument('--root', type=Path, default=Path(__file__).resolve().parents[2])
    args = parser.parse_args()
    layers = args.root / 'scripts' / 'check_layers.py'
    sizes = args.root / 'scripts' / 'check_sizes.py'
    problems: list[str] = []
    with tempfile.TemporaryDirectory(prefix='bulkflow-layers-') as tmp:
        def fresh(name: str) -> Path:
            copy = Path(tmp) / name
            for top in ('src', 'umat'):
                shutil.copytree(args.root / top, copy / top)
            return copy

        clean = fresh('clean')
        problems += expect(run(layers, clean), 0, 'go down the layers', 'layers: clean copy passes')
        problems += expect(run(sizes, clean), 0, 'routines <=', 'sizes: clean copy passes')

        # An upward use: the model layer reaching into the element driver.
        up = fresh('upward')
        line = inject_after_module(up / 'src/model/model_steps.f90', '  use driver_run, only: one_increment')
        problems += expect(run(layers, up), 1,
                           f'src/model/model_steps.f90:{line}: forbidden upward use of driver_run',
                           'layers: upward use in src/model fails')

        # A sideways use: MPM (outside the temporary exceptions) using the element driver.
        side = fresh('sideways')
        line = inject_after_module(side / 'src/mpm/mpm_grid.f90', '  use driver_solver, only: solver_t')
        problems += expect(run(layers, side), 1,
                           f'src/mpm/mpm_grid.f90:{line}: forbidden sideways use of driver_solver',
                           'layers: sideways use mpm -> driver fails')

        # The kernels must not use the solver either (the single Abaqus file stands alone).
        kern = fresh('kernels')
        line = inject_after_module(kern / 'umat/elasticity.f90', '  use model_mesh, only: mesh_t')
        problems += expect(run(layers, kern), 1,
                           f'umat/elasticity.f90:{line}: forbidden upward use of model_mesh',
                           'layers: umat using src/model fails')

        # --strict-kinds: a solver module that takes its kinds from material_kinds is reported
        # (the solver uses base_kinds), umat's own uses are not.
        problems += expect(run(layers, clean, '--strict-kinds'), 0, 'go down the layers',
                           'layers --strict-kinds passes on the tree as it is')
        kinds = fresh('kinds')
        line = inject_after_module(kinds / 'src/model/model_steps.f90', '  use material_kinds, only: dp')
        result = run(layers, kinds, '--strict-kinds')
        problems += expect(result, 1, f'src/model/model_steps.f90:{line}:',
                           'layers --strict-kinds reports a solver use of material_kinds')
        if 'umat/' in result.stdout:
            problems.append('layers --strict-kinds: reported a use inside umat/')

        # A routine of 151 lines outside the exceptions.
        long = fresh('long')
        body = ['subroutine too_long_for_the_rule(x)', '  real, intent(inout) :: x']
        body += ['  x = x + 1.0'] * 148 + ['end subroutine too_long_for_the_rule']
        path = long / 'src/base/error_report.f90'
        path.write_text(path.read_text() + '\n' + '\n'.join(body) + '\n')
        first = len(path.read_text().splitlines()) - len(body) + 1
        problems += expect(run(sizes, long), 1,
                           f'src/base/error_report.f90:{first}: routine too_long_for_the_rule has 151 lines',
                           'sizes: a 151-line routine fails')
        # A file of 701 lines.
        path.write_text(path.read_text() + '!\n' * (701 - len(path.read_text().splitlines())))
        problems += expect(run(sizes, long), 1, 'src/base/error_report.f90:1: 701 lines',
                           'sizes: a 701-line file fails')
    for p in problems:
        print('FAIL', p)
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
