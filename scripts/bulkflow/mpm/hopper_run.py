"""Run one MPM wedge-hopper scene (hopper_scene.py) with the solver and reduce it to the figures
the ch. 4 studies compare: steady MDR, outlet velocity and density, MFI, wall time.

Runs are named by a hash of their scene text, so studies that need the same case (the Table 4.2
base case is in studies a-h) share one run: a finished run whose `<base>.json` records the same
scene hash is read back instead of run again (`reuse=False` forces a new run).

    from bulkflow.mpm.hopper_run import run_hopper
    r = run_hopper(exe, "out/mpm_study/runs", cell=0.05, discharge_time=1.5, phi=25.0)
    r["mdr_full"], r["mfi"], r["base"]     # base: output base for paths.py / discharge.py
"""
import fcntl
import hashlib
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from .discharge import mass_flow_index, mean_discharge_rate
from .hopper_scene import hopper_scene
from .paths import frames, outlet_path

DEFAULT_EXE = str(Path(__file__).resolve().parents[3] / "build" / "bin" / "bulkflow")
# Bumped whenever the MPM solver's physics changes, so cached runs of an older solver are not
# read back as this one's (part of every run's name). 1: session 2's solver; 2: the particle
# put-back behind a wall applies the wall's Coulomb friction (before: frictionless); 3: symmetry
# planes on node planes mirror the grid (mpm_mirror), nodes within 1e-6 h of a wall are on it,
# the scene writes the cell in full.
MPM_REVISION = 3
RUN_DEFAULTS = dict(field_frames=5, history_dt=0.01)


def scene_text(**scene):
    kw = dict(RUN_DEFAULTS)
    kw.update(scene)
    return hopper_scene(**kw)


def run_hopper(exe=DEFAULT_EXE, out_dir="out/mpm_study/runs", reuse=True, ranks=1, label="", **scene):
    """Write, run and reduce one hopper scene. `scene` are hopper_scene() keywords. Returns a dict:
    base (output base path), wall [s], psteps, particles, mdr (half model) and mdr_full [kg/s/m],
    mfi, v_out, rho_out (outlet path means of the last 3 frames) and the scene keywords."""
    return cached_run(exe, out_dir, scene_text(**scene), "hopper_" + (label + "_" if label else ""),
                      lambda base, run: _reduce(base, run, scene), reuse, ranks)


def cached_run(exe, out_dir, text, prefix, reduce, reuse=True, ranks=1):
    """Run the scene `text` as out_dir/<prefix><hash> unless a finished run of the same text (and
    MPM_REVISION) is there; reduce(base, run) turns a fresh run (run: digest, base, wall [s],
    psteps, particles, stdout: the solver's printout, not kept) into the dict kept in <base>.json
    and returned."""
    digest = hashlib.sha256(f"mpm revision {MPM_REVISION}\n{text}".encode()).hexdigest()[:12]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    base = out / f"{prefix}{digest}"
    meta = base.with_suffix(".json")
    # two studies asking for the same case at once: the second waits and reads the first's result
    with open(base.with_suffix(".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if reuse and meta.exists():
            r = json.loads(meta.read_text())
            if r.get("digest") == digest:
                return r
        r = reduce(base, _run(exe, base, text, ranks, digest))
        r.pop("stdout", None)
        meta.write_text(json.dumps(r, indent=1))
        return r


def _run(exe, base, text, ranks, digest):
    scene_path = base.with_suffix(".inp")
    scene_path.write_text(text)
    cmd = [exe, str(scene_path), "--output", str(base), "--quiet"]
    if ranks > 1:
        cmd = ["mpirun", "-np", str(ranks)] + cmd
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        sys.stderr.write(res.stdout + res.stderr)
        raise SystemExit(f"run failed: {scene_path}")
    steps = int(re.search(r"throughput (\d+) particle-steps", res.stdout).group(1))
    npart = int(re.search(r"(\d+) particles,", res.stdout).group(1))
    return dict(digest=digest, base=str(base), wall=wall, psteps=steps, particles=npart, stdout=res.stdout)


def _reduce(base, run, scene):
    kw = dict(RUN_DEFAULTS)
    kw.update(scene)
    theta, outlet = kw.get("theta", 30.0), kw.get("outlet", 0.25)
    cell, height = kw.get("cell", 0.05), kw.get("height", 3.0)
    hist = np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)
    mdr = float(mean_discharge_rate(hist))
    mfi, _, _ = mass_flow_index(str(base) + ".h5", theta, outlet, height)
    import h5py
    with h5py.File(str(base) + ".h5", "r") as f:
        op = outlet_path(frames(f, 3), cell, theta, outlet)
    r = dict(run, mdr=mdr, mdr_full=2 * mdr, mfi=float(mfi), v_out=float(np.nanmean(op[:, 1])),
             rho_out=float(np.nanmean(op[:, 2])), scene=kw)
    return r
