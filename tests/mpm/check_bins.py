#!/usr/bin/env python3
"""Flat-bottomed bin acceptance (issue 20, thesis ch. 5): a small concentric bin (half model,
mirrored symmetry plane) and the eccentric bin of the same outlet (full model, outlet against the
right wall), both written by bulkflow-make-bin (inputs/mpm/bin_small_*_2d.inp), run and checked:

- mass balance of each run exact: initial particles + 0 in = out + remaining (counts), the
  discharged mass is n_out times the particle mass and M0 - MASS_OUT - MASS is round-off (1e-12 M0);
- the eccentric bin discharges faster than the concentric one (full-bin MDR per metre, regression
  of the discharged mass from `--skip` s after opening to the end; and the discharged mass at the
  end), as in the thesis's experiments
  and Maiti et al.'s: the sand slides past the 7 deg wall instead of shearing against sand at 34 deg.

    check_bins.py <concentric.inp> <eccentric.inp> --bulkflow <exe> --workdir <dir>
"""
import argparse
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

FAILED = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        FAILED.append(what)


def run(exe, scene, workdir):
    workdir.mkdir(parents=True, exist_ok=True)
    base = workdir / Path(scene).stem
    r = subprocess.run([exe, scene, "--output", str(base), "--quiet"], capture_output=True, text=True)
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    if r.returncode != 0:
        sys.exit(f"bulkflow failed on {scene} (status {r.returncode})")
    return base, r.stdout, np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)


def balance(name, out, hist):
    m = re.search(r"particles (\d+) \((\d+) in, (\d+) out\)", out)
    check(m is not None, f"{name}: summary line with particle counts")
    nend, nin, nout = (int(v) for v in m.groups())
    n0 = int(hist["particles"][0])
    check(nin == 0 and nout > 0, f"{name}: no inflow, {nout} particles discharged")
    check(n0 == nout + nend == nout + int(hist["particles"][-1]),
          f"{name}: particles {n0} initial = {nout} out + {nend} remaining")
    m0 = hist["MASS"][0]
    mp = m0 / n0                     # one material, one particle size: equal masses
    err = np.abs(hist["MASS_ERROR"]).max()
    check(err <= 1e-12 * m0, f"{name}: max |M0 - MASS_OUT - MASS| = {err:.3e} kg (M0 = {m0:.6g} kg/m)")
    check(abs(hist["MASS_OUT"][-1] - nout * mp) <= 1e-12 * m0,
          f"{name}: MASS_OUT {hist['MASS_OUT'][-1]:.9g} = {nout} x particle mass {mp:.6g}")


def rate(hist, skip):
    t, step = hist["time"], hist["step"]
    i2 = int(np.argmax(step >= 2))
    t_open = t[i2] - hist["step_time"][i2]
    sel = t >= t_open + skip
    return float(np.polyfit(t[sel], hist["MASS_OUT"][sel], 1)[0])


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("concentric")
    p.add_argument("eccentric")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True, type=Path)
    p.add_argument("--skip", type=float, default=0.1, help="s after opening left out of the MDR fit")
    a = p.parse_args()
    _, out_c, hist_c = run(a.bulkflow, a.concentric, a.workdir)
    _, out_e, hist_e = run(a.bulkflow, a.eccentric, a.workdir)
    balance("concentric", out_c, hist_c)
    balance("eccentric", out_e, hist_e)
    mdr_c = 2.0 * rate(hist_c, a.skip)          # half model: the full bin discharges twice as much
    mdr_e = rate(hist_e, a.skip)
    check(mdr_e > mdr_c, f"eccentric discharges faster: MDR {mdr_e:.4g} > concentric {mdr_c:.4g} kg/s/m "
          f"(ratio {mdr_e / mdr_c:.3f})")
    out_c, out_e = 2.0 * hist_c["MASS_OUT"][-1], hist_e["MASS_OUT"][-1]
    check(out_e > out_c, f"eccentric has discharged more at the end: {out_e:.4g} > concentric {out_c:.4g} kg/m")
    if FAILED:
        sys.exit(f"{len(FAILED)} check(s) failed")
    print("all bin checks passed")


if __name__ == "__main__":
    main()
