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
import sys
from pathlib import Path

import numpy as np

from bin_checks import Checks, balance, run_scene

check = Checks()


def run(exe, scene, workdir):
    out, hist = run_scene(exe, scene, workdir / Path(scene).stem)
    sys.stdout.write(out)
    return out, hist


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
    out_c, hist_c = run(a.bulkflow, a.concentric, a.workdir)
    out_e, hist_e = run(a.bulkflow, a.eccentric, a.workdir)
    balance(check, "concentric", out_c, hist_c)
    balance(check, "eccentric", out_e, hist_e)
    mdr_c = 2.0 * rate(hist_c, a.skip)          # half model: the full bin discharges twice as much
    mdr_e = rate(hist_e, a.skip)
    check(mdr_e > mdr_c, f"eccentric discharges faster: MDR {mdr_e:.4g} > concentric {mdr_c:.4g} kg/s/m "
          f"(ratio {mdr_e / mdr_c:.3f})")
    out_c, out_e = 2.0 * hist_c["MASS_OUT"][-1], hist_e["MASS_OUT"][-1]
    check(out_e > out_c, f"eccentric has discharged more at the end: {out_e:.4g} > concentric {out_c:.4g} kg/m")
    check.finish("all bin checks passed")


if __name__ == "__main__":
    main()
