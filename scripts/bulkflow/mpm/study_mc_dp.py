"""g: Mohr-Coulomb vs plane-strain matched Drucker-Prager (thesis Figs. 4.10-4.11)

Study g of the MPM wedge hopper (Table 4.2 geometry and strength: theta 30 deg, b 0.25 m, H 3 m,
phi 20 deg, phi_w 5 deg, c = 0; 1 s fill + `--discharge` s with inflow). For each dilation angle
psi of `--psi` two runs: Mohr-Coulomb with the constant psi (hopper_scene psi_constant) and the
linear Drucker-Prager of umat DP mode 1 converted from the same (phi, psi, c) (hopper_scene
model="DP", psi_constant=psi). Compared, as in the thesis:
  Fig. 4.10: filling (end of fill) and discharging (mean of the discharge frames from `--skip` s)
             wall normal stress along the inclined wall (study_walker's reduction: particles 1-2
             cells from the wall, bins of `--bin` cells);
  Fig. 4.11: the outlet velocity profile (paths.outlet_path, mean of the same discharge frames)
             and the MDR vs time (windows of `--window` s of the discharged mass), steady MDR
             (discharge.mean_discharge_rate, from 0.5 s after opening).
Printed: RMS difference of DP from MC over the wall, normalised by the RMS of MC (NRMS), over
study_walker's included range and over the whole wall; outlet mean v_y, outlet density and
steady MDR differences in %; NRMS of the outlet v_y profile; share of yielding particles.

Which dilation makes it an equivalence. umat DP mode 1 (drucker_prager_match.f90,
match_plane_strain) matches, in plane strain at steady plastic flow (elastic strain rate zero so
d eps_zz^p = 0), the Mohr-Coulomb strength (phi, c) AND the in-plane dilation psi, for any
constant 0 <= psi <= phi: tan psi_DP = 3 sin psi / sqrt(3 + sin^2 psi) and tan beta =
9 sin phi / (S + tan psi_DP sin phi), S = sqrt(3 (9 - tan^2 psi_DP)). Thesis eq. 3.2
(tan beta = sqrt(3) sin phi, d = c cos phi) is the psi = psi_DP = 0 case; the thesis ran MC with
its minimum psi (0.1 deg) against that. So the equivalence is tested with both models at the SAME
CONSTANT psi, psi = 0 first (the thesis's case; our MC takes psi = 0 exactly, no 0.1 deg floor).
The Table 4.2 psi 15 -> 0 table has no DP counterpart (the DP props hold one constant psi and
beta would have to follow psi), so it is not an equivalence; it is shown as context (the base
MC run of studies c/d against DP psi = 0). Where the material is not at plastic flow (much of
the settled fill, elastic) the plane-strain match does not hold exactly (sigma_zz is set by
elasticity, not by the flow rule), so filling differences can be larger than discharging ones.
"""
import csv
import json
import math
from pathlib import Path

import numpy as np

from .discharge import discharge_rate, mean_discharge_rate
from .paths import outlet_path
from .study_walker import (CASE_DEFAULTS, TABLE_4_2, WALL_BAND, base_case, frame_time, load_frames,
                           rms_normalised, wall_masks, wall_profiles)


def align(p, q, key):
    """Values of `key` of two wall profiles on their common bins (matched by bin centre s)."""
    sp, sq = np.round(p["s"], 9), np.round(q["s"], 9)
    common, ip, iq = np.intersect1d(sp, sq, return_indices=True)
    return common, p["y"][ip], p[key][ip], q[key][iq]


def rel_diff(a, b):
    """(a - b)/b."""
    return float(a / b - 1.0)


def yield_share(groups):
    """Share of particles whose last return was plastic (SDV5 YIELD != 0), mean over frames."""
    return float(np.mean([np.mean(g["SDV"][:][:, 4] != 0) for g in groups]))


def reduce_run(r, a, geo=TABLE_4_2):
    h, fill, dis, f = load_frames(r["base"], a.skip)
    prof = wall_profiles(fill, dis, h, a.bin, tuple(a.band))
    op = outlet_path(dis, h, geo["theta"], geo["outlet"])
    ys = dict(filling=yield_share(fill), discharging=yield_share(dis))
    times = [frame_time(g) for g in dis]
    f.close()
    hist = np.genfromtxt(r["base"] + "_history.csv", delimiter=",", names=True)
    _, _, opened, rates, edges = discharge_rate(hist, skip=0.0, window=a.window)
    mdr = 2 * float(mean_discharge_rate(hist))
    ok = np.isfinite(op[:, 1])
    return dict(h=h, prof=prof, outlet=op, v_out=float(np.nanmean(op[ok, 1])),
                rho_out=float(np.nanmean(op[ok, 2])), mdr=mdr, t_rate=edges[1:] - opened, rates=2 * np.asarray(rates), yield_share=ys, times=times)


def compare(mc, dp, a, geo=TABLE_4_2):
    h = mc["h"]
    y0 = 0.5 * geo["outlet"] / math.tan(math.radians(geo["theta"]))
    y_top = y0 + geo["height"]
    out = {}
    for key in ("filling", "discharging"):
        s, y, m, d = align(mc["prof"][key], dp["prof"][key], "sigma_n")
        inc, whole = wall_masks(s, y, h, y_top, a.exclude_top, a.bin * h)
        out[f"wall_{key}_nrms_included"] = rms_normalised(d, m, inc)
        out[f"wall_{key}_nrms_whole"] = rms_normalised(d, m, whole)
        out[f"wall_{key}_mean_rel_included"] = rel_diff(np.mean(d[inc]), np.mean(m[inc]))
    om, od = mc["outlet"], dp["outlet"]
    ok = np.isfinite(om[:, 1]) & np.isfinite(od[:, 1])
    out["outlet_v_nrms"] = rms_normalised(od[ok, 1], om[ok, 1])
    out["outlet_v_mean_rel"] = rel_diff(dp["v_out"], mc["v_out"])
    out["outlet_rho_rel"] = rel_diff(dp["rho_out"], mc["rho_out"])
    out["mdr_rel"] = rel_diff(dp["mdr"], mc["mdr"])
    n = min(len(mc["rates"]), len(dp["rates"]))
    late = mc["t_rate"][:n] > 0.5
    out["mdr_windows_nrms_after_0.5s"] = rms_normalised(dp["rates"][:n][late], mc["rates"][:n][late])
    return out


def add_arguments(p):
    from .studies import add_case_arguments
    add_case_arguments(p, **CASE_DEFAULTS)
    p.add_argument("--psi", type=float, nargs="+", default=[0.0, 10.0],
                   help="constant dilation angles of the MC/DP pairs [deg] (0 = thesis eq. 3.2)")
    p.add_argument("--no-context", action="store_true",
                   help="skip the context row (Table 4.2 MC psi 15 -> 0 vs DP psi 0)")
    p.add_argument("--bin", type=float, default=2.0, help="wall bin length in cells")
    p.add_argument("--band", type=float, nargs=2, default=list(WALL_BAND),
                   help="wall band [lo, hi) cells from the wall line")
    p.add_argument("--exclude-top", type=float, default=0.2,
                   help="depth below the free surface left out of the included wall range [m]")
    p.add_argument("--window", type=float, default=0.1, help="MDR window [s]")


FIGS = [("wall_filling_nrms_included", "wall fill NRMS", "{:.3f}"),
        ("wall_filling_nrms_whole", "(whole)", "{:.3f}"),
        ("wall_discharging_nrms_included", "wall dis NRMS", "{:.3f}"),
        ("wall_discharging_nrms_whole", "(whole)", "{:.3f}"),
        ("outlet_v_nrms", "v_out NRMS", "{:.3f}"),
        ("outlet_v_mean_rel", "dv_out", "{:+.2%}"),
        ("outlet_rho_rel", "drho_out", "{:+.2%}"),
        ("mdr_rel", "dMDR", "{:+.2%}")]


def run(a):
    out = Path(a.out)
    pairs = []
    for psi in a.psi:
        rm = base_case(a, psi_constant=psi)
        rd = base_case(a, model="DP", psi_constant=psi)
        pairs.append((f"psi {psi:g}: DP vs MC", psi, rm, rd))
    if not a.no_context:
        rm = base_case(a)
        rd = pairs[0][3] if a.psi and a.psi[0] == 0.0 else base_case(a, model="DP", psi_constant=0.0)
        pairs.append(("context: DP psi 0 vs MC psi 15->0", None, rm, rd))
    red, cmps = {}, []
    for lab, psi, rm, rd in pairs:
        for r in (rm, rd):
            if r["base"] not in red:
                red[r["base"]] = reduce_run(r, a)
        cmps.append((lab, psi, rm, rd, compare(red[rm["base"]], red[rd["base"]], a)))
    print(f"study g: Mohr-Coulomb vs plane-strain matched Drucker-Prager (thesis Figs. 4.10-4.11), Table 4.2 "
          f"hopper, cell {a.cell:g} m, 1 s fill + {a.discharge:g} s discharge")
    print(f"{'run':<34} {'wall s':>6} {'MDR kg/s/m':>10} {'v_out m/s':>9} {'rho_out':>8} "
          f"{'yield fill':>10} {'yield dis':>9}")
    seen = set()
    for lab, psi, rm, rd, _ in cmps:
        for name, r in (("MC", rm), ("DP", rd)):
            if r["base"] in seen:
                continue
            seen.add(r["base"])
            q = red[r["base"]]
            sc = r["scene"]
            desc = (f"{name} psi {sc['psi_constant']:g}" if sc.get("psi_constant") is not None
                    else f"{name} psi 15->0 (Table 4.2)")
            print(f"{desc + ' ' + Path(r['base']).name:<34} {r['wall']:6.0f} {q['mdr']:10.1f} {q['v_out']:9.3f} "
                  f"{q['rho_out']:8.1f} {q['yield_share']['filling']:10.3f} "
                  f"{q['yield_share']['discharging']:9.3f}")
    print()
    print(f"{'comparison':<34} " + " ".join(f"{t:>14}" for _, t, _ in FIGS))
    for lab, psi, rm, rd, c in cmps:
        print(f"{lab:<34} " + " ".join(f"{fmt.format(c[k]):>14}" for k, _, fmt in FIGS))
    print("NRMS = sqrt(mean((DP - MC)^2))/sqrt(mean(MC^2)); wall: particles "
          f"{a.band[0]:g}-{a.band[1]:g} cells from the wall, bins {a.bin:g} cells, included = from 1 cell above the "
          f"outlet corner to {a.exclude_top:g} m below the surface (study_walker); discharge: mean of "
          f"{len(red[pairs[0][2]['base']]['times'])} frames from {a.skip:g} s after opening; d*: (DP - MC)/MC; "
          "MDR: full hopper from 0.5 s after opening; v_out, rho_out: outlet path means; yield: share of particles "
          "at yield (SDV5 != 0), end of fill / mean over the discharge frames")
    # CSV
    with open(out / "mc_dp_wall.csv", "w", newline="") as fcsv:
        w = csv.writer(fcsv)
        w.writerow(["comparison", "state", "s_m", "y_above_apex_m", "sigma_n_mc_Pa", "sigma_n_dp_Pa"])
        for lab, psi, rm, rd, _ in cmps:
            for key in ("filling", "discharging"):
                s, y, m, d = align(red[rm["base"]]["prof"][key], red[rd["base"]]["prof"][key], "sigma_n")
                for i in range(len(s)):
                    w.writerow([lab, key, f"{s[i]:.4f}", f"{y[i]:.4f}", f"{m[i]:.2f}", f"{d[i]:.2f}"])
    with open(out / "mc_dp_outlet.csv", "w", newline="") as fcsv:
        w = csv.writer(fcsv)
        w.writerow(["run", "x_m", "v_y_m_s", "density_kg_m3", "particles_per_frame"])
        for b in red:
            for row in red[b]["outlet"]:
                w.writerow([Path(b).name] + [f"{v:.5g}" for v in row])
    with open(out / "mc_dp_mdr.csv", "w", newline="") as fcsv:
        w = csv.writer(fcsv)
        w.writerow(["run", "t_after_opening_s", "mdr_window_kg_s_m"])
        for b in red:
            for t, v in zip(red[b]["t_rate"], red[b]["rates"]):
                w.writerow([Path(b).name, f"{t:.3f}", f"{v:.2f}"])
    summary = dict(study="mc-dp", figure="thesis Figs. 4.10-4.11", cell=a.cell, discharge_s=a.discharge,
                   skip_s=a.skip, band_cells=list(a.band), bin_cells=a.bin, exclude_top_m=a.exclude_top,
                   equivalence="same constant psi for MC and DP (umat DP mode 1 plane-strain match); psi 0 = thesis eq. 3.2",
                   runs={Path(b).name: dict(mdr_full=q["mdr"], v_out=q["v_out"], rho_out=q["rho_out"],
                                            yield_share=q["yield_share"], frames_t=q["times"]) for b, q in red.items()},
                   comparisons=[dict(label=lab, psi=psi, mc=Path(rm["base"]).name, dp=Path(rd["base"]).name,
                                     mc_wall_s=rm["wall"], dp_wall_s=rd["wall"], **c)
                                for lab, psi, rm, rd, c in cmps])
    (out / "mc_dp_summary.json").write_text(json.dumps(summary, indent=1))
    plot(cmps, red, out / "mc_dp.png", a)
    print(f"wrote {out}/mc_dp_wall.csv, mc_dp_outlet.csv, mc_dp_mdr.csv, mc_dp_summary.json, mc_dp.png")


def plot(cmps, red, path, a, geo=TABLE_4_2):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    y0 = 0.5 * geo["outlet"] / math.tan(math.radians(geo["theta"]))
    fig, axs = plt.subplots(2, 2, figsize=(12, 9))
    styles = ["-", "--", ":"]
    for i, (lab, psi, rm, rd, c) in enumerate(cmps):
        ls = styles[i % len(styles)]
        mc, dp = red[rm["base"]], red[rd["base"]]
        mc_lab = f"MC psi {psi:g}" if psi is not None else "MC psi 15->0"
        dp_lab = f"DP psi {psi:g}" if psi is not None else "DP psi 0"
        for j, key in enumerate(("filling", "discharging")):
            ax = axs[0, j]
            if psi is None and rd["base"] == cmps[0][3]["base"]:
                ax.plot(mc["prof"][key]["y"] - y0, mc["prof"][key]["sigma_n"] / 1e3, ls, c="0.5", lw=1,
                        label=f"{mc_lab} (context)")
                continue
            ax.plot(mc["prof"][key]["y"] - y0, mc["prof"][key]["sigma_n"] / 1e3, ls, c="C0", marker="o", ms=3,
                    label=f"{mc_lab} (NRMS {c[f'wall_{key}_nrms_included']:.3f})")
            ax.plot(dp["prof"][key]["y"] - y0, dp["prof"][key]["sigma_n"] / 1e3, ls, c="C3", marker="s", ms=3,
                    label=dp_lab)
        ax = axs[1, 0]
        done = set()
        for r, q, col, name in ((rm, mc, "C0", mc_lab), (rd, dp, "C3", dp_lab)):
            if (r["base"], "o") in done or (psi is None and r is rd and rd["base"] == cmps[0][3]["base"]):
                continue
            done.add((r["base"], "o"))
            cc = "0.5" if psi is None else col
            ax.plot(q["outlet"][:, 0], -q["outlet"][:, 1], ls, c=cc, marker="o", ms=3, label=name)
            axs[1, 1].plot(q["t_rate"], q["rates"], ls, c=cc, drawstyle="steps-pre",
                           label=f"{name}: {q['mdr']:.0f} kg/s/m")
    axs[0, 0].set_title("(a) filling wall normal stress (Fig. 4.10a)", fontsize=10)
    nf = len(red[cmps[0][2]["base"]]["times"])
    axs[0, 1].set_title(f"(b) discharging wall normal stress, mean of {nf} frames (Fig. 4.10b)", fontsize=10)
    for ax in axs[0]:
        ax.set_xlabel("height above the outlet [m]")
        ax.set_ylabel("wall normal stress [kPa]")
    axs[1, 0].set_title("(c) outlet velocity profile (Fig. 4.11a)", fontsize=10)
    axs[1, 0].set_xlabel("x, distance from the axis [m]")
    axs[1, 0].set_ylabel("downward velocity at the outlet [m/s]")
    axs[1, 1].set_title(f"(d) MDR vs time, windows of {a.window:g} s (Fig. 4.11b)", fontsize=10)
    axs[1, 1].set_xlabel("time after opening [s]")
    axs[1, 1].set_ylabel("MDR, full hopper [kg/s/m]")
    for ax in axs.flat:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"MPM wedge hopper (Table 4.2), cell {a.cell:g} m: Mohr-Coulomb vs plane-strain matched "
                 "Drucker-Prager (same constant psi)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
