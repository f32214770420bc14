"""Helpers of the scene checks: run bulkflow, read its outputs and a scene's `** verify:` lines.

numpy and h5py only. Used by check_scene.py (the CTest entry point).
"""
from __future__ import annotations

import csv
import os
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np


class CheckFailed(Exception):
    """A figure outside its tolerance (the message says which and by how much)."""


@dataclass
class Run:
    """One solver run: where its outputs are and what it printed."""
    base: Path
    returncode: int
    stdout: str
    stderr: str
    command: list[str] = field(default_factory=list)

    @property
    def h5(self) -> Path:
        return self.base.with_suffix('.h5')

    @property
    def history_csv(self) -> Path:
        return Path(str(self.base) + '_history.csv')


@dataclass
class Launcher:
    """How to start the solver: the binary, and mpiexec with its flags for more than one rank."""
    bulkflow: str
    mpiexec: str | None = None
    mpiexec_flags: list[str] = field(default_factory=list)
    numproc_flag: str = '-n'

    def command(self, ranks: int) -> list[str]:
        if ranks == 1:
            return [self.bulkflow]
        if not self.mpiexec:
            raise CheckFailed(f'{ranks} ranks asked for but no mpiexec given')
        return [self.mpiexec, self.numproc_flag, str(ranks), *self.mpiexec_flags, self.bulkflow]

    def run(self, scene: Path, base: Path, ranks: int = 1, extra: list[str] | None = None,
            expect_success: bool = True, timeout: float = 600) -> Run:
        base.parent.mkdir(parents=True, exist_ok=True)
        cmd = self.command(ranks) + [str(scene), '--output', str(base), '--quiet'] + (extra or [])
        env = dict(os.environ)
        env.setdefault('OMPI_ALLOW_RUN_AS_ROOT', '1')
        env.setdefault('OMPI_ALLOW_RUN_AS_ROOT_CONFIRM', '1')
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env,
                              cwd=base.parent)
        run = Run(base, proc.returncode, proc.stdout, proc.stderr, cmd)
        if expect_success and proc.returncode != 0:
            sys.stdout.write(proc.stdout)
            sys.stderr.write(proc.stderr)
            raise CheckFailed(f'bulkflow failed (exit status {proc.returncode}): {" ".join(cmd)}')
        return run


# ---------------------------------------------------------------------------------------------
# Scene parameters

def run_deck(bulkflow: str, deck: Path, base: Path) -> str:
    """Run a deck to completion (outputs BASE.h5, BASE_history.csv); stop the check if it fails."""
    p = subprocess.run([bulkflow, str(deck), '--output', str(base)], capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        raise SystemExit(f'FAIL: {deck.name} exited {p.returncode}:\n{p.stdout}\n{p.stderr}')
    return p.stdout


def verify_deck(bulkflow: str, deck: Path, workdir: Path) -> bool:
    """check_scene.py verify on a deck written by a test (its '** verify:' lines), output printed."""
    p = subprocess.run([sys.executable, str(Path(__file__).parent / 'check_scene.py'), 'verify', str(deck),
                        '--bulkflow', bulkflow, '--workdir', str(workdir)], capture_output=True, text=True, timeout=300)
    print(p.stdout.rstrip())
    return p.returncode == 0


def scene_parameters(path: Path) -> dict[str, str]:
    """The `** verify: key = value` lines of a scene (written by make_verification_scenes.py)."""
    params = {}
    for line in path.read_text().splitlines():
        m = re.match(r'\*\*\s*verify:\s*(\w+)\s*=\s*(.*)$', line)
        if m:
            params[m.group(1)] = m.group(2).strip()
    return params


def floats(text: str) -> np.ndarray:
    return np.array([float(x) for x in text.split()])


# ---------------------------------------------------------------------------------------------
# Outputs

def read_history(path: Path) -> dict[str, np.ndarray]:
    with open(path, newline='') as f:
        rows = list(csv.reader(f))
    header = rows[0]
    data = np.array([[float(x) for x in r] for r in rows[1:]]) if len(rows) > 1 else np.zeros((0, len(header)))
    return {name: data[:, k] for k, name in enumerate(header)}


@dataclass
class Frame:
    step: int
    step_time: float
    total_time: float
    increment: int
    fields: dict[str, np.ndarray]


@dataclass
class Fields:
    node_id: np.ndarray
    element_id: np.ndarray
    x0: np.ndarray                  # (n_nodes, ndim)
    connectivity: np.ndarray        # (n_elems, nen), 0-based
    ndim: int
    frames: list[Frame]

    def centroids(self, frame: Frame | None = None) -> np.ndarray:
        x = self.x0 if frame is None else self.x0 + frame.fields['U']
        return x[self.connectivity].mean(axis=1)


def read_fields(path: Path) -> Fields:
    with h5py.File(path, 'r') as f:
        mesh = f['mesh']
        ndim = int(mesh.attrs['ndim'])
        frames = []
        for name in sorted(f['frames']):
            g = f['frames'][name]
            frames.append(Frame(int(g.attrs['step']), float(g.attrs['step_time']), float(g.attrs['total_time']),
                                int(g.attrs['increment']), {k: g[k][...] for k in g}))
        return Fields(mesh['node_id'][...], mesh['element_id'][...], mesh['coordinates'][:, :ndim],
                      mesh['connectivity'][...], ndim, frames)


# ---------------------------------------------------------------------------------------------
# Checks shared by every scene

def report(name: str, value: float, limit: float, unit: str = '', fmt: str = '.3g') -> None:
    """Print a figure with its limit; raise when it is outside."""
    ok = np.isfinite(value) and abs(value) <= limit
    print(f'  {"ok  " if ok else "FAIL"} {name}: {value:{fmt}}{unit} (limit {limit:{fmt}}{unit})')
    if not ok:
        raise CheckFailed(f'{name} = {value:{fmt}}{unit} exceeds {limit:{fmt}}{unit}')


def check_energy(history: dict[str, np.ndarray], balance: float = 0.01, artificial: float = 0.05,
                 check_artificial: bool = True) -> dict[str, float]:
    """|ETOTAL| <= balance * max(ALLKE, ALLIE, |ALLWK|) at the end and on every row of the second
    half; ALLAE <= artificial * ALLIE at the end."""
    t = history['time']
    scale = np.maximum.reduce([history['ALLKE'], history['ALLIE'], np.abs(history['ALLWK'])])
    ratio = np.abs(history['ETOTAL']) / np.where(scale > 0, scale, np.inf)
    second = t >= 0.5 * t[-1]
    figures = {'energy_end': float(ratio[-1]), 'energy_second_half': float(ratio[second].max())}
    report('energy balance |ETOTAL|/max(ALLKE, ALLIE, |ALLWK|) at the end', 100 * figures['energy_end'],
           100 * balance, ' %')
    report('energy balance, worst row of the second half', 100 * figures['energy_second_half'],
           100 * balance, ' %')
    if check_artificial:
        figures['hourglass'] = float(history['ALLAE'][-1] / history['ALLIE'][-1]) if history['ALLIE'][-1] > 0 \
            else float(history['ALLAE'][-1] > 0) * np.inf
        report('hourglass energy ALLAE/ALLIE at the end', 100 * figures['hourglass'], 100 * artificial, ' %')
    return figures


def check_no_nan(run: Run) -> None:
    """Every number in the history and in every frame is finite."""
    if run.history_csv.exists():
        h = read_history(run.history_csv)
        for name, values in h.items():
            if not np.all(np.isfinite(values)):
                raise CheckFailed(f'history column {name} holds NaN/Inf')
    if run.h5.exists():
        try:
            fields = read_fields(run.h5)
        except (OSError, KeyError) as exc:        # a file the crash left unreadable is no NaN
            print(f'  note: {run.h5.name} unreadable after the stop ({exc})')
            return
        for fr in fields.frames:
            for name, values in fr.fields.items():
                if not np.all(np.isfinite(values)):
                    raise CheckFailed(f'frame at t = {fr.total_time} field {name} holds NaN/Inf')


def effect_lines(stdout: str) -> tuple[list[str], list[str]]:
    """(active effects of the header line, phase names of the timing table)."""
    effects: list[str] = []
    phases: list[str] = []
    in_table = False
    for line in stdout.splitlines():
        m = re.match(r'\s+effects\s+(.*)$', line)
        if m:
            effects = [e.strip() for e in m.group(1).split(',')]
        if line.startswith('timing'):
            in_table = True
            continue
        if in_table:
            m = re.match(r'\s+(\S.*?)\s{2,}[0-9.]+(\s|$)', line)
            if m and m.group(1) not in ('phase',):
                phases.append(m.group(1).strip())
    return effects, phases


def check_effects(run: Run, present: list[str], absent: list[str]) -> None:
    """The header lists the active effects and the run prints its timing table; effects the
    scene does not have appear in neither."""
    effects, phases = effect_lines(run.stdout)
    if not effects:
        raise CheckFailed('no "effects" line in the run header')
    if not phases or 'total' not in phases:
        raise CheckFailed('no timing table (with a total line) at the end of the run')
    for name in present:
        if name not in effects or name not in phases:
            raise CheckFailed(f'effect "{name}" should be listed and timed: effects {effects}, table {phases}')
    for name in absent:
        if name in effects or name in phases:
            raise CheckFailed(f'effect "{name}" is not in this scene but shows: effects {effects}, table {phases}')
    print(f'  ok   effects: {", ".join(effects)}; timed: {", ".join(p for p in phases if p not in ("other", "total"))}')


def check_no_balance_warning(run: Run) -> None:
    """A healthy scene must not raise the energy-balance warning."""
    for line in (run.stdout + run.stderr).splitlines():
        if 'energy balance' in line and 'warning' in line:
            raise CheckFailed(f'unexpected warning: {line.strip()}')
    print('  ok   no energy-balance warning')


# ---------------------------------------------------------------------------------------------
# Comparisons of runs

def max_relative_difference(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| / max |a| (0 when both are zero)."""
    scale = np.max(np.abs(a))
    diff = np.max(np.abs(a - b)) if a.size else 0.0
    if scale == 0:
        return 0.0 if diff == 0 else np.inf
    return float(diff / scale)
