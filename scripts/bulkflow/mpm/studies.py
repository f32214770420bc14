"""MPM hopper studies: grid convergence with its accuracy-vs-cost table (study a / item 6), and
the discharge rate and flow mode against outlet width and hopper angle (studies e, f).

    bulkflow-mpm-study convergence --cells 0.1 0.07 0.05 [--discharge 1.5] [--out out/mpm_study]
                                   [--bulkflow build/bin/bulkflow] [--shape GIMP|LINEAR]
    bulkflow-mpm-study sweep --outlets 0.15 0.25 0.35 --thetas 15 30 45 [--cell 0.05] ...

sweep: every (theta, b) pair with the other at its Table 4.2 value (30 deg, 0.25 m); prints the
full-hopper MDR, the Beverloo-type coefficient C = MDR / (rho_b sqrt(g) b^1.5) with rho_b the
outlet bulk density, and the MFI with the flow mode (mass flow if MFI > 0.3).

For each cell size the thesis ch. 4 wedge hopper (with inflow) is written, run (1 s fill +
`--discharge` s), and reduced with discharge.py / paths.py: steady MDR (regression of the
discharged mass from 0.5 s after opening to the end), mean outlet velocity and density, MFI, wall time and particle-steps. The table
gives each figure's relative difference from the finest run (the reference), against wall time.
"""
import argparse
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from .discharge import mass_flow_index, mean_discharge_rate
from .hopper_scene import hopper_scene
from .paths import frames, outlet_path


def run_case(exe, out, cell, discharge, shape, theta=30.0, outlet=0.25):
    out.mkdir(parents=True, exist_ok=True)
    base = out / f"hopper_cell{cell:g}_{shape.lower()}_theta{theta:g}_b{outlet:g}"
    scene = base.with_suffix(".inp")
    scene.write_text(hopper_scene(cell=cell, discharge_time=discharge, shape=shape, field_frames=5,
                                  history_dt=0.01, theta=theta, outlet=outlet))
    t0 = time.perf_counter()
    r = subprocess.run([exe, str(scene), "--output", str(base), "--quiet"], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.stderr.write(r.stdout + r.stderr)
        raise SystemExit(f"run failed: {scene}")
    steps = int(re.search(r"throughput (\d+) particle-steps", r.stdout).group(1))
    npart = int(re.search(r"(\d+) particles,", r.stdout).group(1))
    hist = np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)
    mdr = mean_discharge_rate(hist)
    mfi, _, _ = mass_flow_index(str(base) + ".h5", theta, outlet)
    import h5py
    f = h5py.File(str(base) + ".h5", "r")
    op = outlet_path(frames(f, 3), cell, theta, outlet)
    return dict(cell=cell, particles=npart, wall=wall, psteps=steps, mdr=mdr, mfi=mfi,
                v_out=float(np.nanmean(op[:, 1])), rho_out=float(np.nanmean(op[:, 2])))


def convergence(a):
    rows = [run_case(a.bulkflow, Path(a.out), c, a.discharge, a.shape) for c in a.cells]
    ref = min(rows, key=lambda r: r["cell"])
    print(f"wedge hopper (thesis ch. 4), {a.shape}, 1 s fill + {a.discharge:g} s discharge with inflow; "
          f"reference: cell {ref['cell']:g} m")
    print(f"{'cell':>6} {'particles':>9} {'wall s':>8} {'Mpst/s':>7} {'MDR kg/s/m':>11} {'dMDR':>7} "
          f"{'v_out':>7} {'dv':>7} {'rho_out':>8} {'drho':>7} {'MFI':>6}")
    for r in rows:
        def rel(k):
            return r[k] / ref[k] - 1
        print(f"{r['cell']:6.3f} {r['particles']:9d} {r['wall']:8.1f} {r['psteps'] / r['wall'] / 1e6:7.3f} "
              f"{2 * r['mdr']:11.2f} {rel('mdr'):+7.3f} {r['v_out']:7.3f} {rel('v_out'):+7.3f} "
              f"{r['rho_out']:8.1f} {rel('rho_out'):+7.3f} {r['mfi']:6.3f}")
    print("MDR: full hopper (twice the half model), per metre of depth; v_out, rho_out: outlet path means "
          "(last 3 frames); d*: relative to the reference")


def sweep(a):
    cases = [(30.0, b) for b in a.outlets] + [(t, 0.25) for t in a.thetas if t != 30.0]
    print(f"wedge hopper sweep, cell {a.cell:g} m, {a.shape}, 1 s fill + {a.discharge:g} s discharge with inflow")
    print(f"{'theta':>6} {'b m':>6} {'particles':>9} {'wall s':>7} {'MDR kg/s/m':>11} {'rho_out':>8} "
          f"{'C':>6} {'MFI':>6}  mode")
    for theta, b in cases:
        r = run_case(a.bulkflow, Path(a.out), a.cell, a.discharge, a.shape, theta, b)
        c = 2 * r["mdr"] / (r["rho_out"] * 9.81 ** 0.5 * b ** 1.5)
        print(f"{theta:6.1f} {b:6.3f} {r['particles']:9d} {r['wall']:7.1f} {2 * r['mdr']:11.2f} "
              f"{r['rho_out']:8.1f} {c:6.3f} {r['mfi']:6.3f}  {'mass flow' if r['mfi'] > 0.3 else 'funnel flow'}",
              flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("study", choices=["convergence", "sweep"])
    p.add_argument("--outlets", type=float, nargs="+", default=[0.15, 0.25, 0.35])
    p.add_argument("--thetas", type=float, nargs="+", default=[15.0, 30.0, 45.0])
    p.add_argument("--cell", type=float, default=0.05)
    p.add_argument("--cells", type=float, nargs="+", default=[0.1, 0.07, 0.05])
    p.add_argument("--discharge", type=float, default=1.5)
    p.add_argument("--shape", choices=["GIMP", "LINEAR"], default="GIMP")
    p.add_argument("--out", default="out/mpm_study")
    p.add_argument("--bulkflow", default=str(Path(__file__).resolve().parents[3] / "build" / "bin" / "bulkflow"))
    a = p.parse_args(argv)
    if a.study == "convergence":
        convergence(a)
    else:
        sweep(a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
