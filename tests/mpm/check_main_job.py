#!/usr/bin/env python3
"""The main job's MPM post-processing (scripts/run_default.sh) on a tiny hopper, in seconds.

    check_main_job.py --bulkflow BIN --workdir DIR [--mpiexec MPIEXEC --ranks N]

A short version of inputs/demo/wedge_hopper_mpm_discharge.inp from the same generator: the same
θ = 30°, b = 0.25 m, Table 4.2 material and cell 0.05 m, but H = 1 m, 0.3 s fill and 0.5 s
discharge without inflow (about 4 400 increments of 660 particles). The solver runs it, then the two
commands run_default.sh calls on it, as run_default.sh calls them:
- bulkflow-mpm-movie: the GIF exists, is a GIF, and holds one picture per particle frame;
- bulkflow-mpm-digest: the MDR plot exists (PNG), exactly two lines are printed, and the figures
  are finite and sensible: the steady MDR > 0 and within a factor 3 of Beverloo and Rose–Tanaka
  (the MPM hopper runs 1.1–1.8 × Beverloo at the converged cells), Rose–Tanaka / Beverloo =
  (tan 30°)^-0.35, the discharged mass = the history's MASS_OUT doubled, an MFI in (0, 1.5) with
  its mode, ρ_i within 2 % of the scene's 1600 kg/m³, the fill height 1 m within a cell.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "scripts"))

from bulkflow.mpm.hopper_scene import hopper_scene  # noqa: E402

failures = []


def check(ok, what):
    print(f"  {'OK  ' if ok else 'FAIL'} {what}")
    if not ok:
        failures.append(what)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bulkflow", required=True)
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--mpiexec")
    ap.add_argument("--ranks", type=int, default=1)
    a = ap.parse_args()
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    scene = work / "tiny_hopper_mpm.inp"
    scene.write_text(hopper_scene(cell=0.05, ppc=2, height=1.0, fill_time=0.3, ramp=0.2,
                                  discharge_time=0.5, inflow=False, field_frames=3,
                                  discharge_frames=8, history_dt=0.01, title="tiny main-job hopper"))
    base = work / "tiny"
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               PYTHONPATH=str(REPO / "scripts"), MPLBACKEND="Agg")
    cmd = [a.bulkflow, str(scene), "--output", str(base), "--quiet"]
    if a.ranks > 1:
        cmd = [a.mpiexec or "mpirun", "-np", str(a.ranks), "--oversubscribe"] + cmd
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if r.returncode != 0:
        print(r.stdout[-3000:], r.stderr[-3000:])
        print("FAIL: the solver run failed")
        return 1

    gif, png, js = work / "tiny.gif", work / "tiny_mdr.png", work / "tiny_digest.json"
    for f in (gif, png, js):
        f.unlink(missing_ok=True)
    py = sys.executable
    r = subprocess.run([py, "-m", "bulkflow.post.mpm_movie", str(base), "--scene", str(scene), "-o", str(gif),
                        "--dpi", "40"], capture_output=True, text=True, env=env)
    print(r.stdout, r.stderr[-2000:], end="")
    check(r.returncode == 0, "bulkflow-mpm-movie exit status 0")
    import h5py
    with h5py.File(f"{base}.h5", "r") as f:
        n_frames = len(f["particles"])
    check(gif.exists() and gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a"), f"{gif.name} is a GIF")
    if gif.exists():
        from PIL import Image
        with Image.open(gif) as im:
            check(im.n_frames == n_frames, f"GIF pictures {im.n_frames} = particle frames {n_frames}")

    r = subprocess.run([py, "-m", "bulkflow.post.mpm_digest", str(base), "--scene", str(scene), "-o", str(png),
                        "--json", str(js), "--skip", "0.15", "--window", "0.1"],
                       capture_output=True, text=True, env=env)
    print(r.stdout, r.stderr[-2000:], end="")
    check(r.returncode == 0, "bulkflow-mpm-digest exit status 0")
    lines = r.stdout.strip().splitlines()
    check(len(lines) == 2 and lines[0].startswith("steady MDR") and lines[1].startswith("flow mode:"),
          "the digest is two lines: steady MDR, flow mode")
    check(png.exists() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f"{png.name} is a PNG")
    if not js.exists():
        check(False, "digest JSON written")
    else:
        d = json.loads(js.read_text())
        finite = all(math.isfinite(d[k]) for k in ("mdr", "beverloo", "rose_tanaka", "ratio_beverloo",
                                                    "ratio_rose_tanaka", "mfi", "rho_fill", "spread"))
        check(finite, "MDR, theories, ratios, MFI, density, spread finite")
        check(d["mdr"] > 0 and 1 / 3 < d["ratio_beverloo"] < 3 and 1 / 3 < d["ratio_rose_tanaka"] < 3,
              f"MDR {d['mdr']:.0f} kg/s/m within a factor 3 of Beverloo {d['beverloo']:.0f} "
              f"and Rose-Tanaka {d['rose_tanaka']:.0f}")
        check(abs(d["rose_tanaka"] / d["beverloo"] - math.tan(math.radians(30)) ** -0.35) < 1e-9,
              "Rose-Tanaka / Beverloo = (tan 30 deg)^-0.35")
        check(abs(d["theta"] - 30) < 1e-6 and abs(d["outlet"] - 0.25) < 1e-9 and d["full_factor"] == 2.0,
              "geometry from the walls: theta 30 deg, b 0.25 m, half model doubled")
        check(abs(d["height"] - 1.0) < 0.05, f"fill height {d['height']:.3f} m = 1 m within a cell")
        check(abs(d["rho_fill"] / 1600 - 1) < 0.02, f"rho_i {d['rho_fill']:.1f} kg/m3 within 2 % of 1600")
        import numpy as np
        hist = np.genfromtxt(f"{base}_history.csv", delimiter=",", names=True)
        check(abs(d["mass_out"] - 2 * hist["MASS_OUT"][-1]) < 1e-9 * max(1.0, d["mass_out"]) and d["mass_out"] > 0,
              f"discharged mass {d['mass_out']:.1f} kg/m = 2 x MASS_OUT")
        check(0 < d["mfi"] < 1.5 and d["flow_mode"] == ("mass" if d["mfi"] > 0.3 else "funnel"),
              f"MFI {d['mfi']:.3f} and its mode ({d['flow_mode']})")
        check(len(d["mfi_last_frames"]) == 3 and abs(d["mfi_last_frames"][-1] - d["mfi"]) < 1e-12,
              "MFI of the last 3 frames, the last one the digest's")
    for f in failures:
        print("FAIL:", f)
    print("OK" if not failures else f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
