"""What the bin scene tests (check_bins.py, check_max_dilation.py, check_pic_time.py) share: the
ok/FAIL line of a check, one run of the solver on a scene, and the particle and mass balance of a
bin that empties through its outlet with no inflow."""
import re
import subprocess
import sys
from pathlib import Path

import numpy as np


class Checks:
    """Prints each check's outcome; `failed` lists the ones that did not hold, `finish` exits
    non-zero when any did."""

    def __init__(self):
        self.failed = []

    def __call__(self, ok, what):
        print(("ok    " if ok else "FAIL  ") + what)
        if not ok:
            self.failed.append(what)

    def finish(self, passed="all checks passed"):
        if self.failed:
            sys.exit(f"{len(self.failed)} check(s) failed")
        print(passed)


def run_scene(exe, scene, base):
    """bulkflow on `scene` with outputs at `base`; exits on a failed run. Returns stdout and the
    history (numpy structured array)."""
    Path(base).parent.mkdir(parents=True, exist_ok=True)
    r = subprocess.run([exe, str(scene), "--output", str(base), "--quiet"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.stdout.write(r.stdout)
        sys.stderr.write(r.stderr)
        sys.exit(f"bulkflow failed on {scene} (status {r.returncode})")
    return r.stdout, np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)


def balance(check, name, out, hist):
    """One material, equal particle masses, no inflow: initial particles = out + remaining (the
    summary's counts and the history's last row), the discharged mass is n_out particle masses and
    M0 - MASS_OUT - MASS stays round-off (1e-12 M0)."""
    m = re.search(r"particles (\d+) \((\d+) in, (\d+) out\)", out)
    check(m is not None, f"{name}: summary line with particle counts")
    if m is None:
        return
    nend, nin, nout = (int(v) for v in m.groups())
    n0 = int(hist["particles"][0])
    check(nin == 0 and nout > 0, f"{name}: no inflow, {nout} particles discharged")
    check(n0 == nout + nend == nout + int(hist["particles"][-1]),
          f"{name}: particles {n0} initial = {nout} out + {nend} remaining")
    m0 = hist["MASS"][0]
    mp = m0 / n0
    err = np.abs(hist["MASS_ERROR"]).max()
    check(err <= 1e-12 * m0, f"{name}: max |M0 - MASS_OUT - MASS| = {err:.3e} kg (M0 = {m0:.6g} kg/m)")
    check(abs(hist["MASS_OUT"][-1] - nout * mp) <= 1e-12 * m0,
          f"{name}: MASS_OUT {hist['MASS_OUT'][-1]:.9g} = {nout} x particle mass {mp:.6g}")


def with_controls(text, scene, edit):
    """The scene text with its first *MPM CONTROLS line replaced by edit(line)."""
    controls = re.search(r"^\*MPM CONTROLS[^\n]*$", text, re.M)
    if controls is None:
        sys.exit(f"{scene}: no *MPM CONTROLS line to change")
    return text[:controls.start()] + edit(controls.group(0)) + text[controls.end():]
