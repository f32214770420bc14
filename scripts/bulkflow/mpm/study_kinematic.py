"""d: vertical velocity across the hopper vs the kinematic model, D vs height (thesis Fig. 4.13)

Study d of the MPM wedge hopper (Table 4.2, the run study c uses: 1 s fill + `--discharge` s with
inflow). In steady discharge (every particle frame from `--skip` s after the outlet opened,
averaged) the downward vertical velocity v = -v_y is binned across the hopper, from the axis to
the wall, in horizontal bands one cell tall at several heights. Each profile is fitted with the
kinematic model (Nedderman & Tuzun; thesis eq. 4.4)

    v(x) = v_c exp(-x^2 / (4 D y))

by theory/kinematic.py fit_diffusion_length (least squares of ln v against x^2), with y the
height above the hopper APEX (the virtual point sink of the wedge: the kinematic model's plane
point-sink solution has its sink there; the thesis does not say where y starts) and x the distance
from the axis. Per height: D, D/y, the fitted v_c against the axis velocity, the fit quality
R^2 = 1 - SS_res/SS_tot of v (linear, not log) and RMS(v - fit)/v_c. Whether D grows with height
(the thesis's observation) is printed: D increasing at every step, and the slope of a straight
line through D(y).

Caveat (physics, not fitting): a self-similar radial flow (v depending on x/y only) gives D
proportional to y, so D growing with height is expected of any converging-hopper flow that is
close to radial; D/y constant would be exactly that.
"""
import csv
import json
import math
from pathlib import Path

import numpy as np

from ..theory.kinematic import fit_diffusion_length, kinematic_velocity
from .study_walker import CASE_DEFAULTS, TABLE_4_2, base_case, frame_time, load_frames

HEIGHTS = [0.25, 0.5, 0.75, 1.0, 1.5, 2.0]      # above the outlet [m]; 2.0 m = 0.67 H


def velocity_profile(groups, y, h, theta, xbin, band=None):
    """Downward vertical velocity across the hopper at height y above the apex, mean over frames.

    Particles with |y_p - y| < band/2 (default band = h: one cell tall) and 0 <= x_p; bins of
    `xbin` in x from the axis. Per bin: mass-weighted mean x (so the bin the wall cuts has the
    x of its material, not its geometric centre), mass-weighted mean v = -v_y, particles per
    frame. Bins beyond the wall (x > y tan theta) get no particles and are dropped."""
    band = h if band is None else band
    x_wall = y * math.tan(math.radians(theta))
    nb = int(math.ceil(x_wall / xbin))
    acc = np.zeros((nb, 4))
    for g in groups:
        x, v, m = g["coordinates"][:], g["V"][:], g["mass"][:]
        sel = (np.abs(x[:, 1] - y) < 0.5 * band) & (x[:, 0] >= 0) & (x[:, 0] < nb * xbin)
        k = np.floor(x[sel, 0] / xbin).astype(int)
        np.add.at(acc, k, np.c_[m[sel] * x[sel, 0], m[sel] * -v[sel, 1], m[sel], np.ones(sel.sum())])
    ok = acc[:, 2] > 0
    return dict(x=acc[ok, 0] / acc[ok, 2], v=acc[ok, 1] / acc[ok, 2], count=acc[ok, 3] / max(len(groups), 1))


def fit_profile(x, v, y):
    """Kinematic-model fit of one profile: dict(D, v_c, r2, rms_over_vc, n). R^2 and the RMS are
    of v itself (the fit is done on ln v, as fit_diffusion_length does)."""
    x, v = np.asarray(x, float), np.asarray(v, float)
    D, vc = fit_diffusion_length(x, v, y)
    fit = kinematic_velocity(x, y, vc, D)
    res = v - fit
    sst = np.sum((v - v.mean()) ** 2)
    return dict(D=float(D), v_c=float(vc), r2=float(1 - np.sum(res ** 2) / sst) if sst > 0 else float("nan"),
                rms_over_vc=float(np.sqrt(np.mean(res ** 2)) / vc), n=int(len(x)))


def wall_distance(x, y, theta):
    """Perpendicular distance from (x, y) to the wall line x = y tan(theta) through the apex."""
    t = math.radians(theta)
    return y * math.sin(t) - np.asarray(x, float) * math.cos(t)


def grows(values):
    """True when every value is larger than the one before."""
    v = np.asarray(values, float)
    return bool(np.all(np.diff(v) > 0))


def add_arguments(p):
    from .studies import add_case_arguments
    add_case_arguments(p, **CASE_DEFAULTS)
    p.add_argument("--heights", type=float, nargs="+", default=HEIGHTS, help="heights above the outlet [m]")
    p.add_argument("--xbin", type=float, default=1.0, help="bin width across the hopper in cells")
    p.add_argument("--wall-gap", type=float, default=1.0,
                   help="bins whose material lies within this many cells of the wall are left out of the fit")


def run(a):
    out = Path(a.out)
    geo = TABLE_4_2
    theta = geo["theta"]
    y0 = 0.5 * geo["outlet"] / math.tan(math.radians(theta))
    r = base_case(a)
    h, fill, dis, f = load_frames(r["base"], a.skip)
    times = [frame_time(g) for g in dis]
    rows, profs = [], []
    for hy in a.heights:
        y = y0 + hy
        p = velocity_profile(dis, y, h, theta, a.xbin * h)
        # the cell the inclined wall cuts carries the node-wall artefact (study_walker doc)
        p["fit"] = wall_distance(p["x"], y, theta) >= a.wall_gap * h
        fit = fit_profile(p["x"][p["fit"]], p["v"][p["fit"]], y)
        fall = fit_profile(p["x"], p["v"], y)
        profs.append((hy, y, p, fit))
        rows.append(dict(height_above_outlet_m=hy, y_above_apex_m=y, half_width_m=y * math.tan(math.radians(theta)),
                         v_axis_data=float(p["v"][0]), D_m=fit["D"], D_over_y=fit["D"] / y, v_c_fit=fit["v_c"],
                         r2=fit["r2"], rms_over_vc=fit["rms_over_vc"], bins=fit["n"],
                         v_wall_over_axis=float(p["v"][-1] / p["v"][0]),
                         D_all_bins_m=fall["D"], r2_all_bins=fall["r2"], rms_over_vc_all_bins=fall["rms_over_vc"]))
    f.close()
    Ds = [q["D_m"] for q in rows]
    ys = [q["y_above_apex_m"] for q in rows]
    slope, icpt = np.polyfit(ys, Ds, 1)
    g = grows(Ds)
    print(f"study d: vertical velocity vs the kinematic model (thesis Fig. 4.13), Table 4.2 hopper, cell {a.cell:g} m, "
          f"run {Path(r['base']).name} ({r['wall']:.0f} s)")
    print(f"steady discharge: mean of {len(times)} frames t = {times[0]:.2f} .. {times[-1]:.2f} s; bands one cell "
          f"tall, x bins {a.xbin:g} cell(s); y above the hopper apex (outlet at y0 = {y0:.4f} m)")
    print(f"{'h above outlet':>14} {'y apex':>7} {'half-w':>7} {'bins':>5} {'v_axis':>7} {'v_c fit':>7} "
          f"{'D [m]':>7} {'D/y':>6} {'R^2':>6} {'RMS/v_c':>8} {'v_wall/v_axis':>13} | {'all bins: D':>11} "
          f"{'R^2':>6} {'RMS/v_c':>8}")
    for q in rows:
        print(f"{q['height_above_outlet_m']:14.3f} {q['y_above_apex_m']:7.3f} {q['half_width_m']:7.3f} {q['bins']:5d} "
              f"{q['v_axis_data']:7.3f} {q['v_c_fit']:7.3f} {q['D_m']:7.4f} {q['D_over_y']:6.3f} {q['r2']:6.3f} "
              f"{q['rms_over_vc']:8.4f} {q['v_wall_over_axis']:13.3f} | {q['D_all_bins_m']:11.4f} "
              f"{q['r2_all_bins']:6.3f} {q['rms_over_vc_all_bins']:8.4f}")
    print(f"D grows with height at every step: {'yes' if g else 'no'}; straight line D = {slope:.4f} y "
          f"{icpt:+.4f} m (dD/dy {slope:.4f})")
    print(f"v: downward velocity [m/s], mass-weighted bin means; fit: ln v vs x^2 (fit_diffusion_length) over the "
          f"bins more than {a.wall_gap:g} cell(s) from the wall (right: every bin); R^2 and RMS of v; "
          "v_wall/v_axis: last bin over first")
    with open(out / "kinematic_profiles.csv", "w", newline="") as fcsv:
        w = csv.writer(fcsv)
        w.writerow(["height_above_outlet_m", "y_above_apex_m", "x_m", "v_down_mpm_m_s", "v_down_fit_m_s",
                    "particles_per_frame", "in_fit"])
        for hy, y, p, fit in profs:
            vf = kinematic_velocity(p["x"], y, fit["v_c"], fit["D"])
            for i in range(len(p["x"])):
                w.writerow([f"{hy:g}", f"{y:.4f}", f"{p['x'][i]:.4f}", f"{p['v'][i]:.5f}", f"{vf[i]:.5f}",
                            f"{p['count'][i]:.2f}", int(p["fit"][i])])
    with open(out / "kinematic_D.csv", "w", newline="") as fcsv:
        w = csv.DictWriter(fcsv, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    summary = dict(study="kinematic", figure="thesis Fig. 4.13", run=r["base"], run_wall_s=r["wall"], cell=a.cell,
                   discharge_s=a.discharge, skip_s=a.skip, frames_t=times, xbin_m=a.xbin * h, band_m=h,
                   y_origin="hopper apex (virtual point sink)", wall_gap_cells=a.wall_gap, rows=rows, D_grows_every_step=g,
                   D_line_slope=float(slope), D_line_intercept_m=float(icpt))
    (out / "kinematic_summary.json").write_text(json.dumps(summary, indent=1))
    plot(profs, rows, slope, icpt, theta, out / "kinematic_profiles.png", a)
    print(f"wrote {out}/kinematic_profiles.csv, kinematic_D.csv, kinematic_summary.json, kinematic_profiles.png")


def plot(profs, rows, slope, icpt, theta, path, a):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.8), gridspec_kw=dict(width_ratios=[1.6, 1]))
    for i, (hy, y, p, fit) in enumerate(profs):
        c = f"C{i}"
        xx = np.linspace(0, y * math.tan(math.radians(theta)), 100)
        axs[0].plot(p["x"][p["fit"]], p["v"][p["fit"]], "o", c=c, ms=4, label=f"{hy:g} m above outlet (y = {y:.2f} m)")
        axs[0].plot(p["x"][~p["fit"]], p["v"][~p["fit"]], "o", c=c, mfc="none", ms=5)
        axs[0].plot(xx, kinematic_velocity(xx, y, fit["v_c"], fit["D"]), "-", c=c, lw=1.2)
    axs[0].set_xlabel("x, distance from the axis [m]")
    axs[0].set_ylabel("downward velocity [m/s]")
    axs[0].set_yscale("log")
    axs[0].set_title("(a) MPM (markers; open: wall cell, not fitted) and v_c exp(-x²/(4Dy)) fits", fontsize=10)
    axs[0].legend(fontsize=8)
    axs[0].grid(alpha=0.3, which="both")
    ys = np.array([q["y_above_apex_m"] for q in rows])
    axs[1].plot(ys, [q["D_m"] for q in rows], "o-", label="fitted D")
    axs[1].plot(ys, slope * ys + icpt, "k:", lw=1, label=f"line, dD/dy = {slope:.3f}")
    for q in rows:
        axs[1].annotate(f"R²={q['r2']:.2f}", (q["y_above_apex_m"], q["D_m"]), fontsize=7,
                        textcoords="offset points", xytext=(4, -10))
    axs[1].set_xlabel("y, height above the hopper apex [m]")
    axs[1].set_ylabel("diffusion length D [m]")
    axs[1].set_title("(b) D vs height", fontsize=10)
    axs[1].grid(alpha=0.3)
    axs[1].legend(fontsize=8)
    fig.suptitle(f"MPM wedge hopper (Table 4.2), cell {a.cell:g} m, steady discharge: kinematic model "
                 "(thesis Fig. 4.13)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
