#!/usr/bin/env python3
"""*MPM CONTROLS, MAX DILATION=j (docs/keywords.md): the small concentric bin
(inputs/mpm/bin_small_concentric_2d.inp) run as it is and with MAX DILATION=1.25 added to its
*MPM CONTROLS line, and checked:

- without it, some particle stretches past J = 1.25 (density below 1800/1.25 = 1440 kg/m3): the
  case the option is for happens in this scene (else the next check could not fail);
- with it, no particle of any frame is looser than 1440 kg/m3 (to 1e-9 relative), the summary
  counts the particle-increments held, and the run takes fewer increments (the stretched
  particle no longer sets the stable increment);
- both runs keep the particle and mass balance exact (bin_checks.balance: n0 = out + remaining,
  MASS_OUT = n_out particle masses, |M0 - MASS_OUT - MASS| round-off), so holding J moves no mass.

    check_max_dilation.py <bin.inp> --bulkflow <exe> --workdir <dir>
"""
import argparse
import re
from pathlib import Path

import h5py

from bin_checks import Checks, balance, run_scene, with_controls

JMAX = 1.25


def run(exe, scene, base):
    out, hist = run_scene(exe, scene, base)
    with h5py.File(str(base) + ".h5", "r") as f:
        rho_min = min(float(f["particles"][k]["density"][:].min()) for k in f["particles"])
    return out, hist, rho_min


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scene")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True)
    a = p.parse_args()
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    text = Path(a.scene).read_text()
    check = Checks()
    held_scene = work / "bin_max_dilation.inp"
    held_scene.write_text(with_controls(text, a.scene, lambda line: line + f", MAX DILATION={JMAX}"))
    rho_i = float(re.search(r"^\*DENSITY\s*\n\s*([0-9.eE+-]+)", text, re.M).group(1))
    floor = rho_i / JMAX

    out0, hist0, rho0 = run(a.bulkflow, a.scene, work / "free")
    out1, hist1, rho1 = run(a.bulkflow, held_scene, work / "held")
    check(rho0 < floor, f"without MAX DILATION a particle stretches past J = {JMAX}: density {rho0:.1f} < {floor:.1f}")
    check(rho1 >= floor * (1 - 1e-9), f"with MAX DILATION={JMAX} every frame's density >= {floor:.1f}: min {rho1:.6f}")
    m = re.search(r"particle-increments held at MAX DILATION: (\d+)", out1)
    check(m is not None and int(m.group(1)) > 0, "the summary counts the held particle-increments: "
          + (m.group(1) if m else "no line"))
    check("held at MAX DILATION" not in out0, "no such line when the scene does not ask for it")
    inc0, inc1 = int(hist0["increment"][-1]), int(hist1["increment"][-1])
    check(inc1 < inc0, f"the held run takes fewer increments: {inc1} < {inc0}")
    balance(check, "free", out0, hist0)
    balance(check, "held", out1, hist1)
    check.finish()


if __name__ == "__main__":
    main()
