"""h: effects of E, phi, phi_w and eta_cv on MDR, outlet density, MFI, wall stress (thesis §4.5.8)

Parametric study of the thesis ch. 4 wedge hopper (§4.5.8, Figs. 4.18-4.24), MPM version. Base
case: phi = 25 deg, phi_w = 15 deg, everything else Table 4.2 (theta 30 deg, b 0.25 m, H 3 m,
rho 1600 kg/m3, E 10 MPa, nu 0.2, psi 15 -> 0 deg over eps_v 0 -> eps_cv). From the base one
parameter at a time is varied: Young's modulus E, internal friction angle phi, wall friction angle
phi_w and the constant-volume solid fraction eta_cv (thesis eq. 4.1: eps_cv = ln(eta_i/eta_cv),
eta_i = 0.64; the base eps_cv = 0.2 of Table 4.3 is eta_cv = 0.64 e^-0.2 = 0.5240 ~ pi/6, so the
pi/6 point *is* the base run).

Per case (1 s fill + `--discharge` s discharge with inflow, cell `--cell`):
- steady MDR of the full hopper (regression of the discharged mass from `--skip` s after opening,
  discharge.mean_discharge_rate) and its noise: the standard error of the mean of the 0.2 s window
  rates (discharge.discharge_rate), which is the yardstick the trends are judged against;
- outlet bulk density (outlet-path mean of the last 3 frames) and the outlet centre velocity (the
  outlet-path bin next to the axis, last 3 frames);
- MFI (discharge.mass_flow_index, last frame);
- position of the peak discharging wall normal stress along the wall (paths.wall_path, last 3
  frames; the one-cell bins are noisy (sub-cell stress mode, few particles per bin), so the peak is
  taken on a running mean over ~0.25 m of wall): s from the outlet edge and y; also the
  sigma_n-weighted mean height of the wall load (y_load), a steadier measure of where the load sits;
- wall time of the run.
Trend per parameter: the change of each figure from the lowest to the highest value, in % of the
base, and whether it exceeds twice the combined noise of the two end runs (else "flat"); the noise
is the window standard error for the MDR and the standard error over the last 3 frames taken one
at a time for the other figures.
The thesis's statements checked: MDR falls with phi (Fig. 4.20) and with phi_w (Fig. 4.23); the
peak wall stress moves up with phi (Fig. 4.19b) and phi_w (Fig. 4.21); eta_cv changes the outlet
bulk density (§4.5.8, last subsection). For reference the density of material at eta_cv,
rho_b eta_cv / eta_i, is printed next to the outlet density.

Second figure (profiles): outlet v_y across the outlet (Figs. 4.19a, 4.22) and the wall normal
stress normalised by its peak against height (Figs. 4.19b, 4.21) for every case.
"""
import csv
import json
import math

import numpy as np

from .discharge import discharge_rate
from .hopper_scene import ETA_INITIAL, eps_cv_from_eta
from .paths import frames, outlet_path, wall_path

BASE = dict(phi=25.0, wall_friction=15.0, young=1.0e7, eps_cv=0.2)
ETA_BASE = ETA_INITIAL * math.exp(-0.2)        # eta_cv of Table 4.3's eps_cv = 0.2 (~ pi/6)
DENSITY = 1600.0

# parameter -> (label, unit, scene keyword, how a CLI value maps to the scene value)
PARAMS = {
    "E": ("E", "MPa", "young", lambda v: v * 1.0e6),
    "phi": ("phi", "deg", "phi", float),
    "phi_w": ("phi_w", "deg", "wall_friction", float),
    "eta_cv": ("eta_cv", "-", "eps_cv", lambda v: 0.2 if abs(v - ETA_BASE) < 1e-3 else eps_cv_from_eta(v)),
}


def add_arguments(p):
    from .studies import add_case_arguments
    add_case_arguments(p, skip=0.5, skip_help="s after opening left out of the MDR")
    p.add_argument("--young", type=float, nargs="+", default=[5.0, 10.0, 20.0], help="E values [MPa]")
    p.add_argument("--phi", type=float, nargs="+", default=[25.0, 30.0, 35.0], help="phi values [deg]")
    p.add_argument("--phi-w", type=float, nargs="+", default=[10.0, 15.0, 20.0], help="phi_w values [deg]")
    p.add_argument("--eta-cv", type=float, nargs="+", default=[0.50, math.pi / 6, 0.55, 0.58],
                   help="eta_cv values (pi/6 within 1e-3 of 0.64 e^-0.2 is the base eps_cv = 0.2)")


def window_noise(hist, skip=0.5, window=0.2):
    """Standard error of the mean of the window MDRs (half model): the scatter a steady MDR carries."""
    rates = discharge_rate(hist, skip=skip, window=window)[3]
    if len(rates) < 2:
        return float("nan")
    return float(np.std(rates, ddof=1) / math.sqrt(len(rates)))


def peak_position(wp, smooth=3):
    """(s, y, sigma_n) of the peak of the running-mean wall normal stress of a wall path
    (rows s, y, sigma_n, tau, n). The running mean over `smooth` bins keeps a single noisy bin from
    being taken for the peak; the ends use the bins available."""
    if len(wp) == 0:
        return float("nan"), float("nan"), float("nan")
    sm = running_mean(wp[:, 2], smooth)
    i = int(np.nanargmax(sm))
    return float(wp[i, 0]), float(wp[i, 1]), float(sm[i])


def running_mean(v, n):
    """Centred running mean over n bins (n odd; fewer bins at the ends)."""
    v = np.asarray(v, dtype=float)
    pad = max(1, int(n)) // 2
    return np.array([np.nanmean(v[max(0, i - pad):i + pad + 1]) for i in range(len(v))])


def reduce_extra(r, cell, theta=30.0, outlet=0.25, skip=0.5, height=3.0):
    """Figures beyond hopper_run's: outlet centre speed, wall stress peak, profiles, and the noise of
    each figure: for the MDR the standard error of the window rates, for the others the standard
    error over the last 3 frames taken one at a time (each figure's frame-to-frame scatter)."""
    import h5py
    from .study_flow_mode import frame_mfis
    hist = np.genfromtxt(r["base"] + "_history.csv", delimiter=",", names=True)
    with h5py.File(r["base"] + ".h5", "r") as f:
        h = float(f["grid"].attrs["h"][0])
        g = frames(f, 3)
        op = outlet_path(g, h, theta, outlet)
        wp = wall_path(g, h, theta, outlet)
        # odd number of bins covering ~0.25 m of wall (one bin per cell)
        nb = max(3, 2 * int(round(0.125 / h)) + 1)
        per = []
        for gk in g:
            opk = outlet_path([gk], h, theta, outlet)
            wpk = wall_path([gk], h, theta, outlet)
            per.append([np.nanmean(opk[:, 2]), -opk[0, 1], peak_position(wpk, nb)[1], _load_centre(wpk)])
    per = np.array(per)
    mfis = frame_mfis(r["base"] + ".h5", theta, outlet, height)

    def se(v):
        v = np.asarray(v, dtype=float)
        return float(np.std(v, ddof=1) / math.sqrt(len(v))) if len(v) > 1 else float("nan")
    s_pk, y_pk, sig_pk = peak_position(wp, nb)
    return dict(v_centre=float(-op[0, 1]), s_peak=s_pk, y_peak=y_pk, sigma_peak=sig_pk, y_load=_load_centre(wp),
                noise=dict(mdr=2 * window_noise(hist, skip), rho_out=se(per[:, 0]), v_centre=se(per[:, 1]),
                           y_peak=se(per[:, 2]), y_load=se(per[:, 3]), mfi=se(mfis)),
                outlet_profile=op[:, :3].tolist(),
                wall_profile=np.c_[wp[:, :3], running_mean(wp[:, 2], nb)].tolist() if len(wp) else [])


def _load_centre(wp):
    """sigma_n-weighted mean height of a wall path (rows s, y, sigma_n, ...)."""
    return float(np.sum(wp[:, 2] * wp[:, 1]) / np.sum(wp[:, 2])) if len(wp) else float("nan")


def end_to_end(values, base, noise_lo, noise_hi):
    """Change from the first to the last value in % of `base`, and a verdict against 2x the
    combined noise of the two end values (noise = standard errors; nan noise -> no verdict)."""
    d = values[-1] - values[0]
    pct = 100.0 * d / base
    tol = 2.0 * math.hypot(noise_lo, noise_hi) if np.isfinite(noise_lo) and np.isfinite(noise_hi) else 0.0
    if abs(d) <= tol:
        verdict = "flat (within noise)"
    else:
        verdict = "rises" if d > 0 else "falls"
    monotone = bool(np.all(np.diff(values) > 0) or np.all(np.diff(values) < 0))
    return pct, verdict, monotone


def run(a):
    from .studies import case
    groups = {"E": a.young, "phi": a.phi, "phi_w": a.phi_w, "eta_cv": a.eta_cv}
    print(f"parametric study (thesis §4.5.8): base phi 25, phi_w 15 deg, Table 4.2 otherwise; cell {a.cell:g} m, "
          f"1 s fill + {a.discharge:g} s discharge with inflow", flush=True)
    rows = []
    for name, values in groups.items():
        label, unit, key, conv = PARAMS[name]
        for v in values:
            scene = dict(BASE)
            scene[key] = conv(v)
            r = case(a, cell=a.cell, discharge_time=a.discharge, **scene)
            x = reduce_extra(r, a.cell, skip=a.skip)
            eta = ETA_INITIAL * math.exp(-scene["eps_cv"])
            rows.append(dict(group=name, value=v, E_MPa=scene["young"] / 1e6, phi=scene["phi"],
                             phi_w=scene["wall_friction"], eps_cv=scene["eps_cv"], eta_cv=eta,
                             rho_cv=DENSITY * eta / ETA_INITIAL, particles=r["particles"], wall=r["wall"],
                             mdr=r["mdr_full"], mdr_noise=x["noise"]["mdr"], noise=x["noise"], rho_out=r["rho_out"],
                             v_out=-r["v_out"], v_centre=x["v_centre"], mfi=r["mfi"], s_peak=x["s_peak"],
                             y_peak=x["y_peak"], sigma_peak=x["sigma_peak"], y_load=x["y_load"], base=r["base"],
                             outlet_profile=x["outlet_profile"], wall_profile=x["wall_profile"]))
            print(f"  {name} = {v:.4g}: MDR {r['mdr_full']:.1f} kg/s/m, MFI {r['mfi']:.3f}, wall {r['wall']:.0f} s",
                  flush=True)
    hdr = (f"{'param':>6} {'value':>7} {'eps_cv':>6} {'MDR':>7} {'+-':>5} {'rho_out':>7} {'rho_cv':>6} "
           f"{'v_c':>6} {'v_mean':>6} {'MFI':>5} {'s_pk':>5} {'y_pk':>5} {'y_load':>6} {'sig_pk':>7} {'wall s':>6}")
    print("\n" + hdr)
    for r in rows:
        print(f"{r['group']:>6} {r['value']:7.4g} {r['eps_cv']:6.3f} {r['mdr']:7.1f} {r['mdr_noise']:5.1f} "
              f"{r['rho_out']:7.1f} {r['rho_cv']:6.0f} {r['v_centre']:6.3f} {r['v_out']:6.3f} {r['mfi']:5.3f} "
              f"{r['s_peak']:5.2f} {r['y_peak']:5.2f} {r['y_load']:6.3f} {r['sigma_peak']:7.0f} {r['wall']:6.0f}")
    print("MDR: full hopper, kg/s/m, +- window standard error; rho_out: outlet-path mean [kg/m3]; rho_cv = "
          "1600 eta_cv/0.64; v_c: outlet centre, v_mean: outlet-path mean downward speed [m/s]; s_pk/y_pk: peak wall normal "
          "stress (0.25 m running mean), distance along the wall from the outlet edge / height above the apex [m]; "
          "y_load: sigma_n-weighted mean height of the wall load [m]; sig_pk [Pa]")
    base_row = next(r for r in rows if r["group"] == "phi" and r["value"] == BASE["phi"]) \
        if any(r["group"] == "phi" and r["value"] == BASE["phi"] for r in rows) else rows[0]
    trends = {}
    print("\ntrends (lowest -> highest value; % of the base case; 'flat' if the change is within 2x the combined "
          "noise of the two end runs: window s.e. for MDR, s.e. over the last 3 frames otherwise):")
    for name in groups:
        g = [r for r in rows if r["group"] == name]
        if len(g) < 2:
            continue
        g.sort(key=lambda r: r["value"])
        t = {}
        for key in ("mdr", "rho_out", "v_centre", "mfi", "y_peak", "y_load"):
            vals = np.array([r[key] for r in g])
            pct, verdict, mono = end_to_end(vals, base_row[key], g[0]["noise"][key], g[-1]["noise"][key])
            t[key] = dict(change_pct=pct, verdict=verdict, monotone=mono, values=vals.tolist())
        trends[name] = t
        print(f"  {name:>6} {g[0]['value']:.4g} -> {g[-1]['value']:.4g}: "
              + "; ".join(f"{k} {v['verdict']} {v['change_pct']:+.1f}%{'' if v['monotone'] else ' (not monotone)'}"
                          for k, v in t.items()))
    # the thesis's statements, each with the quantity and the direction it claims
    claims = [("MDR falls with phi (thesis Fig. 4.20)", "phi", "mdr", "falls"),
              ("peak wall normal stress moves up with phi (Fig. 4.19b)", "phi", "y_peak", "rises"),
              ("MDR falls with phi_w (Fig. 4.23)", "phi_w", "mdr", "falls"),
              ("peak wall normal stress moves up with phi_w (Fig. 4.21)", "phi_w", "y_peak", "rises"),
              ("outlet bulk density changes with eta_cv (§4.5.8)", "eta_cv", "rho_out", "rises")]
    checks = {}
    print("\nthesis statements:")
    for text, name, key, want in claims:
        if name not in trends:
            continue
        t = trends[name][key]
        ok = t["verdict"] == want
        checks[text] = dict(holds=ok, verdict=t["verdict"], change_pct=t["change_pct"], values=t["values"])
        vals = ", ".join(f"{v:.4g}" for v in t["values"])
        print(f"  {text}: {'yes' if ok else 'NO'} ({key} {t['verdict']}, {t['change_pct']:+.1f}%: {vals})")

    out = a.out
    cols = ["group", "value", "E_MPa", "phi", "phi_w", "eps_cv", "eta_cv", "rho_cv", "particles", "wall", "mdr",
            "mdr_noise", "rho_out", "v_out", "v_centre", "mfi", "s_peak", "y_peak", "y_load", "sigma_peak", "base"]
    with open(f"{out}/parametric.csv", "w", newline="") as f:
        w = csv.writer(f)
        nk = ["mdr", "rho_out", "v_centre", "mfi", "y_peak", "y_load"]
        w.writerow(cols + [f"se_{k}" for k in nk])
        for r in rows:
            w.writerow([r[c] for c in cols] + [r["noise"][k] for k in nk])
    with open(f"{out}/parametric.json", "w") as f:
        json.dump(dict(cell=a.cell, discharge=a.discharge, skip=a.skip, base=BASE, rows=rows, trends=trends,
                       checks=checks), f, indent=1)
    _plot(rows, groups, f"{out}/parametric.png", f"{out}/parametric_profiles.png")
    print(f"\nwritten: {out}/parametric.csv, parametric.json, parametric.png, parametric_profiles.png")


def _plot(rows, groups, path, path_profiles):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [n for n in groups if any(r["group"] == n for r in rows)]
    xl = {"E": "E [MPa]", "phi": "phi [deg]", "phi_w": "phi_w [deg]", "eta_cv": "eta_cv [-]"}
    panels = [("mdr", "MDR [kg/s/m]"), ("rho_out", "outlet bulk density [kg/m3]"),
              ("v_centre", "outlet centre speed [m/s]"), ("mfi", "MFI [-]"), ("y_peak", "y of peak wall sigma_n [m]")]
    # y_load is drawn in the y_peak panel (open squares): peak and load centre together
    fig, ax = plt.subplots(len(panels), len(names), figsize=(3.2 * len(names), 2.3 * len(panels)),
                           sharex="col", squeeze=False)
    for j, n in enumerate(names):
        g = sorted([r for r in rows if r["group"] == n], key=lambda r: r["value"])
        x = [r["value"] for r in g]
        for i, (k, lab) in enumerate(panels):
            axx = ax[i, j]
            y = [r[k] for r in g]
            # bars: 2x the noise (window s.e. for MDR, s.e. over the last 3 frames otherwise)
            axx.errorbar(x, y, yerr=[2 * r["noise"][k] for r in g], fmt="o-", capsize=3)
            if k == "rho_out" and n == "eta_cv":
                axx.plot(x, [r["rho_cv"] for r in g], "k--", lw=1, label="1600 eta_cv/0.64")
                axx.legend(fontsize=7)
            if k == "mfi":
                axx.axhline(0.3, c="r", ls=":", lw=1)
            if k == "y_peak":
                axx.errorbar(x, [r["y_load"] for r in g], yerr=[2 * r["noise"]["y_load"] for r in g], fmt="s--",
                             mfc="none", capsize=3, label="load centre")
                axx.legend(fontsize=7)
            if j == 0:
                axx.set_ylabel(lab, fontsize=8)
            axx.tick_params(labelsize=7)
            axx.grid(alpha=0.3)
        ax[-1, j].set_xlabel(xl[n])
        ax[0, j].set_title(f"vary {n}", fontsize=9)
    fig.suptitle("MPM wedge hopper, parametric study (base phi 25, phi_w 15 deg; bars: 2x s.e., MDR from 0.2 s windows, others from the last 3 frames)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(2, len(names), figsize=(3.4 * len(names), 6.4), squeeze=False)
    for j, n in enumerate(names):
        g = sorted([r for r in rows if r["group"] == n], key=lambda r: r["value"])
        for r in g:
            lab = f"{n} = {r['value']:.3g}"
            op = np.array(r["outlet_profile"])
            ax[0, j].plot(op[:, 0], op[:, 1], "o-", ms=3, label=lab)
            wp = np.array(r["wall_profile"])
            if len(wp):
                ax[1, j].plot(wp[:, 3] / r["sigma_peak"], wp[:, 1], "-", label=lab)
                ax[1, j].plot([1.0], [r["y_peak"]], "k+")
        ax[0, j].set_xlabel("x from axis [m]")
        ax[1, j].set_xlabel("sigma_n / peak, 0.25 m running mean")
        ax[0, j].set_title(f"vary {n}", fontsize=9)
        ax[0, j].legend(fontsize=7)
        for k in range(2):
            ax[k, j].grid(alpha=0.3)
            ax[k, j].tick_params(labelsize=7)
    ax[0, 0].set_ylabel("outlet v_y [m/s] (negative: down)")
    ax[1, 0].set_ylabel("height above apex y [m]")
    fig.suptitle("outlet velocity (cf. Figs. 4.19a, 4.22) and normalised discharging wall normal stress "
                 "(cf. Figs. 4.19b, 4.21); last 3 frames; +: peak", fontsize=9)
    fig.tight_layout()
    fig.savefig(path_profiles, dpi=110)
    plt.close(fig)
