"""bins: flat-bottomed bins of thesis ch. 5: T_ss and MDR (Table 5.4-style), free surface, velocity

Thesis ch. 5: a quasi-2D flat-bottomed bin (outlet 11.8 mm, width ~172 mm, fill 200 mm) emptied
through a concentric or an eccentric outlet, ASTM C778 20-30 sand as NDNS (phi = 34 deg, psi = 0)
and DS (phi 46 -> 34 deg, psi 15 -> 0 over eps_cv = ln(eta_i/eta_cv)), Table 5.3. Runs: concentric
and eccentric x NDNS and DS (bin_scene.py, 2D plane strain, per metre of depth), and with
`--variants` the eccentric NDNS bin with a 34 deg right wall and the NDNS bins at rho_i = 1600.
Figures (bin_analysis.py has the definitions; docs/bins.md discusses them):
- table: T_ss (the > 10 % fall of the 0.5 s instantaneous MDR that begins the plateau, §5.5.2;
  the first change of either sign beside it) and the MDR (regression
  of the discharged mass up to T_ss) of the whole bin per metre of depth, Beverloo's slot MDR per
  metre (rho_i, C = 0.64 and 0.58, k = 1.5, d = 0.71 mm: theory/beverloo.py) and the ratio, the
  particle balance and the wall time of each run -> bins_table.csv/.json;
- MDR against time (0.1 s windows and the 0.5 s T_ss windows) with Beverloo -> bins_mdr.png;
- free surface profiles at `--surface-times` with their shape (convex/linear/concave) and, for
  the eccentric bin, its two slopes -> bins_surface.csv/.png;
- time-averaged vertical velocity along y = 10, 40, 70 mm (`--heights`) from `--avg-from` s after
  opening until T_ss (the run's end if T_ss is less than 0.5 s after that start) or until the
  lowest point of the free surface comes within 2 cells of the height -> bins_velocity.csv/.png.
"""
import csv
import json
import math

import numpy as np

from . import bin_analysis as BA
from .bin_scene import D_PARTICLE, OUTLET, RHO_I, YOUNG

CASES = (("concentric", "NDNS"), ("concentric", "DS"), ("eccentric", "NDNS"), ("eccentric", "DS"))
VARIANTS = ((("eccentric", "NDNS"), dict(right_wall_friction=34.0), "right wall 34 deg"),
            (("concentric", "NDNS"), dict(density=1600.0), "rho_i 1600"),
            (("eccentric", "NDNS"), dict(density=1600.0), "rho_i 1600"))
BEVERLOO_K = 1.5          # thesis eq. 1.5, spheres (Nedderman)
SLOT_LENGTH = 1.0e3       # m: Beverloo's rectangle this long, per metre, is the long-slot limit


def add_arguments(p):
    p.add_argument("--edge-cells", type=int, default=1, help="k: cell = outlet / (2k + 1)")
    p.add_argument("--ppc", type=int, default=2, help="particles per cell direction")
    p.add_argument("--discharge", type=float, default=8.0, help="discharge time [s] after the fill")
    p.add_argument("--fill-time", type=float, default=0.3, help="fill (settling) step [s]")
    p.add_argument("--young", type=float, default=YOUNG,
                   help="Young's modulus [Pa] (Table 5.3: 8 MPa; lower: larger stable increment)")
    p.add_argument("--max-dilation", type=float, default=0.0, metavar="J",
                   help="*MPM CONTROLS, MAX DILATION=J in every run (0: off; docs/bins.md)")
    p.add_argument("--pic-time", type=float, default=0.01, metavar="TAU",
                   help="*MPM CONTROLS, PIC TIME=TAU [s] in every run: the PIC/FLIP blend as a rate, "
                        "the discharge independent of E and the increment (0: the fixed FLIP=0.99 of the "
                        "runs before 2026-12-06; docs/bins.md)")
    p.add_argument("--open-edge", action="store_true",
                   help="the floor and the outlet plate hold the particles at the outlet's edge, not the grid "
                        "nodes whose support reaches into the opening (*MPM WALL, OPEN=; docs/accuracy.md)")
    p.add_argument("--variants", action="store_true", help="also the 34 deg right wall and rho_i = 1600 runs")
    p.add_argument("--cases", nargs="+",
                   help="only these, e.g. concentric:NDNS eccentric:DS:4 (a third field: its own discharge time [s])")
    p.add_argument("--surface-times", type=float, nargs="+", default=[0.5, 1.0, 2.5, 4.0, 6.0],
                   help="s after opening")
    p.add_argument("--heights", type=float, nargs="+", default=[0.010, 0.040, 0.070], help="m above the outlet")
    p.add_argument("--avg-from", type=float, default=1.0, help="velocity averaging starts [s after opening]")


def beverloo_per_metre(rho, C, outlet=OUTLET):
    """Beverloo's MDR of a long slot per metre of its length (kg/s/m), eqs. 1.4-1.6."""
    from ..theory.beverloo import beverloo_rect
    return beverloo_rect(outlet, SLOT_LENGTH, D_PARTICLE, rho, C=C, k=BEVERLOO_K) / SLOT_LENGTH


def _runs(a):
    from .bin_run import discharge_figures, run_bin
    todo = [(c, s, {}, "") for c, s in CASES]
    if a.cases:
        todo = []
        for item in a.cases:
            f = item.split(":")
            if len(f) not in (2, 3) or f[0] not in ("concentric", "eccentric") or f[1] not in ("NDNS", "DS"):
                raise SystemExit(f"--cases {item}: expected concentric|eccentric:NDNS|DS[:discharge seconds]")
            todo.append((f[0], f[1], dict(discharge_time=float(f[2])) if len(f) == 3 else {}, ""))
    if a.variants:
        todo += [(c, s, kw, lab) for (c, s), kw, lab in VARIANTS]
    rows = []
    for case, sand, kw, lab in todo:
        scene = dict(case=case, sand=sand, edge_cells=a.edge_cells, ppc=a.ppc, discharge_time=a.discharge,
                     fill_time=a.fill_time, young=a.young, max_dilation=a.max_dilation,
                     pic_time=a.pic_time)
        if a.open_edge:
            scene["open_edge"] = True
        scene.update(kw)
        r = run_bin(a.bulkflow, a.runs, reuse=not a.no_reuse, **scene)
        # the figures from the history, not the cached record: runs made before the plateau rule
        # for T_ss (2026-12-07) keep the old rule's t_ss in their .json
        hist = np.genfromtxt(r["base"] + "_history.csv", delimiter=",", names=True)
        r.update(discharge_figures(hist, 2.0 if r["geometry"]["half"] else 1.0))
        r["label"] = f"{case} {sand}" + (f", {lab}" if lab else "")
        print(f"  {r['label']}: {r['particles']} particles, wall {r['wall']:.0f} s", flush=True)
        rows.append(r)
    return rows


def _surfaces(r, frames, times):
    geo = r["geometry"]
    h = geo["cell"]
    out = []
    for ts in times:
        near = min(frames, key=lambda f: abs(f[0] - ts))
        if abs(near[0] - ts) > 0.051:
            continue
        xs, ys = BA.surface_profile(near[1][:, 0], near[1][:, 1], geo["x_left"], geo["x_right"], h)
        item = dict(t=near[0], x=xs.tolist(), y=ys.tolist())
        if geo["half"]:
            item["shape"], item["bulge"] = BA.surface_shape(xs, ys, min_rise=2 * h)
        else:
            # leave the column at each wall and the outlet's columns out of the line fits
            keep = (xs > geo["x_left"] + h) & (xs < geo["x_out0"])
            item.update(BA.two_slopes(xs[keep], ys[keep]))
            item["shape"], item["bulge"] = BA.surface_shape(xs[keep][::-1], ys[keep][::-1], min_rise=2 * h)
        out.append(item)
    return out


def _velocities(r, frames, heights, avg_from):
    geo = r["geometry"]
    h = geo["cell"]
    # a T_ss less than 0.5 s after the averaging start leaves too few frames: then the run's end
    t_ss = r["t_ss"]
    t_end = t_ss if t_ss is not None and t_ss >= avg_from + 0.5 else frames[-1][0]
    profiles = []
    for H in heights:
        used = []
        for t, x, v, m in frames:
            if t < avg_from - 1e-9 or t > t_end + 1e-9:
                continue
            _, top = BA.surface_profile(x[:, 0], x[:, 1], geo["x_left"], geo["x_right"], h)
            if np.nanmin(top) < H + 2 * h:
                break
            used.append((x, v, m))
        # columns one particle spacing wide: every column of the lattice holds a particle
        dx = h / r["scene"].get("ppc", 2)
        xs, vy = BA.velocity_profile(used, H, h, geo["x_left"], geo["x_right"], dx)
        profiles.append(dict(height=H, frames=len(used), x=xs.tolist(), v=vy.tolist()))
    return profiles


def run(a):
    print(f"flat-bottomed bins (thesis ch. 5): outlet {OUTLET * 1e3:g} mm, cell outlet/{2 * a.edge_cells + 1}, "
          f"PPC {a.ppc}, E {a.young / 1e6:g} MPa, fill {a.fill_time:g} s + discharge {a.discharge:g} s (or the case's own)"
          + (f", MAX DILATION {a.max_dilation:g}" if a.max_dilation > 0 else "")
          + (f", PIC TIME {a.pic_time:g} s" if a.pic_time > 0 else "")
          + (", outlet edge open (OPEN=)" if a.open_edge else ""), flush=True)
    rows = _runs(a)
    bev = {C: beverloo_per_metre(RHO_I, C) for C in (0.64, 0.58)}
    table = []
    for r in rows:
        frames = BA.read_frames(r["base"] + ".h5", r["t_open"])
        r["surfaces"] = _surfaces(r, frames, a.surface_times)
        r["velocity"] = _velocities(r, frames, a.heights, a.avg_from)
        rho = r["scene"].get("density", RHO_I)
        b64 = beverloo_per_metre(rho, 0.64)
        table.append(dict(bin=r["label"], cell_mm=1e3 * r["geometry"]["cell"], particles=r["particles"],
                          wall_s=round(r["wall"], 1), t_ss_s=r["t_ss"], t_first_change_s=r["t_first_change"],
                          mdr_kg_s_m=r["mdr_bin"],
                          beverloo_064=b64, mdr_over_beverloo_064=r["mdr_bin"] / b64,
                          mdr_last_window=r["window_rates"][-1] if r["window_rates"] else float("nan"),
                          n_out=r["n_out"], n_left=r["n_left"], mass_error_rel=r["mass_error"]))
    print(f"\n{'bin':<34} {'cell mm':>7} {'particles':>9} {'wall s':>7} {'T_ss s':>7} {'1st chg':>7} "
          f"{'MDR kg/s/m':>10} {'Bev.0.64':>8} {'MDR/Bev':>7} {'last 0.5s':>9}  balance")
    for t in table:
        tss, chg = (f"{v:7.2f}" if v is not None else "    n/r" for v in (t["t_ss_s"], t["t_first_change_s"]))
        print(f"{t['bin']:<34} {t['cell_mm']:7.3f} {t['particles']:9d} {t['wall_s']:7.1f} {tss} {chg} "
              f"{t['mdr_kg_s_m']:10.3f} {t['beverloo_064']:8.3f} {t['mdr_over_beverloo_064']:7.3f} "
              f"{t['mdr_last_window']:9.3f}  "
              f"{t['particles']} = {t['n_out']} out + {t['n_left']} left, |dM|/M0 {t['mass_error_rel']:.1e}")
    print(f"MDR: whole bin per metre of depth (2D plane strain); T_ss: s after opening, n/r = no > 10 % fall "
          f"that the rate does not recover from before the run ended; 1st chg: the first > 10 % change of either "
          f"sign (a drift or a dip) (a T_ss of a bin whose MDR is a small fraction of Beverloo's marks noise of a "
          f"nearly stopped outflow, not the end of a steady discharge); last 0.5s: MDR of the last window; Beverloo slot per metre at rho_i, k = 1.5, d = 0.71 mm: C = 0.64 "
          f"{bev[0.64]:.3f}, C = 0.58 {bev[0.58]:.3f} kg/s/m")
    for r in rows:
        for s in r["surfaces"]:
            extra = (f", slopes {s['angle_left']:.1f} / {s['angle_right']:.1f} deg (break x = {s['x_break']:.3f} m)"
                     if "angle_left" in s else "")
            print(f"  surface {r['label']}, t = {s['t']:.2f} s: {s['shape']} (bulge {s['bulge']:+.3f}){extra}")
        for p in r["velocity"]:
            v = np.array(p["v"], dtype=float)
            vmin = np.nanmin(v) if np.any(np.isfinite(v)) else float("nan")
            print(f"  velocity {r['label']}, H = {1e3 * p['height']:.0f} mm: peak downward {-vmin:.3f} m/s "
                  f"({p['frames']} frames)")
    _write(a.out, rows, table, bev)
    _plot(a.out, rows, bev)
    print(f"\nwritten: {a.out}/bins_table.csv, bins_table.json, bins_surface.csv, bins_velocity.csv, "
          f"bins_mdr.png, bins_surface.png, bins_velocity.png")


def _write(out, rows, table, bev):
    with open(f"{out}/bins_table.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0]))
        w.writeheader()
        w.writerows(table)
    with open(f"{out}/bins_surface.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["bin", "t_after_opening", "x", "y_top"])
        for r in rows:
            for s in r["surfaces"]:
                for x, y in zip(s["x"], s["y"]):
                    w.writerow([r["label"], f"{s['t']:.4f}", f"{x:.6g}", f"{y:.6g}"])
    with open(f"{out}/bins_velocity.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["bin", "height", "x", "v_y", "frames"])
        for r in rows:
            for p in r["velocity"]:
                for x, v in zip(p["x"], p["v"]):
                    w.writerow([r["label"], p["height"], f"{x:.6g}", f"{v:.6g}", p["frames"]])
    keep = ("label", "base", "wall", "particles", "n_out", "n_left", "mass_error", "t_open", "t_ss",
            "t_first_change", "mdr_bin", "window_ends", "window_rates", "geometry", "scene", "surfaces", "velocity", "psteps")
    with open(f"{out}/bins_table.json", "w") as f:
        json.dump(dict(table=table, beverloo=bev, runs=[{k: r[k] for k in keep} for r in rows]), f, indent=1,
                  default=lambda o: None if isinstance(o, float) and math.isnan(o) else o)


def _plot(out, rows, bev):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for r in rows:
        hist = np.genfromtxt(r["base"] + "_history.csv", delimiter=",", names=True)
        f = 2.0 if r["geometry"]["half"] else 1.0
        ax[0].plot(hist["time"] - r["t_open"], f * hist["MASS_OUT"], label=r["label"])
        ends, rates = BA.window_rates(hist["time"], f * hist["MASS_OUT"], r["t_open"], 0.1, 0.0)
        line, = ax[1].plot(ends - 0.05, rates, lw=0.8, label=r["label"])
        ax[1].step(r["window_ends"], r["window_rates"], where="pre", c=line.get_color(), lw=1.8)
        if r["t_ss"] is not None:
            ax[1].axvline(r["t_ss"], c=line.get_color(), ls=":", lw=1)
    for C, ls in ((0.64, "--"), (0.58, "-.")):
        ax[1].axhline(bev[C], c="k", ls=ls, lw=1, label=f"Beverloo C = {C:g}, k = 1.5 (rho_i 1800)")
    ax[0].set_ylabel("discharged mass [kg/m]")
    ax[1].set_ylabel("MDR [kg/s/m]")
    ax[1].set_title("thin: 0.1 s windows, thick: 0.5 s (T_ss rule), dotted: T_ss", fontsize=9)
    for x in ax:
        x.set_xlabel("time after opening [s]")
        x.grid(alpha=0.3)
        x.legend(fontsize=7)
    fig.suptitle("Flat-bottomed bins (thesis ch. 5), 2D plane strain, whole bin per metre of depth", fontsize=10)
    fig.tight_layout()
    fig.savefig(f"{out}/bins_mdr.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(1, len(rows), figsize=(3.2 * len(rows), 3.6), squeeze=False)
    for k, r in enumerate(rows):
        geo = r["geometry"]
        for s in r["surfaces"]:
            x, y = np.array(s["x"]), np.array(s["y"], dtype=float)
            if geo["half"]:
                x, y = np.r_[-x[::-1], x], np.r_[y[::-1], y]
            ax[0, k].plot(1e3 * x, 1e3 * y, label=f"{s['t']:.1f} s: {s['shape']}")
        ax[0, k].set_title(r["label"], fontsize=9)
        ax[0, k].set_xlabel("x [mm]" + (" (outlet centre 0)" if geo["half"] else ""))
        ax[0, k].set_ylim(0.0, 1e3 * (geo["fill"] + 0.01))
        ax[0, k].set_aspect("equal")
        ax[0, k].legend(fontsize=6)
    ax[0, 0].set_ylabel("free surface height [mm]")
    fig.tight_layout()
    fig.savefig(f"{out}/bins_surface.png", dpi=110)
    plt.close(fig)

    heights = [p["height"] for p in rows[0]["velocity"]]
    fig, ax = plt.subplots(1, len(heights), figsize=(4 * len(heights), 3.6), squeeze=False)
    for r in rows:
        geo = r["geometry"]
        for k, p in enumerate(r["velocity"]):
            x = np.array(p["x"]) - (0.0 if geo["half"] else 0.5 * (geo["x_out0"] + geo["x_out1"]))
            v = np.array(p["v"], dtype=float)
            if geo["half"]:
                x, v = np.r_[-x[::-1], x], np.r_[v[::-1], v]
            ax[0, k].plot(1e3 * x, v, label=r["label"])
    for k, H in enumerate(heights):
        ax[0, k].set_title(f"H = {1e3 * H:.0f} mm above the outlet", fontsize=9)
        ax[0, k].set_xlabel("x from the outlet centre [mm]")
        ax[0, k].grid(alpha=0.3)
    ax[0, 0].set_ylabel("time-averaged v_y [m/s]")
    ax[0, 0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(f"{out}/bins_velocity.png", dpi=110)
    plt.close(fig)
