#!/usr/bin/env python3
"""*NONLOCAL on the small MPM hopper (docs/nonlocal.md), ctest mpm_nonlocal_hopper_2d.

    check_nonlocal.py SCENE --bulkflow BIN --workdir DIR

Runs SCENE (a hopper whose MC material's psi table follows the VUSDFLD's FV1 = volumetric
strain) four ways and checks:
1. LENGTH a thousandth of the particle spacing: every particle a neighbourhood of its own, so the run with
   the option (VUSDFLD on all blocks, the average, then the VUMAT with fieldNew given) is the
   local run bit for bit: history CSV and every particle dataset identical. Shows the split of
   the VUSDFLD from the VUMAT keeps the Abaqus contract exactly.
2. LENGTH of three particle spacings: runs to the end with finite fields and the particle count
   balance exact; the results differ from the local run (history and the last frame's SDV).
   (A length of 0.4 spacings already changes the run late in the discharge, where particles
   crowd above the outlet and come that close: the average acts only where neighbours are.)
3. The same stopped with --stop-after in the discharge and continued with --restart: history and
   particle datasets identical to the uninterrupted run.
Exit 0 when all hold, 1 with the failures listed.
"""
import argparse
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np


def run(bulkflow, deck, base, *extra):
    r = subprocess.run([bulkflow, str(deck), "--output", str(base), "--quiet", *extra],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{deck} {' '.join(extra)}: exit {r.returncode}\n{r.stdout}\n{r.stderr}")


def frames(base):
    """{frame: {dataset: array}} of the particle groups."""
    out = {}
    with h5py.File(f"{base}.h5", "r") as f:
        for name, g in f["particles"].items():
            out[name] = {k: np.array(v) for k, v in g.items()}
    return out


def same(a, b):
    if a.keys() != b.keys():
        return False
    return all(a[k].keys() == b[k].keys() and all(np.array_equal(a[k][d], b[k][d]) for d in a[k]) for k in a)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scene")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True)
    a = p.parse_args()
    work = Path(a.workdir)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    text = Path(a.scene).read_text()
    # FV1 in every frame, so the field the VUMAT read can be compared
    text = text.replace("*ELEMENT OUTPUT\nS, SDV\n", "*ELEMENT OUTPUT\nS, SDV, FV\n")
    cell = float(text.split("CELL=")[1].split(",")[0].split()[0])
    spacing = cell / 2  # PPC=2
    i = text.index("*STEP")
    decks = {}
    for name, length in (("local", None), ("tiny", 1e-3 * spacing), ("nonlocal", 3 * spacing)):
        t = text if length is None else text[:i] + f"*NONLOCAL, LENGTH={length!r}\n" + text[i:]
        decks[name] = work / f"{name}.inp"
        decks[name].write_text(t)
        run(a.bulkflow, decks[name], work / name)
    fails = []
    hist = {n: (work / f"{n}_history.csv").read_text() for n in decks}
    fr = {n: frames(work / n) for n in decks}
    # 1
    if hist["tiny"] != hist["local"] or not same(fr["tiny"], fr["local"]):
        fails.append("LENGTH below the spacing: not the local run bit for bit")
    # 2
    last = max(fr["nonlocal"])
    nl, lo = fr["nonlocal"][last], fr["local"][last]
    for k in ("S", "SDV", "FV1", "coordinates"):
        if not np.all(np.isfinite(nl[k])):
            fails.append(f"nonlocal: {k} not finite in the last frame")
    h = np.genfromtxt(work / "nonlocal_history.csv", delimiter=",", names=True)
    names = h.dtype.names
    if "MASS" in names and "MASS_OUT" in names and "MASS_IN" in names:
        err = abs(h["MASS"][-1] + h["MASS_OUT"][-1] - h["MASS_IN"][-1] - h["MASS"][0])
        if err > 1e-9 * h["MASS"][0]:
            fails.append(f"nonlocal: mass balance off by {err}")
    if hist["nonlocal"] == hist["local"]:
        fails.append("nonlocal with three spacings changed nothing")
    if np.array_equal(nl["SDV"], lo["SDV"]) if nl["SDV"].shape == lo["SDV"].shape else False:
        fails.append("nonlocal with three spacings: the last frame's SDV are the local run's")
    # 3
    stop = 1800  # in the discharge of the small hopper (the fill ends near increment 1120)
    base = work / "restart"
    shutil.copy(decks["nonlocal"], work / "restart.inp")
    run(a.bulkflow, work / "restart.inp", base, "--stop-after", str(stop))
    run(a.bulkflow, work / "restart.inp", base, "--restart")
    if (work / "restart_history.csv").read_text() != hist["nonlocal"] or not same(frames(base), fr["nonlocal"]):
        fails.append("restart with *NONLOCAL: not the uninterrupted run bit for bit")
    for f in fails:
        print("FAIL:", f)
    print("ok" if not fails else f"{len(fails)} failure(s)")
    sys.exit(1 if fails else 0)


if __name__ == "__main__":
    main()
