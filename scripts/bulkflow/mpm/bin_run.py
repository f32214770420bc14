"""Run one flat-bottomed bin scene (bin_scene.py) with the solver and reduce it to the thesis ch. 5
figures: discharged mass against time, T_ss, MDR, particle balance, wall time.

Runs are named by a hash of their scene text (and the MPM solver revision of hopper_run.py), so a
study run again reads a finished run back instead of repeating it (`reuse=False` forces a run).

    from bulkflow.mpm.bin_run import run_bin
    r = run_bin(exe, "out/mpm_study/runs", case="eccentric", sand="DS", edge_cells=1)
    r["mdr_bin"], r["t_ss"], r["wall"], r["base"]
"""
import json
import math
import re
import subprocess
import sys
import time

import numpy as np

from .bin_analysis import opening_time, steady_rate, steady_time
from .bin_scene import bin_geometry, bin_scene
from .hopper_run import DEFAULT_EXE, cached_run


def run_bin(exe=DEFAULT_EXE, out_dir="out/mpm_study/runs", reuse=True, label="", **scene):
    """Write, run and reduce one bin scene (`scene`: bin_scene() keywords). Returns a dict: base,
    wall [s], particles (initial), n_out, n_left, mass_error (max |MASS_ERROR| / M0), t_open,
    t_ss [s after opening, None: not reached], t_first_change (discharge_figures), mdr_model (per
    metre of the model), mdr_bin (the whole bin per metre of depth: twice a half model's), the 0.5 s window ends and rates, the geometry
    and the scene keywords."""
    text = bin_scene(**scene)

    def reduce(base, run):
        r = reduce_run(str(base), run["stdout"], scene)
        r.update(digest=run["digest"], wall=run["wall"])
        return r

    return cached_run(exe, out_dir, text, f"bin_{label + '_' if label else ''}", reduce, reuse)


def reduce_run(base, stdout, scene):
    """The figures of a finished run (its history CSV and the solver's summary lines)."""
    hist = np.genfromtxt(base + "_history.csv", delimiter=",", names=True)
    m = re.search(r"particles (\d+) \((\d+) in, (\d+) out\)", stdout)
    n_left, n_out = int(m.group(1)), int(m.group(3))
    kw = {k: scene[k] for k in ("case", "cell", "edge_cells", "outlet", "width", "fill") if k in scene}
    geo = bin_geometry(**kw)
    return dict(base=base, particles=int(hist["particles"][0]), n_out=n_out, n_left=n_left,
                mass_error=float(np.abs(hist["MASS_ERROR"]).max() / hist["MASS"][0]),
                psteps=int(re.search(r"throughput (\d+) particle-steps", stdout).group(1)),
                geometry=geo, scene=scene, **discharge_figures(hist, 2.0 if geo["half"] else 1.0))


def discharge_figures(hist, factor):
    """t_open, T_ss (the end of the steady discharge: the fall > 10 % between 0.5 s windows that
    begins the plateau, bin_analysis.steady_time `plateau`), t_first_change (the first change of
    either sign, the rule of the runs before 2026-12-07; for a drifting rate the two differ), the MDR up to T_ss (model and
    whole bin: `factor` 2 for a half model) and the windows, from a run's history columns."""
    t, mass = hist["time"], hist["MASS_OUT"]
    t_open = opening_time(hist)
    t_ss, ends, rates = steady_time(t, mass, t_open, plateau=True)
    t_any, _, _ = steady_time(t, mass, t_open)
    mdr = steady_rate(t, mass, t_open, t_ss)
    return dict(t_open=t_open, t_ss=t_ss if math.isfinite(t_ss) else None,
                t_first_change=t_any if math.isfinite(t_any) else None, mdr_model=mdr, mdr_bin=factor * mdr,
                window_ends=ends.tolist(), window_rates=(factor * rates).tolist())
