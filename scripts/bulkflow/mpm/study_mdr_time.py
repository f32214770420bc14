"""b: MDR and outlet density vs time, psi 15 -> 0 deg table vs constant psi = 10 deg (Fig. 4.14)

Thesis §4.5.6, Fig. 4.14: with the dilation angle falling linearly from 15 deg to 0 over the
volumetric strain 0 -> eps_cv = 0.2 (Table 4.3) the material stops dilating once it has
loosened to the constant-volume state, so the outlet bulk density and the mass discharge rate
settle; with a constant non-zero dilation angle (10 deg) every bit of further shear keeps
loosening the material near the outlet, and the density and the MDR keep falling.

Both cases are the Table 4.2 hopper (phi 20, phi_w 5, theta 30, b 0.25 m, H 3 m) with inflow
at the top, 1 s fill and a long discharge (`--discharge`, default 3 s) so that a trend can be
told from the noise. Figures per case:
- instantaneous MDR of the full hopper in windows of `--window` s (discharge.discharge_rate, from
  the discharged-mass history), against the window's mid time after opening;
- mean outlet bulk density against time: the outlet-path mean (paths.outlet_path, one frame at a
  time) of every particle frame (`--frame-dt` s apart);
- trends: least-squares straight lines through the window MDRs and the densities from `--skip` s
  after opening (the start-up transient left out), slope with a 95 % interval (Student t), and the
  slope in % of the fitted value at the middle of the fit range per second.
"""
import csv
import json
import math

import numpy as np
from scipy import stats

from .discharge import discharge_rate
from .paths import outlet_path

CASES = (("psi 15->0 table", dict()), ("psi 10 constant", dict(psi_constant=10.0)))


def add_arguments(p):
    from .studies import add_case_arguments
    add_case_arguments(p, discharge=3.0, skip=0.5, skip_help="s after opening left out of the trend fits")
    p.add_argument("--window", type=float, default=0.2, help="MDR window [s]")
    p.add_argument("--frame-dt", type=float, default=0.1, help="particle frame interval in the discharge [s]")


def linear_trend(t, y, conf=0.95):
    """Least-squares line y = a + s t. Returns dict: slope, slope_ci (half-width of the `conf`
    interval, Student t with n-2 dof), intercept, mid (fitted value at the mean t), rel_pct (slope in
    % of `mid` per unit t) and rel_ci_pct, n. Fewer than 3 points: no interval (nan)."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(t) & np.isfinite(y)
    t, y = t[ok], y[ok]
    n = len(t)
    if n < 2:
        return dict(slope=math.nan, slope_ci=math.nan, intercept=math.nan, mid=math.nan, rel_pct=math.nan,
                    rel_ci_pct=math.nan, n=n)
    tm = t.mean()
    sxx = np.sum((t - tm) ** 2)
    slope = float(np.sum((t - tm) * (y - y.mean())) / sxx)
    intercept = float(y.mean() - slope * tm)
    if n > 2:
        res = y - (intercept + slope * t)
        se = math.sqrt(np.sum(res ** 2) / (n - 2) / sxx)
        ci = float(stats.t.ppf(0.5 + 0.5 * conf, n - 2) * se)
    else:
        ci = math.nan
    mid = intercept + slope * tm
    return dict(slope=slope, slope_ci=ci, intercept=intercept, mid=float(mid), rel_pct=100.0 * slope / mid,
                rel_ci_pct=100.0 * ci / abs(mid), n=n)


def window_rates(hist, window=0.2, skip=0.0):
    """(mid times after opening, full-hopper window MDRs) from the discharged-mass history."""
    _, _, opened, rates, edges = discharge_rate(hist, skip=skip, window=window)
    mids = 0.5 * (edges[1:len(rates) + 1] + edges[:len(rates)]) - opened
    return mids, 2.0 * np.asarray(rates), opened


def density_series(h5path, opened, cell=None, theta=30.0, outlet=0.25):
    """(times after opening, outlet-path mean bulk density, outlet-path mean downward speed -v_y) for
    every particle frame from the opening on."""
    import h5py
    ts, rho, vy = [], [], []
    with h5py.File(h5path, "r") as f:
        h = float(f["grid"].attrs["h"][0]) if cell is None else cell
        for k in sorted(f["particles"].keys()):
            g = f["particles"][k]
            t = float(g.attrs["total_time"][0]) - opened
            if t < -1e-9:
                continue
            op = outlet_path([g], h, theta, outlet)
            ts.append(t)
            rho.append(float(np.nanmean(op[:, 2])))
            vy.append(float(-np.nanmean(op[:, 1])))
    return np.array(ts), np.array(rho), np.array(vy)


def run(a):
    from .studies import case
    frames = max(1, int(round(a.discharge / a.frame_dt)))
    print(f"MDR vs time (thesis Fig. 4.14): Table 4.2 hopper, cell {a.cell:g} m, 1 s fill + {a.discharge:g} s "
          f"discharge with inflow; windows {a.window:g} s; trend fits from {a.skip:g} s after opening", flush=True)
    res = []
    for label, kw in CASES:
        r = case(a, cell=a.cell, discharge_time=a.discharge, field_frames=frames, **kw)
        hist = np.genfromtxt(r["base"] + "_history.csv", delimiter=",", names=True)
        tw, mdr, opened = window_rates(hist, a.window)
        td, rho, vy = density_series(r["base"] + ".h5", opened)
        sel = tw - 0.5 * a.window >= a.skip - 1e-9       # windows that start after the transient
        fm = linear_trend(tw[sel], mdr[sel])
        seld = td >= a.skip
        fr = linear_trend(td[seld], rho[seld])
        fv = linear_trend(td[seld], vy[seld])
        res.append(dict(label=label, scene=kw, base=r["base"], wall=r["wall"], particles=r["particles"],
                        mdr_mean=r["mdr_full"], t_win=tw.tolist(), mdr_win=mdr.tolist(), t_frame=td.tolist(),
                        rho=rho.tolist(), v_out=vy.tolist(), mdr_fit=fm, rho_fit=fr, v_fit=fv,
                        mdr_first=float(np.mean(mdr[sel][:3])), mdr_last=float(np.mean(mdr[sel][-3:]))))
        print(f"  {label}: {r['particles']} particles, wall {r['wall']:.0f} s", flush=True)

    print(f"\n{'t [s]':>6} " + " ".join(f"{'MDR ' + c['label']:>20}" for c in res))
    for i, t in enumerate(res[0]["t_win"]):
        print(f"{t:6.2f} " + " ".join(f"{c['mdr_win'][i]:20.1f}" if i < len(c["mdr_win"]) else f"{'':>20}"
                                      for c in res))
    print(f"\n{'t [s]':>6} " + " ".join(f"{'rho_out ' + c['label']:>24}" for c in res))
    for i, t in enumerate(res[0]["t_frame"]):
        print(f"{t:6.2f} " + " ".join(f"{c['rho'][i]:24.1f}" if i < len(c["rho"]) else f"{'':>24}" for c in res))
    print(f"\n{'case':<20} {'MDR mean':>9} {'MDR trend %/s':>16} {'kg/s/m per s':>16} {'first->last':>15} "
          f"{'rho trend %/s':>16} {'rho mid':>8} {'speed trend %/s':>16}")
    for c in res:
        fm, fr, fv = c["mdr_fit"], c["rho_fit"], c["v_fit"]
        print(f"{c['label']:<20} {c['mdr_mean']:9.1f} {fm['rel_pct']:+8.2f} +-{fm['rel_ci_pct']:5.2f} "
              f"{fm['slope']:+8.1f} +-{fm['slope_ci']:5.1f} {c['mdr_first']:7.0f}->{c['mdr_last']:<6.0f} "
              f"{fr['rel_pct']:+8.2f} +-{fr['rel_ci_pct']:5.2f} {fr['mid']:8.1f} {fv['rel_pct']:+8.2f} +-{fv['rel_ci_pct']:5.2f}")
    print(f"MDR mean: regression of the discharged mass from 0.5 s after opening (full hopper, kg/s/m); trends: "
          f"straight-line fits from {a.skip:g} s, +- 95 % interval; first->last: mean of the first and last 3 "
          f"windows in the fit range; speed: outlet-path mean downward speed")
    def verdict(f):
        # steady if 0 lies inside the 95 % interval of the slope
        if abs(f["rel_pct"]) <= f["rel_ci_pct"]:
            return "steady (0 inside the 95 % interval of the trend)"
        return "falling" if f["slope"] < 0 else "rising"
    for c in res:
        c["mdr_verdict"], c["rho_verdict"] = verdict(c["mdr_fit"]), verdict(c["rho_fit"])
        c["mdr_steady"] = c["mdr_verdict"].startswith("steady")
        print(f"  {c['label']}: MDR {c['mdr_verdict']}; outlet density {c['rho_verdict']}")
    if len(res) == 2:
        d = res[1]["mdr_fit"]["rel_pct"] - res[0]["mdr_fit"]["rel_pct"]
        ci = math.hypot(res[1]["mdr_fit"]["rel_ci_pct"], res[0]["mdr_fit"]["rel_ci_pct"])
        print(f"  MDR trend difference ({res[1]['label']} - {res[0]['label']}): {d:+.2f} +- {ci:.2f} %/s")

    out = a.out
    with open(f"{out}/mdr_time_windows.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_after_opening"] + [f"mdr [{c['label']}]" for c in res])
        for i, t in enumerate(res[0]["t_win"]):
            w.writerow([t] + [c["mdr_win"][i] if i < len(c["mdr_win"]) else "" for c in res])
    with open(f"{out}/mdr_time_density.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_after_opening"] + [f"rho_out [{c['label']}]" for c in res]
                   + [f"speed_out [{c['label']}]" for c in res])
        for i, t in enumerate(res[0]["t_frame"]):
            w.writerow([t] + [c["rho"][i] if i < len(c["rho"]) else "" for c in res]
                       + [c["v_out"][i] if i < len(c["v_out"]) else "" for c in res])
    with open(f"{out}/mdr_time.json", "w") as f:
        json.dump(dict(cell=a.cell, discharge=a.discharge, window=a.window, skip=a.skip, cases=res), f, indent=1)
    _plot(res, a, f"{out}/mdr_time.png")
    print(f"\nwritten: {out}/mdr_time_windows.csv, mdr_time_density.csv, mdr_time.json, mdr_time.png")


def _plot(res, a, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for c, col in zip(res, ("C0", "C3")):
        td = np.array(c["t_frame"])
        ax[0].plot(td, c["rho"], "o-", c=col, ms=3, label=c["label"])
        fr = c["rho_fit"]
        tt = np.array([a.skip, td.max()])
        ax[0].plot(tt, fr["intercept"] + fr["slope"] * tt, "--", c=col, lw=1,
                   label=f"fit {fr['rel_pct']:+.2f} +- {fr['rel_ci_pct']:.2f} %/s")
        tw = np.array(c["t_win"])
        edges = np.r_[tw - 0.5 * a.window, tw[-1] + 0.5 * a.window]
        ax[1].stairs(c["mdr_win"], edges, color=col, label=c["label"])
        fm = c["mdr_fit"]
        tt = np.array([a.skip, tw.max() + 0.5 * a.window])
        ax[1].plot(tt, fm["intercept"] + fm["slope"] * tt, "--", c=col, lw=1,
                   label=f"fit {fm['rel_pct']:+.2f} +- {fm['rel_ci_pct']:.2f} %/s")
    # MDR: zoom on the part after the start-up (its windows are cut off; they are in the CSV)
    lo = min(min(np.array(c["mdr_win"])[np.array(c["t_win"]) - 0.5 * a.window >= a.skip - 1e-9]) for c in res)
    hi = max(max(c["mdr_win"]) for c in res)
    ax[1].set_ylim(0.85 * lo, 1.05 * hi)
    for x in ax:
        x.axvline(a.skip, c="grey", ls=":", lw=1)
        x.set_xlabel("time after opening [s]")
        x.grid(alpha=0.3)
        x.legend(fontsize=8)
    ax[0].set_ylabel("mean outlet bulk density [kg/m3]")
    ax[1].set_ylabel(f"MDR, {a.window:g} s windows [kg/s/m]")
    ax[0].set_title("(a) outlet density (cf. Fig. 4.14a)", fontsize=10)
    ax[1].set_title("(b) mass discharge rate (cf. Fig. 4.14b)", fontsize=10)
    fig.suptitle(f"MPM wedge hopper, Table 4.2, cell {a.cell:g} m, with inflow; dotted: start of trend fits (MDR axis zoomed on the discharge after it)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
