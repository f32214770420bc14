#!/usr/bin/env python3
"""MPM throughput benchmark (a script that prints figures; not a test).

    .venv/bin/python scripts/bench_mpm.py [--bulkflow build/bin/bulkflow] [--increments 3000]
                                         [--discharge SECONDS --cell H]

1. particle-steps per second per core on 1 rank, for the ch. 4 wedge hopper (cell 0.05 m, 2x2
   PPC, uGIMP and linear shape functions), FILL step only, --stop-after N increments;
   the solver's own counter (Σ particles over increments / wall time of the time loop).
2. the same on 2 ranks (mpirun -np 2; particle decomposition with a replicated grid): particle-
   steps/s in all and per rank. On a machine shared with other jobs the two ranks wait for each
   other at every grid sum (two per increment), so this figure depends on the machine's load.
3. with --discharge S: the wall time of the whole ch. 4 hopper run (1 s fill + S s discharge with
   inflow) at cell --cell (default 0.125/4.5 = 0.0278 m: the outlet half-width 4.5 cells with its
   edge mid-cell, within 0.6 % of 5.5 cells in the outlet centre velocity and 2.3 % in the MDR;
   bulkflow-mpm-study convergence, src/mpm/README.md), on --np ranks, the wall time per simulated
   second and the MDR.
Needs the release build (scripts/build.sh release).
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

root = Path(__file__).resolve().parent
sys.path.insert(0, str(root))
from bulkflow.mpm.hopper_scene import hopper_scene  # noqa: E402


def run(cmd, env=None):
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    return r, time.perf_counter() - t0


def throughput(out):
    m = re.search(r"throughput (\d+) particle-steps,\s+([0-9.E+-]+) per second \(time loop\s+([0-9.]+) s", out)
    return (int(m.group(1)), float(m.group(2)), float(m.group(3))) if m else None


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bulkflow", default=str(root.parent / "build" / "bin" / "bulkflow"))
    p.add_argument("--increments", type=int, default=3000)
    p.add_argument("--discharge", type=float, default=0.0)
    # the converged resolution of study a (src/mpm/README.md): outlet half-width 4.5 cells, edge mid-cell
    p.add_argument("--cell", type=float, default=0.125 / 4.5)
    p.add_argument("--np", type=int, default=1, help="ranks for the --discharge run")
    p.add_argument("--skip-throughput", action="store_true", help="only the --discharge run")
    a = p.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_mpm_"))
    print(f"bulkflow MPM benchmark ({a.bulkflow}); scratch {tmp}")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    for shape in () if a.skip_throughput else ("GIMP", "LINEAR"):
        scene = tmp / f"hopper_{shape.lower()}.inp"
        scene.write_text(hopper_scene(cell=0.05, shape=shape, field_frames=1, history_dt=0.1))
        r, wall = run([a.bulkflow, str(scene), "--output", str(tmp / scene.stem), "--quiet",
                       "--stop-after", str(a.increments)])
        t = throughput(r.stdout)
        if r.returncode != 0 or t is None:
            print(r.stdout, r.stderr)
            sys.exit(1)
        npart = re.search(r"(\d+) particles,", r.stdout).group(1)
        print(f"  1 rank, {shape:6s}: {npart} particles, {a.increments} increments: "
              f"{t[1]:.3e} particle-steps/s per core (time loop {t[2]:.2f} s, process {wall:.2f} s)")
        timing = r.stdout.split("timing (wall seconds):")[-1]
        print("    " + "\n    ".join(l for l in timing.splitlines() if l.strip()))
    if not a.skip_throughput:
        # 2 ranks
        r, wall = run(["mpirun", "-np", "2", a.bulkflow, str(tmp / "hopper_gimp.inp"), "--output",
                       str(tmp / "np2"), "--quiet", "--stop-after", str(a.increments)], env=env)
        t = throughput(r.stdout)
        if r.returncode != 0 or t is None:
            print(r.stdout, r.stderr)
            sys.exit(1)
        print(f"  2 ranks, GIMP  : {t[1]:.3e} particle-steps/s in all, {t[1] / 2:.3e} per rank "
              f"(time loop {t[2]:.2f} s, process {wall:.2f} s)")
        print(f"    load average at the end: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    if a.discharge > 0:
        scene = tmp / "hopper_discharge.inp"
        scene.write_text(hopper_scene(cell=a.cell, discharge_time=a.discharge, field_frames=5, history_dt=0.01))
        # not --quiet: the solver's "step 1/2 ... done ... wall X s" line splits the fill from the discharge
        cmd = [a.bulkflow, str(scene), "--output", str(tmp / "hopper_discharge")]
        if a.np > 1:
            cmd = ["mpirun", "-np", str(a.np)] + cmd
        r, wall = run(cmd, env=env)
        t = throughput(r.stdout)
        if r.returncode != 0 or t is None:
            print(r.stdout, r.stderr)
            sys.exit(1)
        npart = re.search(r"(\d+) particles,", r.stdout).group(1)
        print(f"  ch. 4 hopper, {a.np} rank(s), cell {a.cell:g} m ({npart} particles), 1 s fill + {a.discharge:g} s discharge "
              f"with inflow: wall time {wall:.1f} s ({wall / (1 + a.discharge):.1f} s per simulated second), "
              f"{t[1]:.3e} particle-steps/s")
        done = [float(x) for x in re.findall(r"^\s+step 1/\d+ .* done .* wall\s+([0-9.]+) s", r.stdout, re.M)]
        fill = done[0] if done else float("nan")
        discharge = t[2] - fill
        print(f"    of it: fill step {fill:.1f} s, discharge step {discharge:.1f} s (time loop {t[2]:.1f} s; "
              f"set-up and output close {wall - t[2]:.1f} s)")
        print(f"    target: under 600 s for 5 s of discharge at the converged cell: the discharge step "
              f"{'meets' if discharge < 600 else 'does NOT meet'} it ({discharge:.0f} s for {a.discharge:g} s); "
              f"fill + discharge {'also meets' if wall < 600 else 'does not'} ({wall:.0f} s); "
              f"load average at the end {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
        import numpy as np
        from bulkflow.mpm.discharge import mean_discharge_rate
        hist = np.genfromtxt(str(tmp / "hopper_discharge_history.csv"), delimiter=",", names=True)
        print(f"    steady MDR (full hopper, from 0.5 s after opening): {2 * mean_discharge_rate(hist):.1f} kg/s/m; "
              f"history: {tmp / 'hopper_discharge_history.csv'}")


if __name__ == "__main__":
    main()
