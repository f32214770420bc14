"""Run one arching scene with the solver (mpirun) and decide flow/no-flow from its history.

    from bulkflow.arching.runner import run_scene
    rec = run_scene(scene, "out/cow", np=2)     # -> RunRecord(outcome, flows, decision, wall, ...)

The solver is `build/bin/bulkflow` of this checkout unless BULKFLOW_BIN (or `solver=`) names
another. Open MPI's root/oversubscribe permissions are set in the child's environment. The
decision is `bulkflow.arching.decision.decide` on the history CSV; the solver's own
machine-readable stop line (stdout) is kept only as a cross-check in the record.

A run that an element distortion ends after the plate opened (the solver's "element N ... tangled /
inverted / collapsed" error, exit status 2) is decided from the rows it wrote, as UNDECIDED unless
FLOW or ARREST was already reached (README "Distortion after the opening"); any other solver
failure, and a distortion before the opening, raises.
"""
from __future__ import annotations

import os
import re
import resource
import shutil
import subprocess
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from .decision import FLOW, UNDECIDED, decide, read_stop_params
from .scene import ArchingScene

REPO = Path(__file__).resolve().parents[3]


def solver_path(solver: str | None = None) -> Path:
    p = Path(solver or os.environ.get("BULKFLOW_BIN", REPO / "build" / "bin" / "bulkflow"))
    if not p.exists():
        raise FileNotFoundError(f"{p}: no solver binary; build it with `bash scripts/build.sh release` "
                                f"or set BULKFLOW_BIN")
    return p


def mpi_environment() -> dict:
    env = dict(os.environ)
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
    return env


@dataclass
class RunRecord:
    outlet_width: float
    n_arc: int
    n_elements: int
    outcome: str
    flows: bool                       #: FLOW or UNDECIDED (the material is not at rest)
    wall: float                       #: wall-clock seconds of the solver run
    increments: int
    cpu: float = 0.0                  #: CPU seconds of the run, all ranks (the machine may be shared)
    element_steps: int = 0            #: increments × elements: the work, independent of the load
    decision: dict = field(default_factory=dict)
    solver_line: str = ""
    base: str = ""
    ended_by: str = ""                #: the solver's distortion error that ended the run, if one did


    def as_dict(self) -> dict:
        return asdict(self)


_DONE = re.compile(r"bulkflow: done, (\d+) increments")
_DISTORTION = re.compile(r"element (\d+) at total time\s+([-+.\dEe]+): element (tangled|inverted|collapsed)")


def distortion_end(stderr: str, history: Path, step: int) -> str:
    """The solver's element-distortion error as one short phrase, if it ended the run in `step`
    (the history's last row is in that step); "" otherwise."""
    m = _DISTORTION.search(stderr)
    row = _last_row(history) if m else []
    # columns time, step, ...: the row must be whole and in the opening step
    if not row or int(float(row[1])) != step:
        return ""
    return f"element {m.group(1)} {m.group(3)} at total time {float(m.group(2)):.4f} s"


def _last_row(history: Path) -> list[str]:
    """The fields of the history's last row; [] without a row, or when the row is cut short (on
    several ranks an abort can end rank 0 mid-row: then the rows cannot be decided)."""
    lines = [ln for ln in history.read_text().splitlines() if ln.strip()] if history.exists() else []
    if len(lines) < 2 or len(lines[-1].split(",")) != len(lines[0].split(",")):
        return []
    return lines[-1].split(",")


def run_measured(cmd: list[str], **kwargs) -> tuple[subprocess.CompletedProcess, float, float]:
    """subprocess.run(cmd, **kwargs) with the MPI environment: the finished process, its wall time
    and the CPU time (user + system) of the children it started [s]."""
    t0 = time.perf_counter()
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run(cmd, env=mpi_environment(), **kwargs)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return proc, wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def run_timed(cmd: list[str], log: Path) -> tuple[subprocess.CompletedProcess, float, float]:
    """run_measured with stdout and stderr kept apart (the caller reads both) and written to `log`
    when the run ends."""
    proc, wall, cpu = run_measured(cmd, capture_output=True, text=True)
    log.write_text(proc.stdout + proc.stderr)
    return proc, wall, cpu


def run_scene(scene: ArchingScene, workdir, np: int = 2, solver: str | None = None, name: str | None = None,
              keep: bool = True, log=None) -> RunRecord:
    """Write the scene, run it on `np` ranks, decide. Raises RuntimeError if the solver fails."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    name = name or f"arch_B{scene.outlet_width * 1000:.2f}mm_n{scene.n_arc}"
    inp = scene.write(workdir / f"{name}.inp")
    base = workdir / name
    exe = str(solver_path(solver))
    cmd = [exe, str(inp), "--output", str(base), "--quiet"]
    if np > 1:
        mpirun = shutil.which("mpirun") or "mpirun"
        cmd = [mpirun, "-np", str(np)] + cmd
    proc, wall, cpu = run_timed(cmd, workdir / f"{name}.log")
    params = read_stop_params(inp)
    ended_by = ""
    if proc.returncode != 0:
        ended_by = distortion_end(proc.stderr, Path(f"{base}_history.csv"), params.step)
        if not ended_by:
            raise RuntimeError(f"{' '.join(cmd)} failed with status {proc.returncode}:\n{proc.stderr[-2000:]}")
    d = decide(f"{base}_history.csv", params, ended_by)
    line = next((ln for ln in proc.stdout.splitlines() if "stop condition: result=" in ln), "")
    m = _DONE.search(proc.stdout)
    last = [] if m else _last_row(Path(f"{base}_history.csv"))    # a run ended early: its last row's increment
    rec = RunRecord(outlet_width=scene.outlet_width, n_arc=scene.n_arc, n_elements=scene.n_elements(),
                    outcome=d.outcome, flows=d.outcome in (FLOW, UNDECIDED), wall=wall,
                    increments=int(m.group(1)) if m else int(float((last or ["0"] * 4)[3])),
                    decision=d.as_dict(), solver_line=line,
                    base=str(base), cpu=cpu, ended_by=ended_by)
    rec.element_steps = rec.increments * rec.n_elements
    if not keep:
        for suffix in (".h5", ".xmf"):
            p = Path(f"{base}{suffix}")
            if p.exists():
                p.unlink()
    if log:
        log(f"  B = {scene.outlet_width * 100:7.3f} cm  n_arc {scene.n_arc:3d} ({rec.n_elements} el): "
            f"{d.summary()}  [{wall:.1f} s wall, {cpu:.1f} s cpu, {rec.increments} inc]")
    return rec
