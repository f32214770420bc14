"""f: flow mode by the mass-flow index as theta, phi and phi_w vary one at a time (thesis §4.5.7)

Thesis §4.5.7 (Fig. 4.16, Table 4.4): the flow mode of the FEM hopper is told by the mass-flow
index MFI = mean wall velocity / mean centreline velocity (mass flow if MFI > 0.3, funnel flow
below; Ketterhagen et al. 2009), and each of the three chart parameters (half angle theta,
internal friction angle phi, wall friction angle phi_w) is varied with the other two fixed.

Here, from the base point theta = 30, phi = 25, phi_w = 15 deg (the §4.5.8 base case, rest Table
4.2; its runs are shared with `parametric`), each parameter takes several values; per run the MFI
(discharge.mass_flow_index, last frame) and its mode are printed, with the MFI of each of the last
3 frames as a noise gauge. Where the MFI of two neighbouring values brackets 0.3, the transition
is located by linear interpolation of MFI between them. If a series does not cross 0.3 it is
extended (up to `--extend` points, by its last step, within physical limits) in the direction in
which the MFI moves towards 0.3 -- the choice of ranges is thus checked by the data, not tuned.

Why these ranges (theory/flow_mode.py, docs/theory/hopper_theory.md §h): for delta = phi = 25 deg the conical
mass-flow limit is theta_c = 40 deg at phi_w = 15 deg (58 deg at 5, 29.5 deg at 20); the plane
(wedge) limit is larger (rule of thumb +10 deg). Jenike's plane-flow chart (thesis Fig. 4.16) is
not available (no closed form, no digitised data), so the theta-phi_w plot carries the conical
closed form (a real boundary, but for cones) and the +10 deg rule of thumb, marked as approximate.
The earlier MPM sweep (src/mpm/README.md) turned to funnel flow near 45 deg already at phi_w = 5.
"""
import csv
import json
import math

import numpy as np

from ..theory.flow_mode import MFI_THRESHOLD, conical_mass_flow_limit, plane_boundary_rule_of_thumb

BASE = dict(theta=30.0, phi=25.0, wall_friction=15.0)
# series -> (scene keyword, physical range allowed when extending)
SERIES = {"theta": ("theta", (5.0, 60.0)), "phi_w": ("wall_friction", (0.0, None)), "phi": ("phi", (15.0, 45.0))}


def add_arguments(p):
    from .studies import add_case_arguments
    add_case_arguments(p)
    p.add_argument("--thetas", type=float, nargs="+", default=[20.0, 25.0, 30.0, 35.0, 40.0])
    p.add_argument("--phi-ws", type=float, nargs="+", default=[5.0, 10.0, 15.0, 20.0, 25.0])
    p.add_argument("--phis", type=float, nargs="+", default=[20.0, 25.0, 30.0, 35.0, 40.0])
    p.add_argument("--extend", type=int, default=2, help="extra points per series if it does not cross 0.3")


def mfi_crossings(x, mfi, level=MFI_THRESHOLD):
    """Where MFI(x) passes `level`, by linear interpolation between neighbouring points (x sorted).
    Returns a list of dicts: x (crossing), lo, hi (bracketing x values), direction ('falls' if MFI
    goes from above to below the level as x grows, else 'rises'). A point exactly at the level is
    its own crossing."""
    x = np.asarray(x, dtype=float)
    m = np.asarray(mfi, dtype=float)
    o = np.argsort(x)
    x, m = x[o], m[o]
    out = []
    for i in range(len(x) - 1):
        a, b = m[i] - level, m[i + 1] - level
        if not (np.isfinite(a) and np.isfinite(b)):
            continue
        if a == 0.0:
            if i == 0 or (m[i - 1] - level) != 0.0:
                out.append(dict(x=float(x[i]), lo=float(x[i]), hi=float(x[i]),
                                direction="falls" if b < 0 else "rises"))
            continue
        if a * b < 0:
            xc = x[i] + (x[i + 1] - x[i]) * a / (a - b)
            out.append(dict(x=float(xc), lo=float(x[i]), hi=float(x[i + 1]), direction="falls" if a > 0 else "rises"))
    if len(x) and m[-1] - level == 0.0 and (len(x) == 1 or m[-2] - level != 0.0):
        out.append(dict(x=float(x[-1]), lo=float(x[-1]), hi=float(x[-1]), direction="at end"))
    return out


def next_value(xs, mfis, lim, level=MFI_THRESHOLD):
    """The next value to try for a series that does not cross `level`: one step (the spacing of the
    last two points at that end) beyond the end towards which the MFI approaches the level; None if
    the series crosses, has fewer than 2 points, moves away from the level, or the step leaves lim."""
    o = np.argsort(xs)
    x = np.asarray(xs, dtype=float)[o]
    m = np.asarray(mfis, dtype=float)[o]
    if len(x) < 2 or mfi_crossings(x, m, level):
        return None
    above = m[0] > level
    # MFI above the level everywhere: go where it is lowest; below everywhere: where it is highest
    hi_end = (m[-1] < m[0]) if above else (m[-1] > m[0])
    v = x[-1] + (x[-1] - x[-2]) if hi_end else x[0] - (x[1] - x[0])
    lo, hi = lim
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        return None
    return float(v)


def frame_mfis(h5path, theta, outlet=0.25, height=3.0, n=3):
    """MFI of each of the last n particle frames (discharge.mass_flow_index's definition, per frame)."""
    import h5py
    vals = []
    with h5py.File(h5path, "r") as f:
        h = float(f["grid"].attrs["h"][0])
        keys = sorted(f["particles"].keys())[-n:]
        t = math.radians(theta)
        y0 = 0.5 * outlet / math.tan(t)
        for k in keys:
            g = f["particles"][k]
            x, v = g["coordinates"][:], g["V"][:]
            d_wall = x[:, 1] * math.sin(t) - x[:, 0] * math.cos(t)
            band = (x[:, 1] > y0 + 2 * outlet) & (x[:, 1] < y0 + 0.75 * height)
            wall, axis = band & (d_wall < h), band & (x[:, 0] < h)
            vals.append(float(v[wall, 1].mean() / v[axis, 1].mean()) if wall.any() and axis.any() else math.nan)
    return vals


def run(a):
    from .studies import case
    print(f"flow mode by MFI (thesis §4.5.7): base theta {BASE['theta']:g}, phi {BASE['phi']:g}, phi_w "
          f"{BASE['wall_friction']:g} deg, Table 4.2 otherwise; cell {a.cell:g} m, 1 s fill + {a.discharge:g} s "
          f"discharge with inflow", flush=True)
    lists = {"theta": list(a.thetas), "phi_w": list(a.phi_ws), "phi": list(a.phis)}
    rows = []

    def one(series, v):
        key = SERIES[series][0]
        scene = dict(BASE)
        scene[key] = v
        r = case(a, cell=a.cell, discharge_time=a.discharge, **scene)
        fm = frame_mfis(r["base"] + ".h5", scene["theta"])
        row = dict(series=series, value=v, theta=scene["theta"], phi=scene["phi"], phi_w=scene["wall_friction"],
                   mfi=r["mfi"], mfi_frames=fm, mode="mass" if r["mfi"] > MFI_THRESHOLD else "funnel",
                   mdr=r["mdr_full"], particles=r["particles"], wall=r["wall"], base=r["base"],
                   theta_c_cone=conical_mass_flow_limit(scene["phi"], scene["wall_friction"]),
                   theta_c_plane_rot=plane_boundary_rule_of_thumb(scene["phi"], scene["wall_friction"])["theta_c_deg"])
        print(f"  {series} = {v:g}: MFI {r['mfi']:.3f} ({row['mode']}), wall {r['wall']:.0f} s", flush=True)
        return row

    for series, vals in lists.items():
        lim = SERIES[series][1]
        if series == "phi_w":
            lim = (lim[0], BASE["phi"])             # a wall rougher than the material shears inside it
        got = [one(series, v) for v in vals]
        for _ in range(a.extend):
            v = next_value([r["value"] for r in got], [r["mfi"] for r in got], lim)
            if v is None:
                break
            print(f"  {series}: no crossing of {MFI_THRESHOLD} yet, adding {v:g}", flush=True)
            got.append(one(series, v))
        rows += got

    trans = {}
    print(f"\n{'series':>6} {'theta':>6} {'phi':>5} {'phi_w':>5} {'MFI':>6} {'last 3 frames':>20} {'mode':>7} "
          f"{'MDR':>7} {'th_c cone':>9} {'wall s':>6}")
    for series in lists:
        g = sorted([r for r in rows if r["series"] == series], key=lambda r: r["value"])
        for r in g:
            fr = " ".join(f"{v:.3f}" for v in r["mfi_frames"])
            print(f"{series:>6} {r['theta']:6.1f} {r['phi']:5.1f} {r['phi_w']:5.1f} {r['mfi']:6.3f} {fr:>20} "
                  f"{r['mode']:>7} {r['mdr']:7.1f} {r['theta_c_cone']:9.1f} {r['wall']:6.0f}")
        trans[series] = mfi_crossings([r["value"] for r in g], [r["mfi"] for r in g])
    print("MFI: last frame (the shared definition); last 3 frames: the same per frame (noise); MDR kg/s/m; "
          "th_c cone: conical mass-flow limit for delta = phi (theory/flow_mode.py; the plane chart is not available)")
    print(f"\ntransition (MFI = {MFI_THRESHOLD} by linear interpolation between the bracketing points):")
    for series in lists:
        if trans[series]:
            for c in trans[series]:
                print(f"  {series}: {c['x']:.2f} deg (between {c['lo']:g} and {c['hi']:g}; MFI {c['direction']} "
                      f"through {MFI_THRESHOLD} as {series} grows)")
        else:
            g = [r["mfi"] for r in rows if r["series"] == series]
            print(f"  {series}: no crossing in the range run (MFI {min(g):.3f}..{max(g):.3f})")
    tc = conical_mass_flow_limit(BASE["phi"], BASE["wall_friction"])
    print(f"  theory at the base (delta = phi = {BASE['phi']:g}, phi_w = {BASE['wall_friction']:g}): conical limit "
          f"theta_c = {tc:.1f} deg; plane rule of thumb {tc + 10:.1f} deg (approximate, not Jenike's chart)")

    out = a.out
    cols = ["series", "value", "theta", "phi", "phi_w", "mfi", "mode", "mdr", "particles", "wall", "theta_c_cone",
            "theta_c_plane_rot", "base"]
    with open(f"{out}/flow_mode.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols + ["mfi_frame_min", "mfi_frame_max"])
        for r in rows:
            w.writerow([r[c] for c in cols] + [min(r["mfi_frames"]), max(r["mfi_frames"])])
    with open(f"{out}/flow_mode.json", "w") as f:
        json.dump(dict(cell=a.cell, discharge=a.discharge, base=BASE, threshold=MFI_THRESHOLD, rows=rows,
                       transitions=trans, theory=dict(conical_theta_c_base=tc,
                                                      plane_rule_of_thumb_base=tc + 10.0,
                                                      note="Jenike's plane-flow chart not available")), f, indent=1)
    _plot(rows, trans, a, f"{out}/flow_mode.png")
    print(f"\nwritten: {out}/flow_mode.csv, flow_mode.json, flow_mode.png")


def _plot(rows, trans, a, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 4, figsize=(17, 5.0), gridspec_kw=dict(width_ratios=[1, 1, 1, 1.25]))
    labels = {"theta": "half angle theta [deg]", "phi_w": "wall friction angle phi_w [deg]",
              "phi": "internal friction angle phi [deg]"}
    for j, s in enumerate(("theta", "phi_w", "phi")):
        g = sorted([r for r in rows if r["series"] == s], key=lambda r: r["value"])
        if not g:
            continue
        x = np.array([r["value"] for r in g])
        m = np.array([r["mfi"] for r in g])
        lo = np.array([min(r["mfi_frames"]) for r in g])
        hi = np.array([max(r["mfi_frames"]) for r in g])
        ax[j].fill_between(x, lo, hi, color="C0", alpha=0.2, label="range of last 3 frames")
        ax[j].plot(x, m, "o-", c="C0", label="MFI (last frame)")
        ax[j].axhline(MFI_THRESHOLD, c="r", ls=":", label="MFI = 0.3")
        for c in trans.get(s, []):
            ax[j].axvline(c["x"], c="k", ls="--", lw=1)
            ax[j].annotate(f"{c['x']:.1f}°", (c["x"], MFI_THRESHOLD), xytext=(4, 8), textcoords="offset points",
                           fontsize=8)
        ax[j].set_xlabel(labels[s])
        ax[j].grid(alpha=0.3)
        fixed = {"theta": f"phi {BASE['phi']:g}, phi_w {BASE['wall_friction']:g}",
                 "phi_w": f"theta {BASE['theta']:g}, phi {BASE['phi']:g}",
                 "phi": f"theta {BASE['theta']:g}, phi_w {BASE['wall_friction']:g}"}[s]
        ax[j].set_title(f"vary {s} ({fixed} deg)", fontsize=9)
        ax[j].legend(fontsize=7)
    ax[0].set_ylabel("mass-flow index [-]")
    # theta - phi_w plane (thesis Fig. 4.16 axes): points of the theta and phi_w series
    q = ax[3]
    pts = [r for r in rows if r["series"] in ("theta", "phi_w") or (r["series"] == "phi" and r["value"] == BASE["phi"])]
    for r in pts:
        mass = r["mode"] == "mass"
        q.plot(r["theta"], r["phi_w"], "o", ms=8, c="C0" if mass else "C3", mfc="C0" if mass else "none")
        # theta-series labels below the points, phi_w-series labels to the right (they would overlap)
        off = (-9, -13) if r["series"] == "theta" else (6, -3)
        q.annotate(f"{r['mfi']:.2f}", (r["theta"], r["phi_w"]), xytext=off, textcoords="offset points", fontsize=7)
    for s, c0 in (("theta", "theta"), ("phi_w", "phi_w")):
        for c in trans.get(s, []):
            xy = (c["x"], BASE["wall_friction"]) if s == "theta" else (BASE["theta"], c["x"])
            q.plot(*xy, "k*", ms=11)
    wf = np.linspace(0.0, BASE["phi"], 200)
    tc = np.array([conical_mass_flow_limit(BASE["phi"], w) for w in wf])
    q.plot(tc, wf, "k-", lw=1.2, label=f"conical limit, delta = {BASE['phi']:g} (closed form)")
    q.plot(tc + 10.0, wf, "k--", lw=1, label="plane: conical + 10 deg (rule of thumb, approx.)")
    q.plot([], [], "o", c="C0", label="MPM mass flow (MFI > 0.3)")
    q.plot([], [], "o", c="C3", mfc="none", label="MPM funnel flow")
    q.plot([], [], "k*", label="MPM transition (interpolated)")
    q.set_xlim(0, 75)
    q.set_ylim(0, BASE["phi"] + 2)
    q.set_xlabel("half angle theta [deg]")
    q.set_ylabel("wall friction angle phi_w [deg]")
    q.set_title(f"theta-phi_w plane, phi = {BASE['phi']:g} deg (Jenike's plane chart not available)", fontsize=9)
    q.grid(alpha=0.3)
    q.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    fig.suptitle(f"MPM wedge hopper, flow mode by MFI; cell {a.cell:g} m, 1 s fill + {a.discharge:g} s discharge",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
