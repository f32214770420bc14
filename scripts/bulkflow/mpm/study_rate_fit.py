"""e: MDR vs outlet width b and tan(theta): fitted power-law exponents vs Rose-Tanaka (Fig. 4.15)

Thesis §4.5.6, eq. 4.5 and Fig. 4.15: the FEM mass discharge rate follows the Rose-Tanaka form
MDR ~ b^1.5 (tan theta)^-0.35. Here the MPM wedge hopper (Table 4.2 material: phi 20, phi_w 5,
psi 15 -> 0; H 3 m, with inflow) is run
- at theta = `--theta-b` (30 deg) for the outlet widths `--outlets`, and
- at b = `--b-theta` (0.25 m) for the half angles `--thetas`,
and the exponents n of MDR ~ b^n and m of MDR ~ (tan theta)^m are fitted by least squares on
log MDR against log b (log tan theta), with a 95 % interval from the slope's standard error and
Student's t (n_points - 2 dof). The same fits are made with MDR / rho_out (rho_out = outlet bulk
density, which changes from case to case; Beverloo/Rose-Tanaka are written for a flowing density),
so a density change is not mistaken for a kinematic one.

Which half angles enter the theta fit (decided before looking at the rates): Rose-Tanaka's factor
(tan theta tan phi_d)^-0.35 holds only below the transition angle theta < 90 deg - phi_d (45 deg in
the thesis form phi_d = 45 deg; above it F = 1, theory/beverloo.rose_tanaka_factor), and it describes
a converging mass-flow hopper, so a point enters only if theta < 90 - phi_d AND it is mass flow
(MFI > 0.3). The earlier sweep (src/mpm/README.md) had funnel flow (MFI 0.29) at 45 deg, so the
default range stops at 40 deg; points left out are drawn open and listed. The steep end is bounded
by the correlation too: F diverges as theta -> 0 (a vertical channel of width b is no orifice), so
10 deg is the lowest angle run; the fit without the steepest point is printed as a sensitivity.

Grid alignment of the outlet edge: hopper_scene puts node lines on x = 0 and y = y0, so the outlet
edge x = b/2 lies at b/(2h) cells from the axis; its fractional part (0 for b = 0.20, 0.30 m at
h = 0.05 m, 0.5 for 0.15, 0.25, 0.35, 0.45 m) decides how the corner between the outlet and the
wall is resolved, the resolution effect src/mpm/README.md notes for the convergence runs. The b fit
is therefore also made on the widths whose edge has the same offset as the base case b = 0.25 m
(the "grid-consistent" subset), and the offset is listed per point. With `--align-edge` (the
default) every width is run at the cell nearest to `--cell` that puts its edge mid-cell
(hopper_scene.aligned_cell: b = 0.20 m at h = 0.04 m, 0.30 m at 0.0429 m), so all widths are
grid-consistent; `--no-align-edge` runs them all at `--cell` and shows the artefact.
"""
import argparse
import csv
import json
import math

import numpy as np
from scipy import stats

from ..theory.beverloo import rose_tanaka_factor
from .hopper_scene import aligned_cell

G = 9.81


def add_arguments(p):
    from .studies import add_case_arguments
    add_case_arguments(p)
    p.add_argument("--outlets", type=float, nargs="+", default=[0.15, 0.20, 0.25, 0.30, 0.35, 0.45],
                   help="b [m]")
    p.add_argument("--theta-b", type=float, default=30.0, help="half angle of the b series [deg]")
    p.add_argument("--thetas", type=float, nargs="+", default=[10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0],
                   help="half angles [deg]")
    p.add_argument("--b-theta", type=float, default=0.25, help="outlet width of the theta series [m]")
    p.add_argument("--align-edge", action=argparse.BooleanOptionalAction, default=True,
                   help="run each width at the cell nearest --cell that puts the outlet edge mid-cell")
    p.add_argument("--phi-d", type=float, default=45.0,
                   help="Rose-Tanaka stagnant-zone angle: theta fit only below 90 - phi_d [deg]")


def power_law_fit(x, y, conf=0.95):
    """Least squares of log y = log A + k log x. Returns dict: exponent k, ci (half-width of the
    `conf` interval, Student t with n-2 dof; nan for 2 points), lo, hi, prefactor A, r2, n, and
    the x range. Non-positive or non-finite points are dropped."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    lx, ly = np.log(x[ok]), np.log(y[ok])
    n = len(lx)
    if n < 2:
        return dict(exponent=math.nan, ci=math.nan, lo=math.nan, hi=math.nan, prefactor=math.nan, r2=math.nan,
                    n=n, x_min=math.nan, x_max=math.nan)
    xm = lx.mean()
    sxx = np.sum((lx - xm) ** 2)
    k = float(np.sum((lx - xm) * (ly - ly.mean())) / sxx)
    a = float(ly.mean() - k * xm)
    res = ly - (a + k * lx)
    sst = np.sum((ly - ly.mean()) ** 2)
    r2 = float(1.0 - np.sum(res ** 2) / sst) if sst > 0 else 1.0
    if n > 2:
        se = math.sqrt(np.sum(res ** 2) / (n - 2) / sxx)
        ci = float(stats.t.ppf(0.5 + 0.5 * conf, n - 2) * se)
    else:
        ci = math.nan
    return dict(exponent=k, ci=ci, lo=k - ci, hi=k + ci, prefactor=math.exp(a), r2=r2, n=n,
                x_min=float(np.exp(lx.min())), x_max=float(np.exp(lx.max())))


def edge_offset(b, cell):
    """Fractional part of the outlet half-width in cells (0 = the outlet edge on a node line)."""
    q = 0.5 * b / cell
    return float(round(q - math.floor(q + 1e-9), 6)) % 1.0


def _fmt(f, ref):
    inside = f["lo"] <= ref <= f["hi"] if np.isfinite(f["ci"]) else False
    return (f"{f['exponent']:+.3f} +- {f['ci']:.3f}  [{f['lo']:+.3f}, {f['hi']:+.3f}]  R2 {f['r2']:.4f}  "
            f"(ref {ref:+.2f}: {'inside' if inside else 'outside'})")


def run(a):
    from .studies import case
    print(f"MDR vs b and theta (thesis Fig. 4.15): Table 4.2 material, cell {a.cell:g} m, 1 s fill + "
          f"{a.discharge:g} s discharge with inflow", flush=True)
    rows = []
    todo = [("b", a.theta_b, b) for b in a.outlets] + [("theta", t, a.b_theta) for t in a.thetas]
    for series, theta, b in todo:
        cell = aligned_cell(a.cell, b) if a.align_edge else a.cell
        r = case(a, cell=cell, discharge_time=a.discharge, theta=theta, outlet=b)
        rows.append(dict(series=series, theta=theta, b=b, cell=cell, tan_theta=math.tan(math.radians(theta)),
                         particles=r["particles"], wall=r["wall"], mdr=r["mdr_full"], rho_out=r["rho_out"],
                         v_out=r["v_out"], mfi=r["mfi"], C=r["mdr_full"] / (r["rho_out"] * math.sqrt(G) * b ** 1.5),
                         F_RT=rose_tanaka_factor(theta, a.phi_d), base=r["base"]))
        print(f"  {series}: theta {theta:g}, b {b:g}: MDR {r['mdr_full']:.1f}, MFI {r['mfi']:.3f}, "
              f"wall {r['wall']:.0f} s", flush=True)
    theta_max = 90.0 - a.phi_d
    for r in rows:
        r["in_fit"] = bool(r["mfi"] > 0.3 and (r["series"] == "b" or r["theta"] < theta_max))
        r["edge_offset"] = edge_offset(r["b"], r["cell"])
    print(f"\n{'series':>6} {'theta':>6} {'b m':>5} {'tan':>6} {'parts':>6} {'wall s':>6} {'MDR':>8} {'rho_out':>8} "
          f"{'MDR/rho':>8} {'C':>6} {'MFI':>6} {'F_RT':>5} {'edge':>4} fit")
    for r in rows:
        print(f"{r['series']:>6} {r['theta']:6.1f} {r['b']:5.2f} {r['tan_theta']:6.3f} {r['particles']:6d} "
              f"{r['wall']:6.0f} {r['mdr']:8.1f} {r['rho_out']:8.1f} {r['mdr'] / r['rho_out']:8.4f} {r['C']:6.3f} "
              f"{r['mfi']:6.3f} {r['F_RT']:5.2f} {r['edge_offset']:4.2f} {'yes' if r['in_fit'] else 'no'}")
    print("MDR: full hopper [kg/s/m]; MDR/rho [m2/s]; C = MDR/(rho_out sqrt(g) b^1.5); F_RT: Rose-Tanaka "
          f"factor (tan theta tan {a.phi_d:g})^-0.35; edge: fractional part of b/(2 cell) (outlet edge offset from "
          f"a node line); fit: point used (mass flow, theta < {theta_max:g} deg)")

    fits = {}
    bs = [r for r in rows if r["series"] == "b" and r["in_fit"]]
    ts = [r for r in rows if r["series"] == "theta" and r["in_fit"]]
    fits["b"] = power_law_fit([r["b"] for r in bs], [r["mdr"] for r in bs])
    fits["b_rho"] = power_law_fit([r["b"] for r in bs], [r["mdr"] / r["rho_out"] for r in bs])
    fits["tan"] = power_law_fit([r["tan_theta"] for r in ts], [r["mdr"] for r in ts])
    fits["tan_rho"] = power_law_fit([r["tan_theta"] for r in ts], [r["mdr"] / r["rho_out"] for r in ts])
    # grid-consistent subset: outlet edge at the same offset from a node line as the base case
    off0 = edge_offset(a.b_theta, aligned_cell(a.cell, a.b_theta) if a.align_edge else a.cell)
    fits["edge_offset_base"] = off0
    bg = [r for r in bs if abs(r["edge_offset"] - off0) < 1e-6]
    fits["b_grid"] = power_law_fit([r["b"] for r in bg], [r["mdr"] for r in bg])
    fits["b_rho_grid"] = power_law_fit([r["b"] for r in bg], [r["mdr"] / r["rho_out"] for r in bg])
    # sensitivity: without the steepest hopper (where F_RT is least trustworthy)
    ts2 = sorted(ts, key=lambda r: r["theta"])[1:]
    fits["tan_no_steepest"] = power_law_fit([r["tan_theta"] for r in ts2], [r["mdr"] for r in ts2])
    fits["tan_rho_no_steepest"] = power_law_fit([r["tan_theta"] for r in ts2], [r["mdr"] / r["rho_out"] for r in ts2])
    rng_b = f"b {fits['b']['x_min']:.2f}-{fits['b']['x_max']:.2f} m at theta {a.theta_b:g} deg ({fits['b']['n']} pts)"
    th = [r["theta"] for r in ts]
    rng_t = f"theta {min(th):g}-{max(th):g} deg at b {a.b_theta:g} m ({len(ts)} pts)" if ts else "none"
    th2 = [r["theta"] for r in ts2]
    rng_t2 = f"theta {min(th2):g}-{max(th2):g} deg ({len(ts2)} pts)" if ts2 else "none"
    print("\nfitted exponents (least squares in log-log, 95 % interval):")
    print(f"  MDR         ~ b^n          n = {_fmt(fits['b'], 1.5)}   {rng_b}")
    print(f"  MDR/rho_out ~ b^n          n = {_fmt(fits['b_rho'], 1.5)}")
    widths = ", ".join(f"{r['b']:g}" for r in bg)
    rng_bg = f"b {widths} m (outlet edge offset {off0:g} cell, as b = {a.b_theta:g})"
    print(f"  grid-consistent subset, {rng_bg}:")
    print(f"  MDR         ~ b^n          n = {_fmt(fits['b_grid'], 1.5)}")
    print(f"  MDR/rho_out ~ b^n          n = {_fmt(fits['b_rho_grid'], 1.5)}")
    print(f"  MDR         ~ (tan th)^m   m = {_fmt(fits['tan'], -0.35)}   {rng_t}")
    print(f"  MDR/rho_out ~ (tan th)^m   m = {_fmt(fits['tan_rho'], -0.35)}")
    print(f"  sensitivity, {rng_t2}:")
    print(f"  MDR         ~ (tan th)^m   m = {_fmt(fits['tan_no_steepest'], -0.35)}")
    print(f"  MDR/rho_out ~ (tan th)^m   m = {_fmt(fits['tan_rho_no_steepest'], -0.35)}")
    print("  reference: Rose-Tanaka (thesis eq. 4.5) n = 1.5, m = -0.35")
    # local exponent between neighbouring half angles: shows whether one power law fits the range
    tsort = sorted(ts, key=lambda r: r["theta"])
    local = []
    for r0, r1 in zip(tsort[:-1], tsort[1:]):
        k = math.log(r1["mdr"] / r0["mdr"]) / math.log(r1["tan_theta"] / r0["tan_theta"])
        local.append(dict(theta_lo=r0["theta"], theta_hi=r1["theta"], m_local=k))
    fits["tan_local"] = local
    print("  local exponent d ln MDR / d ln tan(theta): "
          + ", ".join(f"{q['theta_lo']:g}-{q['theta_hi']:g}: {q['m_local']:+.2f}" for q in local))

    out = a.out
    cols = ["series", "theta", "b", "cell", "tan_theta", "particles", "wall", "mdr", "rho_out", "v_out", "mfi", "C", "F_RT",
            "edge_offset", "in_fit", "base"]
    with open(f"{out}/rate_fit.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols + ["mdr_over_rho"])
        for r in rows:
            w.writerow([r[c] for c in cols] + [r["mdr"] / r["rho_out"]])
    with open(f"{out}/rate_fit.json", "w") as f:
        json.dump(dict(cell=a.cell, discharge=a.discharge, theta_b=a.theta_b, b_theta=a.b_theta, phi_d=a.phi_d,
                       fit_rule=f"mass flow (MFI > 0.3) and theta < 90 - phi_d = {theta_max:g} deg",
                       range_b=rng_b, range_b_grid=rng_bg, range_theta=rng_t, range_theta_sensitivity=rng_t2,
                       reference=dict(n=1.5, m=-0.35), fits=fits, rows=rows), f, indent=1)
    _plot(rows, fits, a, f"{out}/rate_fit.png")
    print(f"\nwritten: {out}/rate_fit.csv, rate_fit.json, rate_fit.png")


def _plot(rows, fits, a, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    for j, (series, key, xlab, ref, refname) in enumerate(
            (("b", "b", "outlet width b [m]", 1.5, "b^1.5"),
             ("theta", "tan_theta", "tan(theta) [-]", -0.35, "(tan theta)^-0.35"))):
        g = sorted([r for r in rows if r["series"] == series], key=lambda r: r[key])
        if not g:
            continue
        fk = "b" if series == "b" else "tan"
        # normalise by the fits' value at the geometric middle of the fitted range so MDR and
        # MDR/rho_out (different units) share one log axis and the slopes compare directly
        xin = np.array([r[key] for r in g if r["in_fit"]])
        xmid = math.exp(np.mean(np.log(xin))) if len(xin) else g[0][key]
        for q, lab, mk, col in (("mdr", "MDR", "o", "C0"), ("mdr_rho", "MDR / rho_out", "x", "C2")):
            f = fits[fk] if q == "mdr" else fits[fk + "_rho"]
            norm = f["prefactor"] * xmid ** f["exponent"]
            x = np.array([r[key] for r in g])
            y = np.array([r["mdr"] if q == "mdr" else r["mdr"] / r["rho_out"] for r in g]) / norm
            inf = np.array([r["in_fit"] for r in g])
            ax[j].plot(x[inf], y[inf], mk, c=col, label=f"{lab} (used)")
            if (~inf).any():
                ax[j].plot(x[~inf], y[~inf], mk, mfc="none", c=col, label=f"{lab} (not used)")
            xx = np.geomspace(x.min(), x.max(), 50)
            ax[j].plot(xx, (xx / xmid) ** f["exponent"], "-", c=col, lw=1,
                       label=f"fit: {f['exponent']:+.3f} +- {f['ci']:.3f}")
            if series == "b" and q == "mdr" and np.isfinite(fits["b_grid"]["exponent"]):
                fg = fits["b_grid"]
                ax[j].plot(xx, fg["prefactor"] * xx ** fg["exponent"] / norm, ":", c=col, lw=1.2,
                           label=f"fit, edge offset as b = {a.b_theta:g}: {fg['exponent']:+.3f} +- {fg['ci']:.3f}")
                for xi, yi, r in zip(x, y, g):
                    if abs(r["edge_offset"] - fits["edge_offset_base"]) > 1e-6:
                        ax[j].annotate(f"edge offset {r['edge_offset']:g}", (xi, yi), fontsize=7, xytext=(4, -10),
                                       textcoords="offset points")
            if series == "theta" and q == "mdr":
                for xi, yi, r in zip(x, y, g):
                    ax[j].annotate(f"{r['theta']:g}°", (xi, yi), fontsize=7, xytext=(3, 4),
                                   textcoords="offset points")
        xx = np.geomspace(min(r[key] for r in g), max(r[key] for r in g), 50)
        ax[j].plot(xx, (xx / xmid) ** ref, "k--", lw=1, label=f"Rose-Tanaka {refname}")
        ax[j].set_xscale("log")
        ax[j].set_yscale("log")
        ax[j].set_xlabel(xlab)
        ax[j].grid(alpha=0.3, which="both")
        ax[j].legend(fontsize=7)
    ax[0].set_ylabel("rate / fit at mid-range [-]")
    ax[0].set_title(f"(a) vs outlet width, theta = {a.theta_b:g} deg (cf. Fig. 4.15a)", fontsize=10)
    ax[1].set_title(f"(b) vs half angle, b = {a.b_theta:g} m (cf. Fig. 4.15b)", fontsize=10)
    fig.suptitle(f"MPM wedge hopper, Table 4.2 material, cell {a.cell:g} m"
                 f"{' (each width at the cell that puts its outlet edge mid-cell)' if a.align_edge else ''}: "
                 "MDR power laws (95 % intervals)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
