#!/usr/bin/env python3
"""*MPM CONTROLS, MAX DILATION=j (docs/keywords.md): the small concentric bin
(inputs/mpm/bin_small_concentric_2d.inp) run as it is and with MAX DILATION=1.25 added to its
*MPM CONTROLS line, and checked:

- without it, some particle stretches past J = 1.25 (density below 1800/1.25 = 1440 kg/m3): the
  case the option is for happens in this scene (else the next check could not fail);
- with it, no particle of any frame is looser than 1440 kg/m3 (to 1e-9 relative), the summary
  counts the particle-increments held, and the run takes fewer increments (the stretched
  particle no longer sets the stable increment);
- both runs keep the particle and mass balance exact (n0 = out + remaining; |M0 - MASS_OUT - MASS|
  round-off), so holding J moves no mass.

    check_max_dilation.py <bin.inp> --bulkflow <exe> --workdir <dir>
"""
import argparse
import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

FAILED = []
JMAX = 1.25


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        FAILED.append(what)


def run(exe, scene, base):
    r = subprocess.run([exe, str(scene), "--output", str(base)], capture_output=True, text=True)
    if r.returncode != 0:
        sys.stdout.write(r.stdout)
        sys.stderr.write(r.stderr)
        sys.exit(f"bulkflow failed on {scene} (status {r.returncode})")
    hist = np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)
    with h5py.File(str(base) + ".h5", "r") as f:
        rho_min = min(float(f["particles"][k]["density"][:].min()) for k in f["particles"])
    return r.stdout, hist, rho_min


def balance(name, out, hist):
    m = re.search(r"particles (\d+) \((\d+) in, (\d+) out\)", out)
    check(m is not None, f"{name}: summary line with particle counts")
    if m is None:
        return
    nend, _, nout = (int(v) for v in m.groups())
    n0 = int(hist["particles"][0])
    check(n0 == nout + nend and nout > 0, f"{name}: particles {n0} initial = {nout} out + {nend} remaining")
    err = np.abs(hist["MASS_ERROR"]).max()
    check(err <= 1e-12 * hist["MASS"][0], f"{name}: max |M0 - MASS_OUT - MASS| = {err:.3e} kg")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scene")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True)
    a = p.parse_args()
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    text = Path(a.scene).read_text()
    controls = re.search(r"^\*MPM CONTROLS[^\n]*$", text, re.M)
    if controls is None:
        sys.exit(f"{a.scene}: no *MPM CONTROLS line to add MAX DILATION to")
    held_scene = work / "bin_max_dilation.inp"
    held_scene.write_text(text[:controls.end()] + f", MAX DILATION={JMAX}" + text[controls.end():])
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
    balance("free", out0, hist0)
    balance("held", out1, hist1)
    if FAILED:
        sys.exit(f"{len(FAILED)} check(s) failed")
    print("all checks passed")


if __name__ == "__main__":
    main()
