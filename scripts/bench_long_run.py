#!/usr/bin/env python3
"""Long-run stability benchmark (issue 21 point 4, the longer variant of `ctest -L stability`).

    python3 scripts/bench_long_run.py [--bulkflow build/bin/bulkflow] [--increments 1000000]
                                      [--material elastic|mohr-coulomb|mpm|all] [--workdir DIR]

A plane-strain CPE4R column (inputs/verification/column_2d.inp: 1 m tall, 4 elements wide, on
rollers, gravity by smooth step over 0.49 s) is held under gravity for as long as `--increments`
stable increments take (a probe run measures the solver's own stable increment first, so the run
is the solver's real time step, not a user-chosen one). Two materials: the elastic column of the
verification scene, and the same column of Mohr-Coulomb sand (phi 10 deg, c 0: the at-rest
stress state K0 = nu/(1 - nu) = 0.43 lies outside the yield surface, so the column yields while
gravity comes on, then rests).

"Stable" means, and is checked (exit status 1 when one fails):
  * every history value finite, exit status 0;
  * energy balance: |ETOTAL(t) - ETOTAL(0)| <= 1 % of the largest of ALLWK, ALLIE, ALLKE at every
    history row (the bound of the short stability cases, held 100 times longer);
  * no drift: the least-squares slope of the energy error over the second half of the run, times
    the run's length, is below 0.1 % (an error that accumulates per increment would grow
    linearly; round-off that stays bounded does not);
  * the column is at rest at the end (ALLKE below 1e-6 of ALLIE) and its base stress equals
    -rho g (H - y) within 3 % (elastic and Mohr-Coulomb alike: vertical equilibrium);
  * the lateral stress ratio sigma_11/sigma_22 at the base is the closed form within 1 %:
    K0 = nu/(1 - nu) for the elastic column, the active ratio (1 - sin phi)/(1 + sin phi) for the
    Mohr-Coulomb column (it yielded: its K0 lies outside the yield surface).
It prints increments, wall time, nanoseconds per element-increment and the figures above.

`--material mpm` runs the material-point column of inputs/mpm/column_k0_2d.inp (elastic,
nu = 0.2, 320 particles, GIMP, local damping 0.2, gravity by smooth step over 0.3 s) for as many
increments. An MPM balance is not exact (the PIC share of the grid-to-particle transfer and the
damping dissipate energy that no column books), so there "stable" means: finite, the particle
mass exact, no energy created (ETOTAL never rises above its start by more than 2 % of the largest
energy, the bound of `ctest -L stability`), no drift (ETOTAL's slope over the second half times
the run's length below 0.1 % of the largest energy), at rest at the end (ALLKE/ALLIE <= 1e-6),
and the vertical stress of the lowest particle row within 3 % of -rho g (H - y).
"""
import argparse
import math
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np

REPO = Path(__file__).resolve().parent.parent
ENERGY_BOUND = 0.01
DRIFT_BOUND = 0.001
REST_BOUND = 1.0e-6


def verdict(ok):
    """Print each criterion's outcome; are they all met?"""
    for what, good in ok.items():
        print(f"  {'ok  ' if good else 'FAIL'} {what}")
    return all(ok.values())


def scene(material, period, history_rows):
    """The verification column with the hold's period, a history row every period/history_rows and
    one field frame at the end; `material` elastic or mohr-coulomb."""
    text = (REPO / "inputs/verification/column_2d.inp").read_text()
    old_period = re.search(r"\*DYNAMIC, EXPLICIT\n, ([0-9.eE+-]+)\n", text)
    if old_period is None:
        raise SystemExit("bench_long_run: inputs/verification/column_2d.inp lost its *DYNAMIC line")
    text = text.replace(old_period.group(0), f"*DYNAMIC, EXPLICIT\n, {period!r}\n")
    text = text.replace("*OUTPUT, FIELD, NUMBER INTERVAL=10", "*OUTPUT, FIELD, NUMBER INTERVAL=1")
    text = text.replace("*OUTPUT, HISTORY, NUMBER INTERVAL=200", f"*OUTPUT, HISTORY, NUMBER INTERVAL={history_rows}")
    if material == "mohr-coulomb":
        lines = text.splitlines(keepends=True)
        at = next(i for i, l in enumerate(lines) if l.startswith("*ELASTIC"))
        # the data line of *ELASTIC follows; the Mohr-Coulomb options go after it
        lines.insert(at + 2, "*MOHR COULOMB\n10.0, 0.0\n*MOHR COULOMB HARDENING\n0.0, 0.0\n")
        text = "".join(lines)
    return text


def run(exe, workdir, name, text, extra=()):
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / (name + ".inp")
    inp.write_text(text)
    base = workdir / name
    t0 = time.perf_counter()
    r = subprocess.run([exe, str(inp), "--output", str(base), "--quiet", *extra], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.stdout.write(r.stdout[-3000:] + r.stderr[-3000:])
        raise SystemExit(f"bench_long_run: {name}: exit status {r.returncode}")
    hist = np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)
    return base, hist, wall


def stable_increment(exe, workdir, material):
    """The solver's stable increment on this column: a probe of 2000 increments."""
    _, hist, _ = run(exe, workdir, f"probe_{material}", scene(material, 1.0, 10), ["--stop-after", "2000"])
    return float(hist["time"][-1]) / float(hist["increment"][-1])


def base_stress(base):
    with h5py.File(str(base) + ".h5", "r") as f:
        xy = f["mesh/coordinates"][()]
        conn = f["mesh/connectivity"][()]
        last = sorted(f["frames"])[-1]
        stress = f["frames"][last]["S"][()]
    yc = xy[conn, 1].mean(axis=1)
    row = yc < yc.min() + 1e-9
    s22 = float(np.mean(stress[row, 1]))
    return s22, -2000.0 * 9.81 * (1.0 - float(yc[row][0])), float(np.mean(stress[row, 0])) / s22


def long_run(exe, workdir, material, increments):
    dt = stable_increment(exe, workdir, material)
    period = increments * dt
    base, hist, wall = run(exe, workdir, f"long_{material}", scene(material, period, 1000))
    n = int(hist["increment"][-1])
    names = hist.dtype.names
    finite = all(np.all(np.isfinite(hist[c])) for c in names)
    scale = max(float(np.max(np.abs(hist[c]))) for c in ("ALLWK", "ALLIE", "ALLKE"))
    err = (hist["ETOTAL"] - hist["ETOTAL"][0]) / scale
    half = hist["time"] >= 0.5 * hist["time"][-1]
    slope = np.polyfit(hist["time"][half], err[half], 1)[0]
    drift = abs(slope) * float(hist["time"][-1])
    rest = float(hist["ALLKE"][-1]) / max(float(hist["ALLIE"][-1]), 1e-300)
    s, exact, ratio = base_stress(base)
    nu, phi = 0.3, math.radians(10.0)
    ratio_exact = nu / (1.0 - nu) if material == "elastic" else (1.0 - math.sin(phi)) / (1.0 + math.sin(phi))
    ok = {
        "finite": finite,
        "energy": float(np.max(np.abs(err))) <= ENERGY_BOUND,
        "drift": drift <= DRIFT_BOUND,
        "rest": rest <= REST_BOUND,
        "base stress": abs(s - exact) <= 0.03 * abs(exact),
        "lateral ratio": abs(ratio - ratio_exact) <= 0.01 * ratio_exact,
    }
    with h5py.File(str(base) + ".h5", "r") as f:
        elements = int(f["mesh/connectivity"].shape[0])
    print(f"{material}: {n} increments of {dt:.4e} s ({period:.1f} s), wall {wall:.1f} s, "
          f"{1e9 * wall / (n * elements):.0f} ns per element-increment ({elements} elements)")
    print(f"  energy error max {np.max(np.abs(err)):.3e} (bound {ENERGY_BOUND:g}), end {err[-1]:+.3e}, "
          f"drift over the second half x run length {drift:.3e} (bound {DRIFT_BOUND:g})")
    print(f"  at rest: ALLKE/ALLIE {rest:.2e} (bound {REST_BOUND:g}); base sigma_22 {s:.1f} Pa, "
          f"closed form {exact:.1f} Pa ({100 * (s - exact) / exact:+.2f} %); sigma_11/sigma_22 {ratio:.5f}, "
          f"closed form {ratio_exact:.5f}")
    return verdict(ok)


def mpm_scene(period, history_rows):
    text = (REPO / "inputs/mpm/column_k0_2d.inp").read_text()
    old = re.search(r"\*DYNAMIC, EXPLICIT\n, ([0-9.eE+-]+)\n", text)
    if old is None:
        raise SystemExit("bench_long_run: inputs/mpm/column_k0_2d.inp lost its *DYNAMIC line")
    text = text.replace(old.group(0), f"*DYNAMIC, EXPLICIT\n, {period!r}\n")
    text = re.sub(r"\*OUTPUT, FIELD, NUMBER INTERVAL=\d+", "*OUTPUT, FIELD, NUMBER INTERVAL=1", text)
    return re.sub(r"\*OUTPUT, HISTORY, NUMBER INTERVAL=\d+", f"*OUTPUT, HISTORY, NUMBER INTERVAL={history_rows}", text)


def mpm_long_run(exe, workdir, increments):
    _, probe, _ = run(exe, workdir, "probe_mpm", mpm_scene(1.0, 10), ["--stop-after", "2000"])
    dt = float(probe["time"][-1]) / float(probe["increment"][-1])
    period = increments * dt
    base, hist, wall = run(exe, workdir, "long_mpm", mpm_scene(period, 1000))
    n = int(hist["increment"][-1])
    finite = all(np.all(np.isfinite(hist[c])) for c in hist.dtype.names)
    scale = max(float(np.max(np.abs(hist[c]))) for c in ("ALLWK", "ALLIE", "ALLKE"))
    err = (hist["ETOTAL"] - hist["ETOTAL"][0]) / scale
    half = hist["time"] >= 0.5 * hist["time"][-1]
    drift = abs(np.polyfit(hist["time"][half], err[half], 1)[0]) * float(hist["time"][-1])
    rest = float(hist["ALLKE"][-1]) / max(float(hist["ALLIE"][-1]), 1e-300)
    mass_now = hist["MASS"][0] + hist["MASS_IN"][-1] - hist["MASS_OUT"][-1]
    with h5py.File(str(base) + ".h5", "r") as f:
        last = sorted(f["particles"])[-1]
        xy = f["particles"][last]["coordinates"][()]
        stress = f["particles"][last]["S"][()]
    low = xy[:, 1] < xy[:, 1].min() + 1e-3
    s22 = float(np.mean(stress[low, 1]))
    exact = -1600.0 * 9.81 * (1.0 - float(np.mean(xy[low, 1])))
    ok = {
        "finite": finite and bool(np.all(np.isfinite(stress))),
        "mass": abs(mass_now - hist["MASS"][-1]) <= 1e-9 * hist["MASS"][0],
        "no energy created": float(np.max(err)) <= 0.02,
        "drift": drift <= DRIFT_BOUND,
        "rest": rest <= REST_BOUND,
        "base stress": abs(s22 - exact) <= 0.03 * abs(exact),
    }
    print(f"mpm: {n} increments of {dt:.4e} s ({period:.1f} s), wall {wall:.1f} s, "
          f"{1e9 * wall / (n * len(xy)):.0f} ns per particle-increment ({len(xy)} particles)")
    print(f"  ETOTAL rise max {np.max(err):.3e} (bound 0.02), end {err[-1]:+.3e} (a fall is dissipation no column books), "
          f"drift over the second half x run length {drift:.3e} (bound {DRIFT_BOUND:g})")
    print(f"  at rest: ALLKE/ALLIE {rest:.2e} (bound {REST_BOUND:g}); lowest row sigma_22 {s22:.1f} Pa, "
          f"closed form {exact:.1f} Pa ({100 * (s22 - exact) / exact:+.2f} %); "
          f"sigma_11/sigma_22 {float(np.mean(stress[low, 0])) / s22:.4f} (K0 = 0.25)")
    return verdict(ok)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bulkflow", default=str(REPO / "build/bin/bulkflow"))
    ap.add_argument("--increments", type=int, default=1_000_000)
    ap.add_argument("--material", choices=("elastic", "mohr-coulomb", "mpm", "all"), default="all")
    ap.add_argument("--workdir", type=Path, default=REPO / "out/bench_long_run")
    a = ap.parse_args()
    if not os.access(a.bulkflow, os.X_OK):
        raise SystemExit(f"bench_long_run: {a.bulkflow} is not an executable (bash scripts/build.sh release)")
    print(f"bench_long_run: {a.bulkflow}, {a.increments} increments, load average {os.getloadavg()[0]:.2f}")
    materials = ("elastic", "mohr-coulomb", "mpm") if a.material == "all" else (a.material,)
    good = [mpm_long_run(a.bulkflow, a.workdir, a.increments) if m == "mpm" else
            long_run(a.bulkflow, a.workdir, m, a.increments) for m in materials]
    sys.exit(0 if all(good) else 1)


if __name__ == "__main__":
    main()
