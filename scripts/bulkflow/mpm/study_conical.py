"""conical: 3D conical hopper (quarter model): MFI over a theta-phi_w sweep vs Jenike's conical limit

Runs the quarter conical hopper of cone_scene.py (bulkflow-make-cone: a *SURFACE, TYPE=REVOLUTION
wall, symmetry planes x = 0 and z = 0, outlet diameter D at the truncated apex) for every pair of
half angle theta (from the vertical) and wall friction angle phi_w, each a fill and a discharge
without inflow, and reduces each run to:

* MDR of the full hopper: 4 x the regression slope of the discharged mass from `--skip` s after
  the outlet opens to the end (discharge.mean_discharge_rate), against Beverloo's circular-outlet
  form C rho sqrt(g) (D - k d)^(5/2) and Rose-Tanaka's factor (tan theta tan phi_d)^(-0.35)
  (theory/beverloo.py; C = 0.58, d = 0: the continuum has no grain size, rho = the fill's density);
* MFI in 3D (the 2D definition of discharge.py with the wall line replaced by the cone): mean
  vertical velocity of the particles within one cell of the cone (distance normal to it) over the
  mean vertical velocity of the particles within one cell of the axis (r < h), both in the band
  y0 + D .. min(y0 + 0.75 H, y_t) -- the conical section, whose wall Jenike's criterion is about
  (the 2D band y0 + 2b .. y0 + 0.75 H lies in the cylinder for wide cones: at theta = 45 deg it
  gave 0.875, the bin's plug flow) -- pooled over the last `--frames` particle frames; mass flow if
  MFI > 0.3 (theory/flow_mode.py). Computed from the run's frames at every call (not cached);
* where the MFI crosses 0.3 along theta for each phi_w (linear interpolation between the
  bracketing runs, study_flow_mode.mfi_crossings), against Jenike's conical mass-flow limit
  theta_c(delta = phi, phi_w) (theory/flow_mode.conical_mass_flow_limit), in degrees.

CSV/PNG/JSON in --out (conical.csv, conical.json, conical.png); runs are cached in --runs by the
hash of their scene (hopper_run.cached_run) and the wall time of each is kept and printed.
"""
import csv
import json
import math

import numpy as np

from ..theory.beverloo import C_DEFAULT, beverloo_circular, rose_tanaka_factor
from ..theory.flow_mode import MFI_THRESHOLD, classify_mfi, conical_mass_flow_limit
from .cone_scene import add_size_arguments, cone_geometry, cone_scene
from .discharge import mean_discharge_rate
from .hopper_run import DEFAULT_EXE, cached_run
from .study_flow_mode import mfi_crossings

GRAVITY = 9.81


def add_arguments(p):
    add_size_arguments(p)
    p.add_argument("--thetas", type=float, nargs="+", default=[15.0, 30.0, 45.0],
                   help="cone half angles from the vertical [deg]")
    p.add_argument("--phi-ws", type=float, nargs="+", default=[10.0, 20.0], help="wall friction angles [deg]")
    p.add_argument("--fill", type=float, default=0.6, help="fill time [s] (gravity ramp 0.3 s)")
    p.add_argument("--discharge", type=float, default=1.0, help="discharge time [s]")
    p.add_argument("--skip", type=float, default=0.3, help="MDR from this time after opening [s]")
    p.add_argument("--frames", type=int, default=3, help="last particle frames pooled for the MFI")
    p.add_argument("--field-frames", type=int, default=10, help="particle frames per step")
    p.add_argument("--leave-out", dest="skip_cases", nargs="+", default=[], metavar="THETA:PHI_W",
                   help="pairs of the sweep not run (a time budget); reported as left out")


def scene_keywords(a, theta, phi_w):
    return dict(cell=a.cell, theta=theta, wall_friction=phi_w, phi=a.phi, outlet=a.outlet, radius=a.radius,
                height=a.height, fill_time=a.fill, discharge_time=a.discharge, field_frames=a.field_frames)


def cone_mfi(h5path, theta, outlet, radius, height, frames=3):
    """The 3D mass-flow index of a quarter cone run (module doc) and the particle counts it used."""
    import h5py
    y0, y_t = cone_geometry(theta, outlet, radius)
    t = math.radians(theta)
    vw, va = [], []
    with h5py.File(h5path, "r") as f:
        h = float(f["grid"].attrs["h"][0])
        for k in sorted(f["particles"].keys())[-frames:]:
            g = f["particles"][k]
            x, v = g["coordinates"][:], g["V"][:]
            r = np.hypot(x[:, 0], x[:, 2])
            y = x[:, 1]
            d_wall = (y * math.tan(t) - r) * math.cos(t)          # normal to the cone
            band = (y > y0 + outlet) & (y < min(y0 + 0.75 * height, y_t))
            vw.append(v[band & (d_wall < h), 1])
            va.append(v[band & (r < h), 1])
    vw, va = np.concatenate(vw), np.concatenate(va)
    if len(vw) == 0 or len(va) == 0:
        return math.nan, len(vw), len(va)
    return float(vw.mean() / va.mean()), len(vw), len(va)


def run_cone(exe, runs, reuse, a, theta, phi_w):
    kw = scene_keywords(a, theta, phi_w)

    def reduce(base, run):
        hist = np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)
        mdr = 4 * float(mean_discharge_rate(hist, a.skip))
        return dict(run, mdr_full=mdr, mass0=4 * float(hist["MASS"][0]), scene=kw)

    r = cached_run(exe, runs, cone_scene(**kw), "cone_", reduce, reuse)
    r["mfi"], r["n_wall"], r["n_axis"] = cone_mfi(r["base"] + ".h5", theta, a.outlet, a.radius, a.height, a.frames)
    return r


def run(a):
    exe = getattr(a, "bulkflow", DEFAULT_EXE)
    density = 1600.0
    beverloo = beverloo_circular(a.outlet, 0.0, density)
    print(f"conical hopper (quarter model), D {a.outlet:g} m, R {a.radius:g} m, H {a.height:g} m, phi {a.phi:g} deg, "
          f"cell {a.cell:g} m; {a.fill:g} s fill + {a.discharge:g} s discharge", flush=True)
    rows = []
    skipped = {tuple(float(v) for v in c.split(":")) for c in a.skip_cases}
    for phi_w in a.phi_ws:
        for theta in a.thetas:
            if (theta, phi_w) in skipped:
                print(f"  theta {theta:4.1f} phi_w {phi_w:4.1f}: left out (--leave-out)", flush=True)
                continue
            r = run_cone(exe, a.runs, not a.no_reuse, a, theta, phi_w)
            rt = beverloo * rose_tanaka_factor(theta)
            row = dict(theta=theta, phi_w=phi_w, mfi=r["mfi"], mode=classify_mfi(r["mfi"]), n_wall=r["n_wall"],
                       n_axis=r["n_axis"], mdr=r["mdr_full"], beverloo=beverloo, rose_tanaka=rt,
                       mdr_over_beverloo=r["mdr_full"] / beverloo, mdr_over_rose_tanaka=r["mdr_full"] / rt,
                       theta_c_jenike=conical_mass_flow_limit(a.phi, phi_w), particles=r["particles"],
                       wall_s=r["wall"], psteps=r["psteps"], base=r["base"])
            rows.append(row)
            print(f"  theta {theta:4.1f} phi_w {phi_w:4.1f}: MFI {row['mfi']:.3f} ({row['mode']}), MDR "
                  f"{row['mdr']:.2f} kg/s, {r['particles']} particles (quarter), wall {r['wall']:.1f} s", flush=True)
    print(f"\n{'theta':>6} {'phi_w':>6} {'MFI':>6} {'mode':>7} {'n_w/n_a':>9} {'MDR kg/s':>9} {'/Bev':>6} "
          f"{'/R-T':>6} {'th_c Jenike':>11} {'particles':>9} {'wall s':>7}")
    for r in rows:
        print(f"{r['theta']:6.1f} {r['phi_w']:6.1f} {r['mfi']:6.3f} {r['mode']:>7} {r['n_wall']:4d}/{r['n_axis']:<4d} "
              f"{r['mdr']:9.2f} {r['mdr_over_beverloo']:6.3f} {r['mdr_over_rose_tanaka']:6.3f} "
              f"{r['theta_c_jenike']:11.1f} {r['particles']:9d} {r['wall_s']:7.1f}")
    print(f"MDR: full hopper (4 x the quarter); Beverloo C rho sqrt(g) D^2.5 = {beverloo:.2f} kg/s (C {C_DEFAULT}, "
          f"rho {density:g}, k d = 0); R-T: Beverloo x (tan theta)^-0.35 (theta < 45 deg); th_c Jenike: conical "
          f"mass-flow limit for delta = phi = {a.phi:g} deg; wall s: wall time of the run")
    transitions = []
    print(f"\nMFI = {MFI_THRESHOLD} along theta (linear interpolation) against Jenike's conical limit:")
    for phi_w in a.phi_ws:
        g = sorted((r for r in rows if r["phi_w"] == phi_w), key=lambda r: r["theta"])
        tc = conical_mass_flow_limit(a.phi, phi_w)
        if not g:
            continue
        cross = mfi_crossings([r["theta"] for r in g], [r["mfi"] for r in g])
        if cross:
            for c in cross:
                print(f"  phi_w {phi_w:g}: MPM {c['x']:.1f} deg (between {c['lo']:g} and {c['hi']:g}, MFI "
                      f"{c['direction']}), Jenike {tc:.1f} deg: difference {c['x'] - tc:+.1f} deg")
                transitions.append(dict(phi_w=phi_w, theta_mpm=c["x"], lo=c["lo"], hi=c["hi"],
                                        direction=c["direction"], theta_jenike=tc, difference=c["x"] - tc))
        else:
            m = [r["mfi"] for r in g]
            side = "mass flow" if min(m) > MFI_THRESHOLD else "funnel flow" if max(m) < MFI_THRESHOLD else "mixed"
            print(f"  phi_w {phi_w:g}: no crossing in theta {g[0]['theta']:g}..{g[-1]['theta']:g} deg ({side} "
                  f"throughout, MFI {min(m):.3f}..{max(m):.3f}), Jenike {tc:.1f} deg")
            transitions.append(dict(phi_w=phi_w, theta_mpm=None, lo=g[0]["theta"], hi=g[-1]["theta"],
                                    direction=side, theta_jenike=tc, difference=None))
    out = a.out
    cols = list(rows[0])
    with open(f"{out}/conical.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        w.writerows(rows)
    with open(f"{out}/conical.json", "w") as f:
        json.dump(dict(skipped=sorted(skipped), cell=a.cell, outlet=a.outlet, radius=a.radius, height=a.height, phi=a.phi, fill=a.fill,
                       discharge=a.discharge, skip=a.skip, frames=a.frames, threshold=MFI_THRESHOLD,
                       beverloo=dict(C=C_DEFAULT, rho=density, kd=0.0, mdr=beverloo), rows=rows,
                       transitions=transitions), f, indent=1)
    _plot(rows, transitions, a, beverloo, f"{out}/conical.png")
    print(f"\nwritten: {out}/conical.csv, conical.json, conical.png")


def _plot(rows, transitions, a, beverloo, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(16, 5))
    for j, phi_w in enumerate(a.phi_ws):
        g = sorted((r for r in rows if r["phi_w"] == phi_w), key=lambda r: r["theta"])
        c = f"C{j}"
        ax[0].plot([r["theta"] for r in g], [r["mfi"] for r in g], "o-", c=c, label=f"MPM, phi_w = {phi_w:g}")
        ax[0].axvline(conical_mass_flow_limit(a.phi, phi_w), c=c, ls="--", lw=1,
                      label=f"Jenike conical limit, phi_w = {phi_w:g}")
        ax[2].plot([r["theta"] for r in g], [r["mdr"] for r in g], "o-", c=c, label=f"MPM, phi_w = {phi_w:g}")
    ax[0].axhline(MFI_THRESHOLD, c="r", ls=":", label="MFI = 0.3")
    ax[0].set_xlabel("cone half angle theta [deg]")
    ax[0].set_ylabel("mass-flow index [-]")
    ax[0].legend(fontsize=7)
    ax[0].grid(alpha=0.3)
    q = ax[1]
    wf = np.linspace(0.0, a.phi, 200)
    q.plot([conical_mass_flow_limit(a.phi, w) for w in wf], wf, "k-", label=f"Jenike conical limit, delta = {a.phi:g}")
    for r in rows:
        mass = r["mode"] == "mass"
        q.plot(r["theta"], r["phi_w"], "o", ms=8, c="C0" if mass else "C3", mfc="C0" if mass else "none")
        q.annotate(f"{r['mfi']:.2f}", (r["theta"], r["phi_w"]), xytext=(5, 4), textcoords="offset points", fontsize=7)
    for t in transitions:
        if t["theta_mpm"] is not None:
            q.plot(t["theta_mpm"], t["phi_w"], "k*", ms=11)
    q.plot([], [], "o", c="C0", label="MPM mass flow (MFI > 0.3)")
    q.plot([], [], "o", c="C3", mfc="none", label="MPM funnel flow")
    q.plot([], [], "k*", label="MPM transition (interpolated)")
    q.set_xlim(0, 70)
    q.set_ylim(0, a.phi + 2)
    q.set_xlabel("cone half angle theta [deg]")
    q.set_ylabel("wall friction angle phi_w [deg]")
    q.legend(fontsize=7)
    q.grid(alpha=0.3)
    th = np.linspace(min(a.thetas), max(a.thetas), 100)
    ax[2].plot(th, [beverloo * rose_tanaka_factor(t) for t in th], "k--", label="Rose-Tanaka (C 0.58, k d = 0)")
    ax[2].axhline(beverloo, c="k", ls=":", label="Beverloo, circular outlet")
    ax[2].set_xlabel("cone half angle theta [deg]")
    ax[2].set_ylabel("mass discharge rate, full hopper [kg/s]")
    ax[2].legend(fontsize=7)
    ax[2].grid(alpha=0.3)
    fig.suptitle(f"MPM conical hopper (quarter model), D {a.outlet:g} m, R {a.radius:g} m, H {a.height:g} m, "
                 f"phi {a.phi:g} deg, cell {a.cell:g} m", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
