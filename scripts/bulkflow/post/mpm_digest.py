"""Digest of an MPM hopper discharge: the mass discharge rate (MDR) against time beside Beverloo and
Rose–Tanaka, and two lines — the steady MDR with the theories' values and their ratios, and the
flow mode (mass or funnel flow by the mass-flow index).

    bulkflow-mpm-digest BASE --scene SCENE.inp [-o BASE_mdr.png] [--json BASE_digest.json]
        [--skip 0.5] [--window 0.2] [--C 0.58]

Figures as the thesis ch. 4 studies compute them (bulkflow.mpm.discharge): the steady MDR is the
regression slope of the discharged mass (history MASS_OUT) from `--skip` s after the outlet opens
to the end of the run; the plateau is checked on windows of `--window` s (their spread about the
steady MDR, their trend, and T_ss: the end of the last window before one that differs by more than
10 % from the mean of those before it). MFI = mean vertical velocity of the particles within one
cell of the inclined wall / within one cell of the axis, heights y0 + 2b .. y0 + 0.75 H, last
frame (discharge.mass_flow_index); mass flow if MFI > 0.3 (theory.flow_mode); the MFI of the last
three frames is printed as its noise.

The theories (bulkflow.theory.beverloo, thesis eqs. 1.4–1.7) for the long slot of width b (per
metre of its length), with ρ_i the bulk density of the fill before the outlet opens (Σm/ΣV of the
particles in the last frame of the fill step), C = 0.58 (the usual 0.55–0.65; the thesis gives no
value) and d = 0 (a continuum has no particle diameter, so no empty annulus k d). A half model
(a vertical symmetry wall) is doubled: every rate is the full hopper's, in kg/s per metre of depth.
θ, b and y0 come from the scene's walls (bulkflow.post.mpm_scene), the fill height H from the
first frame.
"""
from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

from bulkflow.mpm.discharge import discharge_rate, mass_flow_index, mean_discharge_rate
from bulkflow.mpm.study_flow_mode import frame_mfis
from bulkflow.post.mpm_scene import hopper_geometry, read_mpm_scene
from bulkflow.post.run_output import read_history
from bulkflow.theory.beverloo import C_DEFAULT, beverloo_rect, rose_tanaka_rect
from bulkflow.theory.flow_mode import MFI_THRESHOLD, classify_mfi

SLOT_LENGTH = 1.0e6     # long-slot limit of beverloo_rect, divided out again (per metre of slot)


def _frames_info(h5_path, n_last=3):
    """From the particle frames: the top of the first frame (the fill height), Σm/ΣV of the last
    frame of step 1 (the fill's bulk density) and (key, time) of the last n frames."""
    import h5py
    with h5py.File(h5_path, "r") as f:
        keys = sorted(f["particles"].keys())
        first = f["particles"][keys[0]]
        ymax = float(first["coordinates"][:, 1].max())
        fill = [k for k in keys if int(f["particles"][k].attrs["step"][0]) == 1] or keys[:1]
        g = f["particles"][fill[-1]]
        rho_fill = float(g["mass"][:].sum() / g["volume"][:].sum())
        last = [(k, float(f["particles"][k].attrs["total_time"][0])) for k in keys[-n_last:]]
    return ymax, rho_fill, last


def digest(base, scene_path, skip=0.5, window=0.2, C=C_DEFAULT):
    """The figures of the digest as a dict (rates in kg/s per metre depth of the full hopper)."""
    scene = read_mpm_scene(scene_path)
    geo = hopper_geometry(scene)
    if geo is None:
        raise SystemExit(f"{scene_path}: no wedge hopper found (a horizontal *MPM WALL deleted in a "
                         "later step, and an inclined wall starting at its end)")
    theta, b, y0 = geo["theta"], geo["outlet"], geo["y0"]
    full = 2.0 if scene.symmetry_x() is not None else 1.0
    hist = read_history(f"{base}_history.csv")
    if "MASS_OUT" not in hist:
        raise SystemExit(f"{base}_history.csv: no MASS_OUT column (does the scene have *OUTFLOW?)")
    ymax, rho_fill, last = _frames_info(f"{base}.h5")
    height = ymax - y0
    mdr_half = float(mean_discharge_rate(hist, skip))
    _, t_ss, opened, rates, edges = discharge_rate(hist, skip, window)
    mdr = full * mdr_half
    rates = full * np.asarray(rates)
    end = float(hist["time"][-1])
    spread = float(np.max(np.abs(rates / mdr - 1.0))) if len(rates) and mdr > 0 else math.nan
    if len(rates) >= 3:
        mid = 0.5 * (edges[1:] + edges[:-1])
        trend = float(np.polyfit(mid, rates, 1)[0] / mdr)
    else:
        trend = math.nan
    beverloo = beverloo_rect(b, SLOT_LENGTH, 0.0, rho_fill, C) / SLOT_LENGTH
    rose_tanaka = rose_tanaka_rect(b, SLOT_LENGTH, 0.0, rho_fill, theta, C) / SLOT_LENGTH
    mfi, n_wall, n_axis = mass_flow_index(f"{base}.h5", theta, b, height)
    mfis = frame_mfis(f"{base}.h5", theta, b, height, n=len(last))
    return dict(mdr=mdr, mdr_from=skip, opened=float(opened), end=end, discharge=end - opened,
                window=window, window_rates=rates.tolist(), window_edges=list(map(float, edges)),
                spread=spread, trend_per_s=trend, t_ss=float(t_ss), steady=bool(t_ss >= end - opened - 1e-9),
                beverloo=beverloo, rose_tanaka=rose_tanaka, ratio_beverloo=mdr / beverloo,
                ratio_rose_tanaka=mdr / rose_tanaka, rho_fill=rho_fill, C=C, theta=theta, outlet=b,
                y0=y0, height=height, full_factor=full, mfi=float(mfi), mfi_wall=int(n_wall),
                mfi_axis=int(n_axis), mfi_last_frames=mfis, mfi_time=last[-1][1],
                flow_mode=classify_mfi(mfi), mass_out=full * float(hist["MASS_OUT"][-1]))


def digest_lines(d):
    """The two lines printed at the end of the main job."""
    plateau = (f"{d['window']:g} s windows within ±{100 * d['spread']:.0f} %, trend "
               f"{100 * d['trend_per_s']:+.1f} %/s" if math.isfinite(d["spread"]) else "too short for windows")
    if not d["steady"]:
        plateau += f"; NOT steady: a window departs by > 10 % at {d['t_ss']:.2f} s after opening"
    if not math.isfinite(d["mdr"]):
        line1 = (f"steady MDR: not measured (the discharge lasted {d['discharge']:.2f} s; the steady rate is "
                 f"taken from {d['mdr_from']:g} s after opening, --skip); Beverloo {d['beverloo']:.0f}, "
                 f"Rose–Tanaka {d['rose_tanaka']:.0f} kg/s/m")
    else:
        line1 = (f"steady MDR {d['mdr']:.0f} kg/s/m (full hopper, {d['mdr_from']:g}–{d['discharge']:.2f} s after "
                 f"opening; {plateau}); Beverloo {d['beverloo']:.0f}, Rose–Tanaka {d['rose_tanaka']:.0f} kg/s/m "
                 f"(b {d['outlet']:g} m, θ {d['theta']:.0f}°, ρ_i {d['rho_fill']:.0f} kg/m³, C {d['C']:g}, d = 0): "
                 f"MPM/Beverloo {d['ratio_beverloo']:.2f}, MPM/Rose–Tanaka {d['ratio_rose_tanaka']:.2f}")
    last = " ".join(f"{m:.2f}" for m in d["mfi_last_frames"])
    line2 = (f"flow mode: {d['flow_mode']} flow, MFI {d['mfi']:.2f} {'>' if d['mfi'] > MFI_THRESHOLD else '≤'} "
             f"{MFI_THRESHOLD:g} (wall/axis vertical velocity, {d['mfi_wall']}/{d['mfi_axis']} particles, frame at "
             f"t = {d['mfi_time']:.2f} s; last 3 frames {last})")
    return line1, line2


def plot_mdr(base, d, output):
    """MDR against time (0.05 s and the digest's windows) with the steady MDR and the theories;
    beside it the discharged mass with the regression line of the steady MDR."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    hist = read_history(f"{base}_history.csv")
    t, mass = hist["time"], d["full_factor"] * hist["MASS_OUT"]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    fine = np.arange(d["opened"], t[-1] + 1e-12, 0.05)
    if len(fine) > 1:
        r = np.diff(np.interp(fine, t, mass)) / np.diff(fine)
        ax[0].plot(0.5 * (fine[1:] + fine[:-1]), r, c="0.6", lw=1, label="MPM, 0.05 s")
    if d["window_rates"]:
        e = d["window_edges"]
        ax[0].stairs(d["window_rates"], e, baseline=None, color="C0", lw=2, label=f"MPM, {d['window']:g} s windows")
    t0 = d["opened"] + d["mdr_from"]
    ax[0].hlines(d["mdr"], t0, t[-1], colors="C0", linestyles="-", lw=1,
                 label=f"steady MDR {d['mdr']:.0f}")
    ax[0].axhline(d["beverloo"], c="C3", ls="--", label=f"Beverloo {d['beverloo']:.0f}")
    ax[0].axhline(d["rose_tanaka"], c="C2", ls="-.", label=f"Rose–Tanaka {d['rose_tanaka']:.0f}")
    ax[0].axvline(d["opened"], c="k", lw=0.8, ls=":")
    ax[0].annotate("outlet opens", (d["opened"], 0), xytext=(3, 3), textcoords="offset points", fontsize=8)
    ax[0].set_xlim(t[0], t[-1])
    ax[0].set_ylim(bottom=0)
    ax[0].set_xlabel("t [s]")
    ax[0].set_ylabel("mass discharge rate [kg/s per m depth]")
    ax[0].legend(fontsize=8, loc="upper left")
    ax[0].set_title(f"MDR (full hopper), MFI {d['mfi']:.2f}: {d['flow_mode']} flow", fontsize=10)
    ax[1].plot(t, mass, c="C0", label="discharged mass")
    m0 = np.interp(t0, t, mass)
    tt = np.array([t0, t[-1]])
    ax[1].plot(tt, m0 + d["mdr"] * (tt - t0), c="k", ls="--", lw=1, label="steady MDR (regression)")
    ax[1].set_xlabel("t [s]")
    ax[1].set_ylabel("discharged mass [kg per m depth]")
    ax[1].legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(output, dpi=110)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("base", help="output base of the run (BASE_history.csv, BASE.h5)")
    p.add_argument("--scene", required=True, help="the scene of the run (walls: θ, b, y0)")
    p.add_argument("-o", "--plot", help="MDR plot (PNG)")
    p.add_argument("--json", help="write the figures as JSON")
    p.add_argument("--skip", type=float, default=0.5, help="steady MDR from this many s after opening")
    p.add_argument("--window", type=float, default=0.2, help="window of the plateau check [s]")
    p.add_argument("--C", type=float, default=C_DEFAULT, help="Beverloo's C")
    a = p.parse_args(argv)
    d = digest(a.base, a.scene, a.skip, a.window, a.C)
    if a.plot:
        plot_mdr(a.base, d, a.plot)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(d, f, indent=1)
    for line in digest_lines(d):
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
