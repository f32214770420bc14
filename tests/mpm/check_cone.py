#!/usr/bin/env python3
"""MPM scenes with a revolved rigid wall (*SURFACE, TYPE=REVOLUTION): run bin/bulkflow and check.

    check_cone.py <kind> <scene.inp> --bulkflow <exe> --workdir <dir>

kinds:
  slide   cone_slide_3d.inp: a block slides down a generator of a cone (30 deg to the horizontal,
          mu = 0.2; the wall is a revolved profile, the block's centre line on the symmetry plane
          z = 0): the acceleration along the generator g (sin a - mu cos a) within 2 % (regression of
          the centre of mass velocity from 0.1 s), the force of the block on the cone m (g - a)
          within 2 % of m g (mean from 0.1 s), no motion across the generator (|v_z| of the centre
          of mass < 1e-3 of the slide velocity), every particle on the material side of the cone
  hopper  cone_quarter_3d.inp (bulkflow-make-cone): a quarter conical hopper (symmetry planes
          x = 0 and z = 0, both mirrored) filled and discharged: exact mass balance and particle
          counts, no outflow while the outlet is closed, the fill's weight carried by the cone and
          the outlet plate at the end of the fill (vertical wall forces within 3 % of M g),
          the two symmetry planes' reactions equal and normal to them (1e-6), the quarter model
          symmetric under x <-> z (centre of mass XCM1 = XCM3 within 1e-3 of the radius), no particle behind a symmetry plane or outside the hopper, and discharge
          (MASS_OUT > 0, MDR integrates to MASS_OUT)
Figures are printed so the test log holds them.
"""
import argparse
import math
import re
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_mpm import check, check_report, mass_balance, run, slide_acceleration  # noqa: E402


def slide(args):
    base, out, hist = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["walls", "gravity"], ["damping", "outflow", "inflow"])
    a, grav = math.radians(30.0), 9.81
    acc, vs, m = slide_acceleration(hist, "cone generator")
    mass = hist["MASS"][0]
    force = np.array([hist[f"WALLF{i}_CONE"][m].mean() for i in (1, 2, 3)])
    slope = np.array([math.cos(a), -math.sin(a), 0.0])
    want = mass * (np.array([0.0, -grav, 0.0]) - acc * slope)
    ferr = np.linalg.norm(force - want) / (mass * grav)
    check(ferr < 0.02, f"force on the cone {np.round(force, 2)} N vs m (g - a) {np.round(want, 2)} N: "
          f"difference {ferr:.2e} of m g")
    drift = np.abs(hist["VCM3"][m]).max() / np.abs(vs[m]).max()
    check(drift < 1e-3, f"no motion across the generator: max |v_z| / max v_slide = {drift:.2e}")
    with h5py.File(str(base) + ".h5", "r") as f:
        keys = sorted(f["particles"].keys())
        worst = 0.0
        for k in keys:
            x = f["particles"][k]["coordinates"][:]
            r = np.hypot(x[:, 0] - 10.0, x[:, 2])
            gap = (x[:, 1] - 1.2 + math.tan(a) * (10.0 - r)) * math.cos(a)
            worst = min(worst, gap.min())
    check(worst > -1e-9, f"every particle on the material side of the cone (smallest gap {worst:.2e} m)")
    mass_balance(hist)


def scene_figures(scene):
    """theta, outlet level y0, outlet radius and bin radius from the generator's comment lines."""
    text = Path(scene).read_text()
    theta = float(re.search(r"theta=([0-9.]+) deg", text).group(1))
    y0 = float(re.search(r"outlet y0 = ([0-9.]+) m", text).group(1))
    d = float(re.search(r"D=([0-9.]+) m", text).group(1))
    radius = float(re.search(r"R=([0-9.]+) m", text).group(1))
    return theta, y0, 0.5 * d, radius


def hopper(args):
    base, out, hist = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["walls", "gravity", "outflow", "damping"], ["inflow"])
    theta, y0, r_out, radius = scene_figures(args.scene)
    mass_balance(hist)
    mm = re.search(r"particles (\d+) \((\d+) in, (\d+) out\)", out)
    check(mm is not None, "summary line with particle counts")
    nend, nin, nout = (int(v) for v in mm.groups())
    n0 = int(hist["particles"][0])
    check(nin == 0 and nout > 0 and n0 - nout == nend == int(hist["particles"][-1]),
          f"particle count: {n0} - {nout} out = {nend}")
    mp = hist["MASS"][0] / n0
    check(abs(hist["MASS_OUT"][-1] - nout * mp) <= 1e-12 * hist["MASS"][0], "MASS_OUT = n_out m_p")
    fill = hist["step"] == 1
    check(hist["MASS_OUT"][fill].max() == 0, "no outflow while the outlet is closed (step FILL)")
    integral = np.sum(hist["MDR"][1:] * np.diff(hist["time"]))
    check(abs(integral - hist["MASS_OUT"][-1]) <= 1e-9 * hist["MASS"][0],
          f"integral of MDR = {integral:.6g} kg = MASS_OUT (quarter model)")
    # the weight at the end of the fill: cone + outlet plate (the symmetry planes carry none of it)
    i = np.nonzero(fill)[0][-1]
    weight = hist["MASS"][i] * 9.81
    carried = hist["WALLF2_CONE"][i] + hist["WALLF2_OUTLET"][i]
    share = hist["WALLF2_CONE"][i] / carried
    check(abs(-carried / weight - 1) < 0.03, f"end of fill: cone {-hist['WALLF2_CONE'][i]:.2f} N + outlet "
          f"{-hist['WALLF2_OUTLET'][i]:.2f} N = {-carried:.2f} N vs weight {weight:.2f} N "
          f"(cone carries {share:.1%}); ALLKE {hist['ALLKE'][i]:.2e} J")
    fx, fz = hist["WALLF1_SYMX"][i], hist["WALLF3_SYMZ"][i]
    check(abs(fx - fz) <= 1e-6 * abs(fx) and abs(hist["WALLF2_SYMZ"][i]) <= 1e-6 * abs(fz),
          f"end of fill: the two symmetry planes' reactions are equal, {fx:.4f} N and {fz:.4f} N, and normal "
          f"to them (SYMZ's vertical part {hist['WALLF2_SYMZ'][i]:.2e} N)")
    asym = np.abs(hist["XCM1"] - hist["XCM3"])[hist["particles"] > 0].max() / radius
    check(asym < 1e-3, f"x <-> z symmetry of the quarter model: max |XCM1 - XCM3| / R = {asym:.2e}")
    t = math.tan(math.radians(theta))
    with h5py.File(str(base) + ".h5", "r") as f:
        keys = sorted(f["particles"].keys())
        lowest, outside = 0.0, 0.0
        for k in keys:
            x = f["particles"][k]["coordinates"][:]
            lowest = min(lowest, x[:, 0].min(), x[:, 2].min())
            r = np.hypot(x[:, 0], x[:, 2])
            above = x[:, 1] >= y0
            wall_r = np.minimum(x[above, 1] * t, radius)
            if above.any():
                outside = max(outside, (r[above] - wall_r).max())
    h = float(h5py.File(str(base) + ".h5", "r")["grid"].attrs["h"][0])
    check(lowest >= 0.0, f"no particle behind a symmetry plane (smallest x or z: {lowest:.3e} m)")
    check(outside <= 1e-9 * radius, f"no particle outside the cone or the cylinder (largest r - r_wall: "
          f"{outside:.2e} m, cell {h:g} m)")
    step2 = hist["step"] == 2
    print(f"      discharge: {hist['MASS_OUT'][-1]:.3f} kg of {hist['MASS'][0]:.3f} kg (quarter) in "
          f"{hist['step_time'][step2][-1]:.3f} s, mean MDR of the full hopper "
          f"{4 * hist['MASS_OUT'][-1] / hist['step_time'][step2][-1]:.2f} kg/s")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("kind", choices=["slide", "hopper"])
    p.add_argument("scene")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True, type=Path)
    args = p.parse_args()
    globals()[args.kind](args)
    print("PASS")


if __name__ == "__main__":
    main()
