#!/usr/bin/env python3
"""Front and back wall friction of a quasi-2D bin (*MPM SIDE FRICTION) against Janssen's slot.

    check_side_friction.py <scene.inp> --bulkflow <exe> --workdir <dir>

The scene (tests/mpm/scenes/side_friction_janssen_2d.inp) is a column of cohesionless sand at
rest in a slot of gap t, between frictionless side walls (mirrored) on a frictionless floor. Checks:
  - the run lists 'side friction' among its effects and times it;
  - K = sigma_zz/sigma_yy measured on the particles (the model's, not assumed; its spread printed);
  - Janssen's slot solution with that K (docs/theory/side_friction.md),
        sigma_v(z) = rho g t / (2 mu K) (1 - exp(-2 mu K z / t)),  z the depth,
    against the layer means of sigma_yy (every grid-cell layer deeper than 0.1 H) within 2 %,
    and against the floor reaction (the weight the floor carries, the rest is on the two walls)
    within 2 %; floor reaction + the side friction force (SIDEF2) = the weight (1e-3);
  - the column is held statically, not chattering: ALLKE ~ 0 and the floor reaction constant to
    1e-4 over the last rows (friction at rest dissipates nothing: ALLFD constant there too);
  - the energy balance closes (|ETOTAL| < 1 % of ALLWK).
Figures are printed so the test log holds them.
"""
import argparse
import math
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

RHO, GRAV, GAP, MU, WIDTH, HEIGHT = 1800.0, 9.81, 0.025, 0.3, 0.04, 0.2


def check(cond, msg):
    print(("ok    " if cond else "FAIL  ") + msg)
    if not cond:
        sys.exit(1)


def janssen(z, k):
    """Vertical stress (compression positive) at depth z in a slot of gap GAP, friction on both faces."""
    a = 2 * MU * k / GAP
    return RHO * GRAV / a * (1 - np.exp(-a * z))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--bulkflow", required=True)
    ap.add_argument("--workdir", required=True, type=Path)
    args = ap.parse_args()
    args.workdir.mkdir(parents=True, exist_ok=True)
    base = args.workdir / Path(args.scene).stem
    r = subprocess.run([args.bulkflow, args.scene, "--output", str(base), "--quiet"], capture_output=True, text=True)
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    check(r.returncode == 0, f"bulkflow exit status {r.returncode}")
    effects = next((l for l in r.stdout.splitlines() if l.strip().startswith("effects")), "")
    check("side friction" in effects, "effect 'side friction' listed as active")
    check("side friction" in r.stdout.split("timing (wall seconds):")[-1], "side friction timed apart")
    hist = np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)

    f = h5py.File(str(base) + ".h5", "r")
    frame = f["particles"][sorted(f["particles"].keys())[-1]]
    x, s = frame["coordinates"][:], frame["S"][:]
    h = float(f["grid"].attrs["h"][0])
    y = x[:, 1]
    top = y.max() + 0.25 * h            # PPC 2: the top particle row sits a quarter cell below the surface
    depth = top - y
    deep = depth > 0.1 * HEIGHT
    ratio = s[deep, 2] / s[deep, 1]
    k = ratio.mean()
    print(f"      K = sigma_zz/sigma_yy over {deep.sum()} particles deeper than 0.1 H: {k:.5f} "
          f"(min {ratio.min():.5f}, max {ratio.max():.5f}); nu/(1-nu) = {0.3 / 0.7:.5f}")
    check(ratio.max() - ratio.min() < 0.02 * k, "K uniform over the column (spread < 2 %)")
    check(np.all(s[:, 2] <= 0), "sigma_zz compressive everywhere")

    layer = np.floor(y / h).astype(int)
    worst = 0.0
    print("      layer  depth [m]  -sigma_yy [Pa]  Janssen [Pa]  error")
    for c in np.unique(layer):
        m = layer == c
        if depth[m].mean() <= 0.1 * HEIGHT:
            continue
        model = -s[m, 1].mean()
        expected = janssen(depth[m], k).mean()
        err = model / expected - 1
        worst = max(worst, abs(err))
        print(f"      {c:5d}  {depth[m].mean():9.4f}  {model:14.2f}  {expected:12.2f}  {err:+.2e}")
    check(worst < 0.02, f"sigma_yy vs Janssen's slot: max relative error {worst:.2e} (< 2 %)")

    weight = RHO * GRAV * WIDTH * HEIGHT
    floor = -hist["WALLF2_FLOOR"][-1]
    expected = janssen(HEIGHT, k) * WIDTH
    err = floor / expected - 1
    print(f"      weight {weight:.3f} N/m: floor carries {floor:.3f} N/m ({floor / weight:.4f} W), "
          f"the front and back walls {-hist['SIDEF2'][-1]:.3f} N/m")
    check(abs(err) < 0.02, f"floor reaction {floor:.3f} vs Janssen {expected:.3f} N/m: error {err:+.2e} (< 2 %)")
    print(f"      Janssen's fraction on the floor sigma_v(H)/(rho g H) = {expected / weight:.4f}")
    side = -hist["SIDEF2"][-1]
    check(abs(floor + side - weight) < 1e-3 * weight,
          f"static balance: floor {floor:.3f} + front/back walls {side:.3f} = {floor + side:.3f} N/m "
          f"= weight {weight:.3f} N/m (1e-3)")

    hold = hist["time"] >= hist["time"][-1] - 0.05
    fl = -hist["WALLF2_FLOOR"][hold]
    drift = (fl.max() - fl.min()) / fl.mean()
    check(drift < 1e-4, f"held statically: floor reaction over the last 0.05 s varies by {drift:.1e} (< 1e-4)")
    fd = hist["ALLFD"][hold]
    check((fd.max() - fd.min()) <= 1e-6 * hist["ALLWK"][-1],
          f"no friction work at rest: ALLFD changes by {fd.max() - fd.min():.2e} J/m over the hold")
    check(hist["ALLKE"][-1] < 1e-8 * hist["ALLWK"][-1], f"at rest: ALLKE = {hist['ALLKE'][-1]:.2e} J/m")
    check(abs(hist["ETOTAL"][-1]) < 0.01 * hist["ALLWK"][-1],
          f"energy balance: ETOTAL = {hist['ETOTAL'][-1]:.3e} of ALLWK = {hist['ALLWK'][-1]:.3e} J/m "
          f"(ALLFD {hist['ALLFD'][-1]:.3e})")


if __name__ == "__main__":
    main()
