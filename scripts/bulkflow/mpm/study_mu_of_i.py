"""Ch. 4 wedge hopper discharge rate against the cell size, static MC vs MC with mu(I).

    PYTHONPATH=scripts .venv/bin/python -m bulkflow.mpm.study_mu_of_i [--edge-cells 1.5 2.5]
        [--discharge 1.5] [--bulkflow build/bin/bulkflow] [--out out/mu_of_i_study]

For each cell h = 0.125 m / edge_cells (the outlet half-width in cells, edge mid-cell as in
bulkflow-mpm-study convergence) the hopper of hopper_scene (thesis Table 4.2: phi 20, psi 15 -> 0)
is written twice, as it is and with the mu(I) block appended to the MC constants
(docs/mu_of_i.md: phi2 = 37.1 deg, i.e. mu2 = sin 20 + 0.262, I0 = 0.279, d = 0.5 mm,
rho_s = 2500), run one at a time (nice), and the mean discharge rate (regression of MASS_OUT from
0.5 s after opening, bulkflow.mpm.discharge.mean_discharge_rate) is printed per run with its
wall time, as one table.
"""
import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from bulkflow.mpm.discharge import mean_discharge_rate
from bulkflow.mpm.hopper_scene import hopper_scene, with_mu_of_i

MU_OF_I_BLOCK = "1., 37.1, 0.279, 0.5e-3, 2500."


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--edge-cells", type=float, nargs="+", default=[1.5, 2.5])
    p.add_argument("--discharge", type=float, default=1.5, help="discharge time [s]")
    p.add_argument("--bulkflow", default="build/bin/bulkflow")
    p.add_argument("--out", default="out/mu_of_i_study")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for k in a.edge_cells:
        cell = 0.125 / k
        base = hopper_scene(cell=cell, discharge_time=a.discharge, field_frames=2)
        for label, text in (("static", base), ("mu(I)", with_mu_of_i(base, MU_OF_I_BLOCK))):
            name = f"hopper_h{cell:.4f}_{'mui' if label != 'static' else 'mc'}"
            deck = out / f"{name}.inp"
            deck.write_text(text)
            t0 = time.perf_counter()
            r = subprocess.run(["nice", a.bulkflow, str(deck), "--output", str(out / name)],
                               capture_output=True, text=True)
            wall = time.perf_counter() - t0
            if r.returncode != 0:
                sys.exit(f"{deck}: exit {r.returncode}\n{r.stderr}")
            hist = np.genfromtxt(out / f"{name}_history.csv", delimiter=",", names=True)
            mdr = mean_discharge_rate(hist)
            tp = re.search(r"throughput (\d+) particle-steps,\s+([0-9.E+-]+) per second", r.stdout)
            rate = float(tp.group(2)) if tp else float("nan")
            rows.append((cell, label, mdr, wall))
            print(f"h = {cell:.4f} m ({k:g} cells per b/2) {label:6s}: MDR {mdr:8.2f} kg/s/m  ({wall:.0f} s wall, "
                  f"{rate:.3e} particle-steps/s)", flush=True)
    print("\nh [m]    static MDR   mu(I) MDR   ratio   (kg/s per m of depth, of the half model)")
    for cell in sorted({r[0] for r in rows}, reverse=True):
        s = next(r[2] for r in rows if r[0] == cell and r[1] == "static")
        m = next(r[2] for r in rows if r[0] == cell and r[1] == "mu(I)")
        print(f"{cell:.4f}  {s:10.2f}  {m:10.2f}  {m / s:6.3f}")


if __name__ == "__main__":
    main()
