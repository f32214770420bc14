"""c: filling and discharging wall normal stress vs modified Walker (thesis Fig. 4.12)

Study c of the MPM wedge hopper (Table 4.2: theta 30 deg, b 0.25 m, H 3 m, phi 20 deg, phi_w 5 deg,
psi 15 -> 0 deg over eps_v 0 -> 0.2; the defaults of hopper_scene.py). One run (1 s fill with the
outlet closed + `--discharge` s with the outlet open and inflow at the top) gives

- the FILLING wall normal stress: the last particle frame of step FILL (outlet closed, settled);
- the DISCHARGING wall normal stress: the mean over every discharge frame from `--skip` s after
  the outlet opened (steady flow) to the end, to beat the particle noise;

both along the inclined wall in wall coordinates (sigma_n = -n.S.n, compression positive), in
bins of `--bin` cells along the wall, from the particles 1-2 cells from the wall line (`--band`).
Why not the particles within one cell of the wall line (paths.py before it took this band too): the cell the inclined wall cuts carries the
node-only wall's artefact. At cell 0.05 m the half-cell row next to the wall carries ~1.9x, the
next row ~0.8x the sigma_n found one cell further in (fill), and along the wall sigma_n swings
with a period of 7 cells in height (autocorrelation 0.64 at lag 7; tan 30 deg ~ 4/7: the node
pattern next to the wall line repeats every 7 cells up); the same pattern shows for MC and DP alike
(study g), i.e. it is geometric, not material. One cell further in the stress is smoother, and
integrated along the wall it matches the solver's wall reaction force (printed: within 1 % in
filling, 4 % in discharge at cell 0.05 m), while the within-one-cell band overshoots it by 20-30 %.
The within-one-cell band is reduced and reported too ("cut cell").

Theory ("modified Walker", thesis §4.5.4). The thesis means Walker's method of differential
slices with Walters' distribution factor (thesis §1.2, its ref. 18). Walters' factor for HOPPERS
is not available to the project (docs/theory/hopper_theory.md §e.3; theory/walker.py implements only the
bin form), so the curves here are Walker's slice solution with Walker's own distribution factor
D (wall at yield, theory/walker.py wall_normal_stress):
  filling:     active state everywhere (omega_a), free surface at the fill top, no surcharge;
  discharging: passive state everywhere (omega_p). A passive/active switch belongs to the
               bin-hopper transition; this hopper has no bin and the discharge flows down to the
               free surface, and the MPM confirms a passive field over the whole height
               (sigma_xx/sigma_yy on the axis ~ K_p, printed), so the switch is not used.
rho_b = 1600 kg/m3 (Table 4.2), delta = phi (cohesionless). Heights y above the hopper apex;
the free surface is at the scene's fill top y0 + H (the inflow keeps it there in discharge).

Figures (printed, CSV/JSON): RMS of the pointwise relative difference (MPM - Walker)/Walker and
the normalised RMS difference sqrt(mean((MPM - W)^2))/sqrt(mean(W^2)), over
  (1) the included part of the wall: from one cell above the outlet corner (the corner cell is
      where the closed outlet wall meets the inclined wall in filling, and where the stress drops
      to zero at the free outlet edge in discharge; the slice theory resolves neither) up to
      `--exclude-top` m (vertical) below the free surface (there both stresses tend to zero, the
      relative difference is ill-conditioned, the top particles have partial uGIMP stencils and
      in discharge the inflow adds unstressed layers);
  (2) the whole wall: every bin with particles whose centre lies below the free surface.
Also the total normal force on the wall from the solver's wall reaction (history WALLF*_WALL,
noise-free) against the integral of the Walker curve.
"""
import csv
import json
import math
from pathlib import Path

import numpy as np

from .paths import WALL_BAND, wall_geometry, wall_stress_profile  # noqa: F401 (also this module's API)

from ..theory.walker import walker_D, wall_normal_stress

# the case studies c and d share (and mc-dp, for its context row): more discharge frames than the
# hopper_run default so that the discharge averages have 8 frames past the start-up transient
CASE_DEFAULTS = dict(cell=0.05, discharge=2.0, field_frames=10, skip=0.6)
TABLE_4_2 = dict(theta=30.0, outlet=0.25, height=3.0, phi=20.0, wall_friction=5.0, density=1600.0)


# ---------------------------------------------------------------------------------------------
# reductions (pure functions of particle frames; tested on synthetic data in
# tests/python/test_mpm_study_fields.py)

def frame_time(g):
    return float(g.attrs["total_time"][0])


def split_frames(groups, skip):
    """(fill, discharge) particle frames: fill = [last frame of step 1] (end of filling), discharge
    = frames of step 2 with step_time >= skip (steady flow after the start-up transient)."""
    fill = [g for g in groups if int(g.attrs["step"][0]) == 1]
    dis = [g for g in groups if int(g.attrs["step"][0]) == 2 and float(g.attrs["step_time"][0]) >= skip - 1e-9]
    return fill[-1:], dis


def all_frames(h5):
    return [h5["particles"][k] for k in sorted(h5["particles"].keys())]


def wall_masks(s, y, h, y_top, exclude_top, bin_width):
    """(included, whole) boolean masks of wall bins (centres s, heights y above the apex):
    included = the bin starts at or above s = h (clear of the outlet corner cell) and its centre
    is at least exclude_top below the free surface y_top; whole = bin centre below y_top."""
    s, y = np.asarray(s), np.asarray(y)
    whole = y < y_top
    inc = whole & (s - 0.5 * bin_width >= h - 1e-9) & (y <= y_top - exclude_top + 1e-9)
    return inc, whole


def rms_relative(m, t, mask=None):
    """RMS of the pointwise relative difference (m - t)/t over mask."""
    m, t = np.asarray(m, float), np.asarray(t, float)
    mask = np.ones(m.shape, bool) if mask is None else np.asarray(mask)
    r = (m[mask] - t[mask]) / t[mask]
    return float(np.sqrt(np.mean(r * r))) if r.size else float("nan")


def rms_normalised(m, t, mask=None):
    """sqrt(mean((m - t)^2)) / sqrt(mean(t^2)) over mask (insensitive to t -> 0 at the surface)."""
    m, t = np.asarray(m, float), np.asarray(t, float)
    mask = np.ones(m.shape, bool) if mask is None else np.asarray(mask)
    if not mask.any():
        return float("nan")
    return float(np.sqrt(np.mean((m[mask] - t[mask]) ** 2)) / np.sqrt(np.mean(t[mask] ** 2)))


def walker_curves(y, y_top, rho, phi, phi_w, theta):
    """Walker slice solution (Walker's D, cohesionless delta = phi), free surface at y_top, no
    surcharge: dict(active=..., passive=...) wall normal stress [Pa] at heights y above the apex."""
    y = np.asarray(y, float)
    out = {}
    for state in ("active", "passive"):
        w = wall_normal_stress(np.minimum(y, y_top), y_top, rho, phi, phi_w, theta, state=state)
        out[state] = np.where(y < y_top, w, 0.0)
    return out


def walker_wall_force(y0, y_top, rho, phi, phi_w, theta, state, n=4001):
    """Integral of the Walker wall normal stress along the wall from the outlet to the surface
    [N per m depth of the half model]."""
    y = np.linspace(y0, y_top, n)
    w = wall_normal_stress(y, y_top, rho, phi, phi_w, theta, state=state)
    ds = (y[1] - y[0]) / math.cos(math.radians(theta))
    return float(np.sum(0.5 * (w[1:] + w[:-1])) * ds)


def history_wall_force(hist, theta, step, t_from=None):
    """Normal and tangential force of the material on the inclined wall (history WALLF*_WALL) in
    wall coordinates: step 1 -> the last row of the fill; step 2 -> mean over rows with
    step_time >= t_from, without the step's last row (its wall force is a 3-4x spike in the
    runs seen: an end-of-step artefact of the reaction output, not the material)."""
    t = math.radians(theta)
    fn = hist["WALLF1_WALL"] * math.cos(t) - hist["WALLF2_WALL"] * math.sin(t)
    ft = hist["WALLF1_WALL"] * math.sin(t) + hist["WALLF2_WALL"] * math.cos(t)
    rows = np.flatnonzero(hist["step"] == step)
    if step == 1:
        i = rows[-1:]
    else:
        i = rows[:-1][hist["step_time"][rows[:-1]] >= t_from]
    return float(fn[i].mean()), float(ft[i].mean())


def axis_stress_ratio(groups, h, y_edges):
    """sigma_xx/sigma_yy of the particles within one cell of the axis in bands of height (means
    over frames): > 1 passive (major stress horizontal), < 1 active."""
    out = []
    for a, b in zip(y_edges[:-1], y_edges[1:]):
        sx = sy = 0.0
        for g in groups:
            x, S = g["coordinates"][:], g["S"][:]
            m = (x[:, 0] < h) & (x[:, 1] >= a) & (x[:, 1] < b)
            sx += S[m, 0].sum()
            sy += S[m, 1].sum()
        out.append(sx / sy if sy != 0 else float("nan"))
    return np.array(out)


# ---------------------------------------------------------------------------------------------
# study

def add_arguments(p):
    from .studies import add_case_arguments
    add_case_arguments(p, **CASE_DEFAULTS)
    p.add_argument("--bin", type=float, default=2.0, help="wall bin length in cells")
    p.add_argument("--band", type=float, nargs=2, default=list(WALL_BAND),
                   help="particles at distance [lo, hi) cells from the wall line (default 1 2)")
    p.add_argument("--exclude-top", type=float, default=0.2,
                   help="vertical depth below the free surface left out of the included range [m]")


def base_case(a, **extra):
    from .studies import case
    return case(a, cell=a.cell, discharge_time=a.discharge, field_frames=a.field_frames, **extra)


def load_frames(base, skip):
    """(h, fill frames, discharge frames, open h5 file) of a run."""
    import h5py
    f = h5py.File(base + ".h5", "r")
    h = float(f["grid"].attrs["h"][0])
    fill, dis = split_frames(all_frames(f), skip)
    return h, fill, dis, f


def wall_profiles(fill, dis, h, bin_cells, band, geo=TABLE_4_2):
    return {"filling": wall_stress_profile(fill, h, geo["theta"], geo["outlet"], bin_cells * h, band),
            "discharging": wall_stress_profile(dis, h, geo["theta"], geo["outlet"], bin_cells * h, band)}


def compare_walker(prof, h, y0, y_top, exclude_top, bin_width, geo=TABLE_4_2):
    """Per state: the Walker curve at the bins, masks and the RMS figures."""
    out = {}
    for key, state in (("filling", "active"), ("discharging", "passive")):
        p = prof[key]
        th = walker_curves(p["y"], y_top, geo["density"], geo["phi"], geo["wall_friction"], geo["theta"])
        inc, whole = wall_masks(p["s"], p["y"], h, y_top, exclude_top, bin_width)
        other = "passive" if state == "active" else "active"
        out[key] = dict(walker_state=state, walker=th[state], inc=inc, whole=whole,
                        D=walker_D(geo["phi"], geo["wall_friction"], geo["theta"], state),
                        rel_inc=rms_relative(p["sigma_n"], th[state], inc),
                        nrms_inc=rms_normalised(p["sigma_n"], th[state], inc),
                        rel_whole=rms_relative(p["sigma_n"], th[state], whole),
                        nrms_whole=rms_normalised(p["sigma_n"], th[state], whole),
                        nrms_inc_other=rms_normalised(p["sigma_n"], th[other], inc),
                        inc_range=[float(p["y"][inc].min() - y0), float(p["y"][inc].max() - y0)]
                        if inc.any() else [float("nan")] * 2,
                        whole_range=[float(p["y"][whole].min() - y0), float(p["y"][whole].max() - y0)])
    return out


def run(a):
    out = Path(a.out)
    geo = TABLE_4_2
    r = base_case(a)
    theta = geo["theta"]
    y0 = 0.5 * geo["outlet"] / math.tan(math.radians(theta))
    y_top = y0 + geo["height"]
    h, fill, dis, f = load_frames(r["base"], a.skip)
    bw = a.bin * h
    bands = {"main": tuple(a.band), "cut cell": (-1.0, 1.0)}
    prof = {k: wall_profiles(fill, dis, h, a.bin, b) for k, b in bands.items()}
    cmp_ = {k: compare_walker(prof[k], h, y0, y_top, a.exclude_top, bw) for k in bands}
    times = {"filling": [frame_time(g) for g in fill], "discharging": [frame_time(g) for g in dis]}
    edges = np.arange(y0, y_top - 0.5 * h, 0.25)
    ratio = {"filling": axis_stress_ratio(fill, h, edges), "discharging": axis_stress_ratio(dis, h, edges)}
    dens = {k: float(np.mean([np.sum(g["mass"][:]) / np.sum(g["volume"][:]) for g in v]))
            for k, v in (("filling", fill), ("discharging", dis))}
    f.close()
    hist = np.genfromtxt(r["base"] + "_history.csv", delimiter=",", names=True)
    force = {}
    for key, state, step in (("filling", "active", 1), ("discharging", "passive", 2)):
        fn, ft = history_wall_force(hist, theta, step, a.skip)
        fw = walker_wall_force(y0, y_top, geo["density"], geo["phi"], geo["wall_friction"], theta, state)
        other = "passive" if state == "active" else "active"
        fo = walker_wall_force(y0, y_top, geo["density"], geo["phi"], geo["wall_friction"], theta, other)
        force[key] = dict(mpm=fn, walker=fw, walker_other=fo, shear=ft)

    print(f"study c: wall normal stress vs Walker (thesis Fig. 4.12), Table 4.2 hopper, cell {a.cell:g} m, "
          f"1 s fill + {a.discharge:g} s discharge, run {Path(r['base']).name} ({r['wall']:.0f} s)")
    print(f"theory: Walker slices with Walker's D (Walters' hopper factor not available), rho 1600, "
          f"delta = phi = 20, phi_w = 5, free surface y_top = {y_top:.3f} m above the apex; "
          f"filling: active, discharging: passive")
    print(f"filling: frame t = {times['filling'][0]:.3f} s; discharging: mean of {len(times['discharging'])} "
          f"frames t = {times['discharging'][0]:.2f} .. {times['discharging'][-1]:.2f} s; wall bins of "
          f"{a.bin:g} cells ({bw:g} m)")
    print(f"{'band (cells)':<14} {'state':<12} {'D':>6} {'included (above outlet) m':>26} {'RMS rel':>8} "
          f"{'NRMS':>6}  {'whole wall m':>13} {'RMS rel':>8} {'NRMS':>6}")
    rows = []
    for k, b in bands.items():
        for key, st in cmp_[k].items():
            ir, wr = st["inc_range"], st["whole_range"]
            print(f"{f'{b[0]:g}..{b[1]:g} ({k})':<14} {key:<12} {st['D']:6.3f} {ir[0]:11.3f} .. {ir[1]:<11.3f} "
                  f"{st['rel_inc']:8.3f} {st['nrms_inc']:6.3f}  {wr[0]:5.3f}..{wr[1]:<6.3f} "
                  f"{st['rel_whole']:8.3f} {st['nrms_whole']:6.3f}")
            rows.append(dict(band_cells=list(b), band_name=k, state=key, walker_state=st["walker_state"],
                             walker_D=st["D"], included_range_above_outlet_m=ir,
                             whole_range_above_outlet_m=wr, rms_relative_included=st["rel_inc"],
                             nrms_included=st["nrms_inc"], rms_relative_whole=st["rel_whole"],
                             nrms_whole=st["nrms_whole"],
                             nrms_included_vs_other_walker_state=st["nrms_inc_other"],
                             bins_included=int(st["inc"].sum()), bins_whole=int(st["whole"].sum())))
    print("RMS rel = sqrt(mean(((MPM - W)/W)^2)); NRMS = sqrt(mean((MPM - W)^2))/sqrt(mean(W^2)); included: bins "
          f"from 1 cell above the outlet corner up to {a.exclude_top:g} m below the surface; whole: every bin "
          "below the surface")
    m = cmp_["main"]
    print(f"for reference, NRMS of the filling stress against Walker PASSIVE: {m['filling']['nrms_inc_other']:.3f} "
          f"(included range, band {a.band[0]:g}..{a.band[1]:g})")
    print("normal force on the wall [kN per m depth, half model] from the solver's wall reaction (fill: last "
          "fill row; discharge: mean of the rows after the skip) vs the integral of the Walker curve:")
    for key, fo in force.items():
        print(f"  {key:<12} MPM {fo['mpm'] / 1e3:7.2f}  Walker {m[key]['walker_state']:<7} "
              f"{fo['walker'] / 1e3:7.2f}  diff {fo['mpm'] / fo['walker'] - 1:+.3f}  (vs the other state "
              f"{fo['walker_other'] / 1e3:6.2f}: {fo['mpm'] / fo['walker_other'] - 1:+.3f})  "
              f"MPM shear/normal {fo['shear'] / fo['mpm']:+.3f} (tan phi_w = {math.tan(math.radians(5)):.3f})")
    # the band's stress integrated along the wall against the solver's wall reaction: which band
    # carries the traction the wall actually feels (independent of any theory)
    integ = {k: {key: float(np.sum(prof[k][key]["sigma_n"][cmp_[k][key]["whole"]]) * bw) for key in force}
             for k in bands}
    for k, b in bands.items():
        print(f"  integral of sigma_n ds, band {b[0]:g}..{b[1]:g} ({k}): " + ", ".join(
            f"{key} {integ[k][key] / 1e3:6.2f} ({integ[k][key] / force[key]['mpm'] - 1:+.3f} vs the wall reaction)"
            for key in force))
    ec = 0.5 * (edges[1:] + edges[:-1]) - y0
    kp = (1 + math.sin(math.radians(geo["phi"]))) / (1 - math.sin(math.radians(geo["phi"])))
    for key in ("filling", "discharging"):
        print(f"axis sigma_xx/sigma_yy, {key} (passive K_p = {kp:.2f}, active 1/K_p = {1 / kp:.2f}), height above "
              "outlet:ratio  " + " ".join(f"{y:.2f}:{v:.2f}" for y, v in zip(ec, ratio[key])))

    with open(out / "walker_wall_stress.csv", "w", newline="") as fcsv:
        w = csv.writer(fcsv)
        w.writerow(["band", "state", "s_m", "y_above_apex_m", "y_above_outlet_m", "sigma_n_mpm_Pa", "tau_mpm_Pa",
                    "sigma_n_walker_Pa", "walker_state", "particles_per_frame", "included"])
        for k, b in bands.items():
            for key, st in cmp_[k].items():
                p = prof[k][key]
                for i in range(len(p["s"])):
                    w.writerow([f"{b[0]:g}..{b[1]:g}", key, f"{p['s'][i]:.4f}", f"{p['y'][i]:.4f}",
                                f"{p['y'][i] - y0:.4f}", f"{p['sigma_n'][i]:.2f}", f"{p['tau'][i]:.2f}",
                                f"{st['walker'][i]:.2f}", st["walker_state"], f"{p['count'][i]:.2f}",
                                int(st["inc"][i])])
    summary = dict(study="walker", figure="thesis Fig. 4.12", run=r["base"], run_wall_s=r["wall"],
                   cell=a.cell, discharge_s=a.discharge, skip_s=a.skip, bin_m=bw, band_cells=list(a.band),
                   exclude_top_m=a.exclude_top, y0=y0, y_top=y_top, frames_t=times,
                   theory="Walker slice solution with Walker's D (Walters' hopper factor not available); "
                          "filling active, discharging passive everywhere; rho 1600, delta = phi",
                   rows=rows,
                   wall_force={k: dict(mpm_N_per_m=v["mpm"], walker_N_per_m=v["walker"],
                                       rel_diff=v["mpm"] / v["walker"] - 1,
                                       walker_other_state_N_per_m=v["walker_other"],
                                       rel_diff_other_state=v["mpm"] / v["walker_other"] - 1,
                                       mpm_shear_over_normal=v["shear"] / v["mpm"])
                               for k, v in force.items()},
                   axis_ratio={k: dict(heights_above_outlet=ec.tolist(), ratio=v.tolist()) for k, v in ratio.items()},
                   band_integral_N_per_m={f"{b[0]:g}..{b[1]:g}": integ[k] for k, b in bands.items()},
                   mean_particle_density=dens)
    (out / "walker_summary.json").write_text(json.dumps(summary, indent=1))
    plot(prof, cmp_, bands, times, y0, y_top, h, out / "walker_wall_stress.png", a)
    print(f"wrote {out}/walker_wall_stress.csv, walker_summary.json, walker_wall_stress.png")


def plot(prof, cmp_, bands, times, y0, y_top, h, path, a, geo=TABLE_4_2):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    yy = np.linspace(y0, y_top, 400)
    th = walker_curves(yy, y_top, geo["density"], geo["phi"], geo["wall_friction"], geo["theta"])
    fig, axs = plt.subplots(1, 2, figsize=(12, 5), sharey=True)
    for ax, key, lab in zip(axs, ("filling", "discharging"), ("(a) filling", "(b) discharging")):
        st = cmp_["main"][key]
        other = "passive" if st["walker_state"] == "active" else "active"
        ax.plot(yy - y0, th[st["walker_state"]] / 1e3, "k-", lw=2,
                label=f"Walker, {st['walker_state']} (D = {st['D']:.3f})")
        ax.plot(yy - y0, th[other] / 1e3, "k:", lw=1, label=f"Walker, {other} (reference)")
        p = prof["main"][key]
        inc = st["inc"]
        b = bands["main"]
        ax.plot(p["y"][inc] - y0, p["sigma_n"][inc] / 1e3, "o-", c="C0", ms=4,
                label=f"MPM, {b[0]:g}-{b[1]:g} cells from the wall")
        ax.plot(p["y"][~inc] - y0, p["sigma_n"][~inc] / 1e3, "o", mfc="none", c="C0", ms=4,
                label="MPM, left out of the RMS")
        q = prof["cut cell"][key]
        ax.plot(q["y"] - y0, q["sigma_n"] / 1e3, "-", c="C1", lw=0.8, alpha=0.8,
                label="MPM, within 1 cell of the wall line (cut cell)")
        ax.axvspan(-0.02, h * math.cos(math.radians(geo["theta"])), color="0.9")
        ax.axvspan(y_top - a.exclude_top - y0, y_top - y0 + 0.05, color="0.9")
        nf = len(times[key])
        ax.set_title(f"{lab}: RMS rel {st['rel_inc']:.2f}, NRMS {st['nrms_inc']:.2f} "
                     f"({'1 frame' if nf == 1 else f'mean of {nf} frames'})", fontsize=10)
        ax.set_xlabel("height above the outlet [m]")
        ax.set_xlim(-0.02, y_top - y0 + 0.05)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    axs[0].set_ylabel("wall normal stress [kPa]")
    fig.suptitle(f"MPM wedge hopper (Table 4.2), cell {a.cell:g} m, wall bins {a.bin * h:g} m; grey: left out "
                 "of the included range (outlet corner cell, top)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
