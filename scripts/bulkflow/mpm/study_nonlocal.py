"""Ch. 4 wedge hopper discharge rate against the cell size, local vs nonlocal (*NONLOCAL).

    PYTHONPATH=scripts .venv/bin/python -m bulkflow.mpm.study_nonlocal [--edge-cells 1.5 2.5 3.5]
        [--length 0.1] [--discharge 1.5] [--bulkflow build/bin/bulkflow] [--out out/nonlocal_study]

The hopper of hopper_scene at h = 0.125 m / edge_cells, as docs/mu_of_i.md runs it (same
generator, same MDR: bulkflow.mpm.discharge.mean_discharge_rate), written twice: as it is
and with `*NONLOCAL, LENGTH=l` (the VUSDFLD's volumetric strain FV1, which drives psi,
averaged over the particles within l; docs/nonlocal.md). Runs one at a time (nice), then prints
the table, the change between the two finest cells and, for a monotone sequence of three cells,
Richardson's extrapolation with Roache's grid convergence index (safety factor 1.25).
"""
import argparse
import math
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from bulkflow.mpm.discharge import mean_discharge_rate
from bulkflow.mpm.hopper_scene import hopper_scene


def with_nonlocal(text, length):
    """The scene with *NONLOCAL in its model data (before the first *STEP)."""
    i = text.find("*STEP")
    if i < 0:
        sys.exit("no *STEP in the scene")
    return text[:i] + f"*NONLOCAL, LENGTH={length!r}, VARIABLE=FV1\n" + text[i:]


def observed_order(h, f):
    """Observed order p of three solutions f at cells h (coarse to fine, any ratios), by the
    fixed-point iteration of Celik et al. (2008, J. Fluids Eng. 130:078001); None if the
    differences change sign (oscillatory: no extrapolation)."""
    e21, e32 = f[2] - f[1], f[1] - f[0]
    if e21 == 0 or e32 == 0 or e21 * e32 < 0:
        return None
    r21, r32 = h[1] / h[2], h[0] / h[1]
    p = 1.0
    for _ in range(200):
        q = math.log((r21 ** p - 1) / (r32 ** p - 1))
        p_new = abs(math.log(abs(e32 / e21)) + q) / math.log(r21)
        if abs(p_new - p) < 1e-12:
            break
        p = p_new
    return p


def richardson(h, f):
    """(extrapolated value, GCI of the finest as a fraction, order) or None."""
    p = observed_order(h, f)
    if p is None:
        return None
    r21 = h[1] / h[2]
    ext = (r21 ** p * f[2] - f[1]) / (r21 ** p - 1)
    gci = 1.25 * abs((f[2] - f[1]) / f[2]) / (r21 ** p - 1)
    return ext, gci, p


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--edge-cells", type=float, nargs="+", default=[1.5, 2.5, 3.5])
    p.add_argument("--length", type=float, default=0.1, help="*NONLOCAL LENGTH [m]")
    p.add_argument("--discharge", type=float, default=1.5, help="discharge time [s]")
    p.add_argument("--variants", nargs="+", default=["local", "nonlocal"], choices=["local", "nonlocal"])
    p.add_argument("--bulkflow", default="build/bin/bulkflow")
    p.add_argument("--out", default="out/nonlocal_study")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = {}
    for k in a.edge_cells:
        cell = 0.125 / k
        base = hopper_scene(cell=cell, discharge_time=a.discharge, field_frames=2)
        for label in a.variants:
            text = base if label == "local" else with_nonlocal(base, a.length)
            name = f"hopper_h{cell:.4f}_{label}" + ("" if label == "local" else f"_l{a.length:g}")
            deck = out / f"{name}.inp"
            deck.write_text(text)
            t0 = time.perf_counter()
            r = subprocess.run(["nice", a.bulkflow, str(deck), "--output", str(out / name), "--quiet"],
                               capture_output=True, text=True)
            wall = time.perf_counter() - t0
            if r.returncode != 0:
                sys.exit(f"{deck}: exit {r.returncode}\n{r.stderr}")
            hist = np.genfromtxt(out / f"{name}_history.csv", delimiter=",", names=True)
            mdr = mean_discharge_rate(hist)
            tp = re.search(r"throughput (\d+) particle-steps,\s+([0-9.E+-]+) per second", r.stdout)
            rate = float(tp.group(2)) if tp else float("nan")
            rows[(cell, label)] = mdr
            print(f"h = {cell:.4f} m ({k:g} cells per b/2) {label:8s}: MDR {mdr:8.2f} kg/s/m  ({wall:.0f} s wall, "
                  f"{rate:.3e} particle-steps/s)", flush=True)
    cells = sorted({c for c, _ in rows}, reverse=True)
    print(f"\nh [m]   " + "".join(f"{v:>12s}" for v in a.variants) + "   (MDR, kg/s per m of depth, half model)")
    for c in cells:
        print(f"{c:.4f}  " + "".join(f"{rows[(c, v)]:12.2f}" for v in a.variants))
    for v in a.variants:
        f = [rows[(c, v)] for c in cells]
        if len(f) >= 2:
            print(f"{v}: change between the two finest cells {100 * (f[-1] - f[-2]) / f[-2]:+.2f} %")
        if len(f) >= 3:
            res = richardson(cells[-3:], f[-3:])
            if res is None:
                print(f"{v}: the last three are not monotone: no Richardson extrapolation")
            else:
                ext, gci, order = res
                print(f"{v}: Richardson {ext:.1f} kg/s/m, observed order {order:.2f}, GCI(fine) "
                      f"{100 * gci:.1f} % (+- {gci * f[-1]:.1f} kg/s/m)")


if __name__ == "__main__":
    main()
