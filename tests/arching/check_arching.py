#!/usr/bin/env python3
"""Arching scene tests (issue 4): the generator's scene runs, and the flow/no-flow decision is right.

    check_arching.py decide  --bulkflow BIN --workdir DIR
    check_arching.py mpi     --bulkflow BIN --workdir DIR --mpiexec MPIEXEC [--mpiexec-flag F] --ranks 1 3
    check_arching.py restart --bulkflow BIN --workdir DIR --stop-after N [--ranks R --mpiexec ...]

Scenes: Case B (thesis Table 6.1, fc0 = 2285 Pa) at H = 1 m above the apex on a coarse mesh
(6 elements along the outlet, ~150 elements): B = 0.10 m arches (Enstad's width at 1 m is 0.31 m),
B = 0.60 m flows (McLean's is 0.67 m but Enstad's 0.31 m; at 0.6 m the material falls at once).

decide:  both scenes on one rank: the history decision (bulkflow.arching.decision) and the solver's
         stop line agree and give ARREST / FLOW; the run ended early (stop condition); the mass
         scaling line is printed for steps 1 and 3; the energy balance holds across the mass change.
mpi:     the arching scene on each rank count: the same stop increment and outcome, identical
         UMAX history column and final displacements (bitwise).
restart: the arching scene stopped with --stop-after N (in the mass-scaled step 1, and inside the
         opening step) and continued with --restart gives the same history (every column), decision
         and final displacements.
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
from bulkflow.arching.decision import ARREST, FLOW, decide, read_stop_params  # noqa: E402
from bulkflow.arching.scene import scene_from_case  # noqa: E402
from bulkflow.post.run_output import read_history  # noqa: E402


class CheckFailed(Exception):
    pass


def small_scene(width: float, **kw):
    d = dict(height=1.0, n_arc=6, t_gravity=0.3, t_slide=0.15, t_open=0.6, field_frames=1)
    d.update(kw)
    return scene_from_case("B", "c0", outlet_width=width, **d)


def command(a, ranks: int) -> list[str]:
    if ranks == 1:
        return [a.bulkflow]
    if not a.mpiexec:
        raise CheckFailed(f"{ranks} ranks asked for but no --mpiexec")
    return [a.mpiexec, a.numproc_flag, str(ranks), *a.mpiexec_flag, a.bulkflow]


def run(a, scene_path: Path, base: Path, ranks: int = 1, extra: list[str] | None = None) -> str:
    env = dict(os.environ)
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    cmd = command(a, ranks) + [str(scene_path), "--output", str(base), "--quiet"] + (extra or [])
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    if p.returncode != 0:
        sys.stdout.write(p.stdout + p.stderr)
        raise CheckFailed(f"bulkflow failed with status {p.returncode}: {' '.join(cmd)}")
    if "NaN" in p.stdout + p.stderr:
        raise CheckFailed("NaN in the solver's output")
    return p.stdout


def solver_result(stdout: str) -> dict:
    m = re.search(r"stop condition: result=(\w+) step=(\d+) step_time=\s*(\S+)", stdout)
    if not m:
        raise CheckFailed("no machine-readable stop condition line in the solver output")
    return dict(result=m.group(1), step=int(m.group(2)), step_time=float(m.group(3)))


def final_u(base: Path) -> np.ndarray:
    import h5py
    with h5py.File(f"{base}.h5", "r") as f:
        last = sorted(f["frames"].keys())[-1]
        return f["frames"][last]["U"][:]


def check_decide(a) -> None:
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    for width, expected in ((0.10, ARREST), (0.60, FLOW)):
        s = small_scene(width)
        inp = s.write(work / f"arch_{int(width * 100)}cm.inp")
        base = work / f"arch_{int(width * 100)}cm"
        out = run(a, inp, base)
        params = read_stop_params(inp)
        d = decide(f"{base}_history.csv", params)
        solver = solver_result(out)
        print(f"  B = {width:.2f} m: history says {d.summary()}")
        print(f"             solver says {solver['result']} at step time {solver['step_time']:.4g} s")
        if d.outcome != expected or solver["result"] != expected:
            raise CheckFailed(f"B = {width} m: expected {expected}, history {d.outcome}, solver {solver['result']}")
        if not d.stopped_early:
            raise CheckFailed(f"B = {width} m: the stop condition did not end the opening step early")
        if out.count("mass scaling  step") != 2:
            raise CheckFailed("expected one mass-scaling line for step 1 (scaled) and one for step 3 (restored)")
        h = read_history(f"{base}_history.csv")
        peak = max(np.max(h["ALLIE"]), np.max(h["ALLKE"]), np.max(np.abs(h["ALLWK"])))
        worst = float(np.max(np.abs(h["ETOTAL"]))) / peak
        print(f"             energy balance |ETOTAL| <= {worst:.2e} of the largest energy")
        if worst > 0.01:
            raise CheckFailed(f"energy balance off by {worst:.3g} of the largest energy")


def check_mpi(a) -> None:
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    inp = small_scene(0.10).write(work / "arch_mpi.inp")
    ref = None
    for r in a.ranks:
        base = work / f"arch_np{r}"
        out = run(a, inp, base, ranks=r)
        res = solver_result(out)
        h = read_history(f"{base}_history.csv")
        got = (res, h["UMAX_ALLN"], h["increment"], final_u(base))
        print(f"  {r} rank(s): {res['result']} at step time {res['step_time']:.6g}, {int(h['increment'][-1])} increments")
        if ref is None:
            ref = got
            continue
        if got[0] != ref[0] or not np.array_equal(got[2], ref[2]):
            raise CheckFailed(f"{r} ranks: decision or increments differ from 1 rank")
        if not np.array_equal(got[1], ref[1]) or not np.array_equal(got[3], ref[3]):
            raise CheckFailed(f"{r} ranks: UMAX history or final U not bitwise equal to 1 rank")
    print("  decision, UMAX history and final U bitwise identical on all rank counts")


def check_restart(a) -> None:
    """Each --stop-after N: interrupted there and continued with --restart, the run must end as the
    uninterrupted one (a stop in step 1 carries the scaled masses, one in step 3 the decision state)."""
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    inp = small_scene(0.10).write(work / "arch_restart.inp")
    r = a.ranks[0]
    full = work / "full"
    out_full = run(a, inp, full, ranks=r)
    hf = read_history(f"{full}_history.csv")
    for n in a.stop_after:
        part = work / f"part_{n}"
        run(a, inp, part, ranks=r, extra=["--stop-after", str(n)])
        step = int(read_history(f"{part}_history.csv")["step"][-1])
        out_part = run(a, inp, part, ranks=r, extra=["--restart"])
        if solver_result(out_full) != solver_result(out_part):
            raise CheckFailed(f"stop after {n}: the restarted run decided differently")
        hp = read_history(f"{part}_history.csv")
        for k in hf:
            if not np.array_equal(hf[k], hp[k]):
                raise CheckFailed(f"stop after {n}: history column {k} differs after the restart")
        if not np.array_equal(final_u(full), final_u(part)):
            raise CheckFailed(f"stop after {n}: final U differs after the restart")
        print(f"  stopped at increment {n} (step {step}), restarted: history and final U identical, "
              f"{solver_result(out_part)['result']}")


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=["decide", "mpi", "restart"])
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True)
    p.add_argument("--mpiexec")
    p.add_argument("--mpiexec-flag", action="append", default=[])
    p.add_argument("--numproc-flag", default="-n")
    p.add_argument("--ranks", type=int, nargs="+", default=[1])
    p.add_argument("--stop-after", type=int, nargs="+", default=[0])
    a = p.parse_args()
    try:
        {"decide": check_decide, "mpi": check_mpi, "restart": check_restart}[a.mode](a)
    except CheckFailed as e:
        print(f"FAILED: {e}")
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
