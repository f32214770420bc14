"""MPM wedge-hopper studies of thesis ch. 4, one command each:

    bulkflow-mpm-study convergence   a / item 6: grid (and shape) convergence, accuracy vs cost
    bulkflow-mpm-study sweep         first look at MDR and flow mode vs outlet width and half angle
    bulkflow-mpm-study mdr-time      b: MDR and outlet density vs time, psi 15 -> 0 vs constant 10 deg (Fig. 4.14)
    bulkflow-mpm-study walker        c: filling and discharging wall normal stress vs modified Walker (Fig. 4.12)
    bulkflow-mpm-study kinematic     d: vertical velocity vs the kinematic model, D vs height (Fig. 4.13)
    bulkflow-mpm-study rate-fit      e: MDR vs b and tan(theta): fitted exponents (Fig. 4.15)
    bulkflow-mpm-study flow-mode     f: MFI as theta, phi, phi_w vary one at a time (§4.5.7)
    bulkflow-mpm-study mc-dp         g: Mohr-Coulomb vs plane-strain matched Drucker-Prager (Figs. 4.10-4.11)
    bulkflow-mpm-study parametric    h: effects of E, phi, phi_w, eta_cv (§4.5.8)

`bulkflow-mpm-study NAME --help` lists a study's options. Every study writes CSV, PNG and JSON
under `--out` (default out/mpm_study/NAME) and shares its runs through out/mpm_study/runs
(hopper_run.py: a run is named by its scene's hash and not repeated).

convergence: for each cell size the thesis ch. 4 wedge hopper (with inflow) is written, run (1 s
fill + `--discharge` s) and reduced: steady MDR (regression of the discharged mass from 0.5 s after
opening to the end), mean outlet velocity and density, MFI, wall time and particle-steps; each
figure's relative difference from the finest run (the reference), against wall time.
sweep: every (theta, b) pair with the other at its Table 4.2 value (30 deg, 0.25 m); the
full-hopper MDR, C = MDR / (rho_b sqrt(g) b^1.5) with rho_b the outlet bulk density, the MFI.
"""
import argparse
import importlib
import importlib.util
import sys
from pathlib import Path

import numpy as np

from .hopper_run import DEFAULT_EXE, run_hopper
from .paths import frames, outlet_path, wall_path

# study name -> module of this package with add_arguments(parser) and run(args)
MODULE_STUDIES = {
    "mdr-time": "study_mdr_time",
    "walker": "study_walker",
    "kinematic": "study_kinematic",
    "rate-fit": "study_rate_fit",
    "flow-mode": "study_flow_mode",
    "mc-dp": "study_mc_dp",
    "parametric": "study_parametric",
    "bins": "study_bins",
    "conical": "study_conical",
}


def add_common(p, name):
    p.add_argument("--out", default=f"out/mpm_study/{name}", help="where the CSV/PNG/JSON go")
    p.add_argument("--runs", default="out/mpm_study/runs", help="shared run directory")
    p.add_argument("--bulkflow", default=DEFAULT_EXE, help="solver executable")
    p.add_argument("--no-reuse", action="store_true", help="run every case again")


def add_case_arguments(p, cell=0.05, discharge=1.5, field_frames=None, skip=None,
                       skip_help="average discharge frames from this time after opening [s]"):
    """The options every study's runs share: cell, discharge time and, where the study uses them,
    the particle frames per step and the time after opening that is left out."""
    p.add_argument("--cell", type=float, default=cell, help="grid cell [m]")
    p.add_argument("--discharge", type=float, default=discharge, help="discharge time [s] after the 1 s fill")
    if field_frames is not None:
        p.add_argument("--field-frames", type=int, default=field_frames, help="particle frames per step")
    if skip is not None:
        p.add_argument("--skip", type=float, default=skip, help=skip_help)


def case(a, **scene):
    """One run of a study (shared across studies through a.runs)."""
    return run_hopper(a.bulkflow, a.runs, reuse=not a.no_reuse, **scene)


def _profiles(r, frames_used=3):
    """Outlet v_y profile and discharging wall normal stress of a run (last frames averaged)."""
    import h5py
    sc = r["scene"]
    with h5py.File(r["base"] + ".h5", "r") as f:
        groups = frames(f, frames_used)
        op = outlet_path(groups, sc["cell"], sc.get("theta", 30.0), sc.get("outlet", 0.25))
        # bins of 0.1 m whatever the cell, so profiles of different resolutions compare bin for bin
        wp = wall_path(groups, sc["cell"], sc.get("theta", 30.0), sc.get("outlet", 0.25), bin_width=0.1)
    return op, wp


def profile_difference(s_ref, v_ref, s, v):
    """RMS of (v - v_ref) over the reference points inside the other profile's range, relative to
    the RMS of v_ref there: how far a coarse profile lies from the reference, as one number."""
    s_ref, v_ref, s, v = (np.asarray(q, dtype=float) for q in (s_ref, v_ref, s, v))
    ok = np.isfinite(v)
    s, v = s[ok], v[ok]
    inside = (s_ref >= s.min()) & (s_ref <= s.max()) & np.isfinite(v_ref)
    if inside.sum() < 2:
        return float("nan")
    d = np.interp(s_ref[inside], s, v) - v_ref[inside]
    return float(np.sqrt(np.mean(d * d)) / np.sqrt(np.mean(v_ref[inside] ** 2)))


def convergence(a):
    """Study a and item 6: grid size, particles per cell and shape functions against the steady
    MDR, the outlet centre velocity, the outlet v_y profile and the discharging wall normal stress
    (thesis Fig. 4.7), with the wall time of each run."""
    # Every cell puts the outlet edge mid-cell (x = b/2 = (k + 1/2) h): where the edge falls in a
    # cell decides how the outlet corner is resolved, and mixing offsets made the series jump by
    # +-18 % (cells 0.1/0.07/0.05/0.035 m: offsets 0.25/0.79/0.5/0.57). --cells overrides.
    cells = a.cells or [0.125 / n for n in a.edge_cells]
    variant = cells[[abs(c - a.variant_cell) for c in cells].index(min(abs(c - a.variant_cell) for c in cells))]
    cases = [(c, a.ppc, a.shape) for c in cells]
    cases += [(variant, p, a.shape) for p in a.ppcs if (variant, p, a.shape) not in cases]
    cases += [(variant, a.ppc, sh) for sh in a.shapes if (variant, a.ppc, sh) not in cases]
    rows = []
    for cell, ppc, shape in cases:
        r = case(a, cell=cell, ppc=ppc, discharge_time=a.discharge, shape=shape)
        r.update(cell=cell, ppc=ppc, shape=shape)
        r["outlet_profile"], r["wall_profile"] = _profiles(r)
        r["v_centre"] = float(r["outlet_profile"][0, 1])
        rows.append(r)
    ref = min((r for r in rows if r["ppc"] == a.ppc and r["shape"] == a.shape), key=lambda r: r["cell"])
    print(f"wedge hopper (thesis ch. 4), 1 s fill + {a.discharge:g} s discharge with inflow; reference: "
          f"cell {ref['cell']:g} m, {ref['ppc']} PPC, {ref['shape']}")
    head = (f"{'cell':>6} {'PPC':>3} {'shape':>6} {'particles':>9} {'wall s':>7} {'MDR kg/s/m':>10} {'dMDR':>7} "
            f"{'v_c m/s':>8} {'dv_c':>7} {'rho_out':>7} {'MFI':>5} {'d v(x)':>7} {'d sig_n':>7}")
    print(head)
    table = []
    for r in rows:
        dv_prof = profile_difference(ref["outlet_profile"][:, 0], ref["outlet_profile"][:, 1],
                                     r["outlet_profile"][:, 0], r["outlet_profile"][:, 1])
        dsig = profile_difference(ref["wall_profile"][:, 0], ref["wall_profile"][:, 2],
                                  r["wall_profile"][:, 0], r["wall_profile"][:, 2])
        row = dict(cell=r["cell"], ppc=r["ppc"], shape=r["shape"], particles=r["particles"], wall_s=r["wall"],
                   mdr_full=r["mdr_full"], d_mdr=r["mdr"] / ref["mdr"] - 1, v_centre=r["v_centre"],
                   d_v_centre=r["v_centre"] / ref["v_centre"] - 1, rho_out=r["rho_out"], mfi=r["mfi"],
                   d_outlet_profile=dv_prof, d_wall_stress=dsig)
        table.append(row)
        print(f"{row['cell']:6.4f} {row['ppc']:3d} {row['shape']:>6} {row['particles']:9d} {row['wall_s']:7.1f} "
              f"{row['mdr_full']:10.1f} {row['d_mdr']:+7.3f} {row['v_centre']:8.3f} {row['d_v_centre']:+7.3f} "
              f"{row['rho_out']:7.1f} {row['mfi']:5.2f} {dv_prof:7.3f} {dsig:7.3f}")
    print("MDR: full hopper (twice the half model) per metre of depth; v_c: outlet centre velocity; d*: relative to "
          "the reference; d v(x), d sig_n: RMS difference of the outlet v_y profile and of the discharging wall "
          "normal stress from the reference's, relative to the reference's RMS (last 3 frames); wall s: of the run")
    out = Path(a.out)
    import csv
    import json
    with open(out / "convergence.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0]))
        w.writeheader()
        w.writerows(table)
    (out / "convergence.json").write_text(json.dumps(dict(reference=dict(cell=ref["cell"], ppc=ref["ppc"],
                                                                        shape=ref["shape"]), rows=table), indent=1))
    with open(out / "convergence_profiles.csv", "w") as f:
        f.write("cell,ppc,shape,path,s_or_x,value\n")
        for r in rows:
            for x, v in r["outlet_profile"][:, :2]:
                f.write(f"{r['cell']},{r['ppc']},{r['shape']},outlet_v_y,{x:.6g},{v:.6g}\n")
            for sw, sig in r["wall_profile"][:, [0, 2]]:
                f.write(f"{r['cell']},{r['ppc']},{r['shape']},wall_sigma_n,{sw:.6g},{sig:.6g}\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.5))
    for r in rows:
        lab = f"h={r['cell']:g} m, {r['ppc']} PPC, {r['shape']}"
        ax[0].plot(r["outlet_profile"][:, 0] / (0.5 * r["scene"].get("outlet", 0.25)), -r["outlet_profile"][:, 1], "o-",
                   ms=3, label=lab)
        ax[1].plot(r["wall_profile"][:, 2] / 1e3, r["wall_profile"][:, 1], "-", label=lab)
        ax[2].loglog([r["wall"]], [abs(r["mdr"] / ref["mdr"] - 1) + 1e-4], "o")
        ax[2].annotate(f"{r['cell']:g}/{r['ppc']}/{r['shape'][0]}", (r["wall"], abs(r["mdr"] / ref["mdr"] - 1) + 1e-4),
                       fontsize=7)
    ax[0].set_xlabel("x / (b/2) (axis → wall)")
    ax[0].set_ylabel("downward velocity at the outlet [m/s]")
    ax[0].legend(fontsize=7)
    ax[0].set_title("(a) outlet velocity (Fig. 4.7a)")
    ax[1].set_xlabel("discharging wall normal stress [kPa]")
    ax[1].set_ylabel("height above the apex [m]")
    ax[1].set_title("(b) wall normal stress (Fig. 4.7b)")
    ax[2].set_xlabel("wall time of the run [s]")
    ax[2].set_ylabel("|MDR / MDR_ref − 1| (+1e-4)")
    ax[2].set_title("accuracy vs cost (cell/PPC/shape)")
    fig.tight_layout()
    fig.savefig(out / "convergence.png", dpi=120)
    print(f"wrote {out}/convergence.csv, convergence_profiles.csv, convergence.json, convergence.png")


def sweep(a):
    cases = [(30.0, b) for b in a.outlets] + [(t, 0.25) for t in a.thetas if t != 30.0]
    print(f"wedge hopper sweep, cell {a.cell:g} m, {a.shape}, 1 s fill + {a.discharge:g} s discharge with inflow")
    print(f"{'theta':>6} {'b m':>6} {'particles':>9} {'wall s':>7} {'MDR kg/s/m':>11} {'rho_out':>8} "
          f"{'C':>6} {'MFI':>6}  mode")
    for theta, b in cases:
        r = case(a, cell=a.cell, discharge_time=a.discharge, shape=a.shape, theta=theta, outlet=b)
        c = r["mdr_full"] / (r["rho_out"] * 9.81 ** 0.5 * b ** 1.5)
        print(f"{theta:6.1f} {b:6.3f} {r['particles']:9d} {r['wall']:7.1f} {r['mdr_full']:11.2f} "
              f"{r['rho_out']:8.1f} {c:6.3f} {r['mfi']:6.3f}  {'mass flow' if r['mfi'] > 0.3 else 'funnel flow'}",
              flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    sub = p.add_subparsers(dest="study", required=True)
    c = sub.add_parser("convergence", help="grid convergence and accuracy vs cost (a, item 6)")
    c.add_argument("--edge-cells", type=float, nargs="+", default=[1.5, 2.5, 3.5, 4.5],
                   help="outlet half-width b/2 = 0.125 m in cells (k + 1/2: the edge mid-cell)")
    c.add_argument("--cells", type=float, nargs="+", help="cell sizes instead of --edge-cells")
    c.add_argument("--ppc", type=int, default=2, help="particles per cell direction of the cell series")
    c.add_argument("--variant-cell", type=float, default=0.05,
                   help="the PPC and shape variants run at the series' cell nearest to this")
    c.add_argument("--ppcs", type=int, nargs="+", default=[3], help="other PPCs at --variant-cell")
    c.add_argument("--shapes", nargs="+", default=["LINEAR"], choices=["GIMP", "LINEAR"],
                   help="other shape functions at --variant-cell")
    s = sub.add_parser("sweep", help="MDR and flow mode vs b and theta (first look)")
    s.add_argument("--outlets", type=float, nargs="+", default=[0.15, 0.25, 0.35])
    s.add_argument("--thetas", type=float, nargs="+", default=[15.0, 30.0, 45.0])
    s.add_argument("--cell", type=float, default=0.05)
    for name, q in (("convergence", c), ("sweep", s)):
        q.add_argument("--discharge", type=float, default=1.5, help="discharge time [s] after the 1 s fill")
        q.add_argument("--shape", choices=["GIMP", "LINEAR"], default="GIMP")
        add_common(q, name)
    runners = {"convergence": convergence, "sweep": sweep}
    for name, module in MODULE_STUDIES.items():
        full = f"{__package__}.{module}"
        if importlib.util.find_spec(full) is None:
            continue        # a study still being written
        mod = importlib.import_module(full)
        q = sub.add_parser(name, help=mod.__doc__.splitlines()[0])
        add_common(q, name)
        mod.add_arguments(q)
        runners[name] = mod.run
    a = p.parse_args(argv)
    Path(a.out).mkdir(parents=True, exist_ok=True)
    return runners[a.study](a) or 0


if __name__ == "__main__":
    sys.exit(main())
