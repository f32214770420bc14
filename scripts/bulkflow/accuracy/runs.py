"""Run one member of a family with the solver and time it (wall and CPU of all ranks).

The solver is `build/bin/bulkflow` of this checkout unless BULKFLOW_BIN names another (the same
rule and the same Open MPI environment as bulkflow.arching.runner, whose public helpers are used).
"""
from __future__ import annotations

import importlib.util
import re
import shutil
from dataclasses import dataclass
from pathlib import Path

from ..arching.runner import run_timed, solver_path

REPO = Path(__file__).resolve().parents[3]
_DONE = re.compile(r"bulkflow: done, (\d+) increments")


@dataclass
class Timing:
    wall: float          #: seconds, solver launch to exit
    cpu: float           #: user + system seconds of all ranks
    increments: int
    base: Path           #: output base (BASE_history.csv, BASE.h5)


def run_deck(text: str, workdir: Path, name: str, ranks: int = 1, solver: str | None = None) -> Timing:
    """Write `text` to workdir/name.inp, run it on `ranks` ranks, return the timing. The solver's
    output goes to workdir/name.log; a failure raises RuntimeError with its last lines."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / f"{name}.inp"
    inp.write_text(text)
    base = workdir / name
    cmd = [str(solver_path(solver)), str(inp), "--output", str(base), "--quiet"]
    if ranks > 1:
        cmd = [shutil.which("mpirun") or "mpirun", "-np", str(ranks)] + cmd
    proc, wall, cpu = run_timed(cmd, workdir / f"{name}.log")
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed with status {proc.returncode}:\n"
                           f"{(proc.stdout + proc.stderr)[-2000:]}")
    m = _DONE.search(proc.stdout)
    return Timing(wall, cpu, int(m.group(1)) if m else 0, base)


def particles_from_log(base) -> int:
    """Number of particles an MPM run printed (BASE.log written by run_deck), 0 if none."""
    m = re.search(r"(\d+) particles,", Path(f"{base}.log").read_text())
    return int(m.group(1)) if m else 0


_VERIFICATION = None


def verification_scenes():
    """scripts/make_verification_scenes.py as a module: its Scene class, meshes and generators
    (the families reuse them so that a family's finest scenes are the verification scenes' kind)."""
    global _VERIFICATION
    if _VERIFICATION is None:
        path = REPO / "scripts" / "make_verification_scenes.py"
        spec = importlib.util.spec_from_file_location("bulkflow_verification_scenes", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        _VERIFICATION = module
    return _VERIFICATION
