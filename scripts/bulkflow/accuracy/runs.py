"""Run one member of a family with the solver and time it (wall and CPU of all ranks).

The solver is `build/bin/bulkflow` of this checkout unless BULKFLOW_BIN names another (the same
rule and the same Open MPI environment as bulkflow.arching.runner, whose public helpers are used).
"""
from __future__ import annotations

import hashlib
import importlib.util
import json
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

from ..arching.runner import run_measured, solver_path

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
    output goes to workdir/name.log as it runs, with its progress lines (step, time, ETA every
    2 s: `tail -f` that log to follow a long member); a failure raises RuntimeError with its last
    lines."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / f"{name}.inp"
    inp.write_text(text)
    base = workdir / name
    cmd = [str(solver_path(solver)), str(inp), "--output", str(base)]
    if ranks > 1:
        cmd = [shutil.which("mpirun") or "mpirun", "-np", str(ranks)] + cmd
    log = workdir / f"{name}.log"
    status, output, wall, cpu = run_logged(cmd, log)
    if status != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed with status {status}:\n{output[-2000:]}")
    m = _DONE.search(output)
    return Timing(wall, cpu, int(m.group(1)) if m else 0, base)


def run_logged(cmd: list[str], log: Path) -> tuple[int, str, float, float]:
    """Run a solver command line (runner.run_measured), its stdout and stderr written to `log` while
    it runs: exit status, the log's text, wall time and CPU time [s]."""
    with open(log, "w") as handle:
        proc, wall, cpu = run_measured(cmd, stdout=handle, stderr=subprocess.STDOUT)
    return proc.returncode, log.read_text(errors="replace"), wall, cpu


_SOLVER_DIGESTS: dict[tuple, str] = {}


def solver_digest(solver: str | None = None) -> str:
    """sha256 of the solver binary's bytes (kept per path, size and mtime: hashed once a family)."""
    path = solver_path(solver)
    st = path.stat()
    key = (str(path.resolve()), st.st_size, st.st_mtime_ns)
    if key not in _SOLVER_DIGESTS:
        _SOLVER_DIGESTS[key] = hashlib.sha256(path.read_bytes()).hexdigest()
    return _SOLVER_DIGESTS[key]


def deck_key(text: str, ranks: int, solver: str | None = None) -> str:
    """What a finished run's results depend on: the deck's text, the rank count and the solver's
    bytes (12 hex digits of their sha256)."""
    h = hashlib.sha256(text.encode())
    h.update(f"\0ranks={ranks}\0".encode())
    h.update(solver_digest(solver).encode())
    return h.hexdigest()[:12]


def reuse_name(stem: str, text: str, ranks: int = 1, solver: str | None = None) -> str:
    """The name a reusable run of this deck goes under: STEM-KEY (KEY = deck_key)."""
    return f"{stem}-{deck_key(text, ranks, solver)}"


def run_deck_reusing(text: str, workdir: Path, name: str, ranks: int = 1,
                     solver: str | None = None) -> tuple[Timing, bool]:
    """run_deck under the name NAME-KEY (KEY = deck_key), unless a run of the same deck, rank
    count and solver binary finished there before: then its outputs and its measured wall and
    CPU times are returned without running (True: reused). A run is finished when its
    NAME-KEY.done.json exists, written only after the solver exited with status 0, so an
    interrupted family is continued by the same command and a changed member, rank count or
    binary is run again."""
    workdir = Path(workdir)
    key = deck_key(text, ranks, solver)
    name = reuse_name(name, text, ranks, solver)
    stamp = workdir / f"{name}.done.json"
    if stamp.exists():
        done = json.loads(stamp.read_text())
        if done.get("key") == key and Path(f"{workdir / name}_history.csv").exists():
            return Timing(done["wall"], done["cpu"], done["increments"], workdir / name), True
    timing = run_deck(text, workdir, name, ranks=ranks, solver=solver)
    stamp.write_text(json.dumps({"key": key, "ranks": ranks, "solver_sha256": solver_digest(solver),
                                 "wall": timing.wall, "cpu": timing.cpu, "increments": timing.increments}))
    return timing, False


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
