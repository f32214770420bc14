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

from .hopper_run import DEFAULT_EXE, run_hopper

# study name -> module of this package with add_arguments(parser) and run(args)
MODULE_STUDIES = {
    "mdr-time": "study_mdr_time",
    "walker": "study_walker",
    "kinematic": "study_kinematic",
    "rate-fit": "study_rate_fit",
    "flow-mode": "study_flow_mode",
    "mc-dp": "study_mc_dp",
    "parametric": "study_parametric",
}


def add_common(p, name):
    p.add_argument("--out", default=f"out/mpm_study/{name}", help="where the CSV/PNG/JSON go")
    p.add_argument("--runs", default="out/mpm_study/runs", help="shared run directory")
    p.add_argument("--bulkflow", default=DEFAULT_EXE, help="solver executable")
    p.add_argument("--no-reuse", action="store_true", help="run every case again")


def case(a, **scene):
    """One run of a study (shared across studies through a.runs)."""
    return run_hopper(a.bulkflow, a.runs, reuse=not a.no_reuse, **scene)


def convergence(a):
    rows = []
    for c in a.cells:
        r = case(a, cell=c, discharge_time=a.discharge, shape=a.shape)
        r["cell"] = c
        rows.append(r)
    ref = min(rows, key=lambda r: r["cell"])
    print(f"wedge hopper (thesis ch. 4), {a.shape}, 1 s fill + {a.discharge:g} s discharge with inflow; "
          f"reference: cell {ref['cell']:g} m")
    print(f"{'cell':>6} {'particles':>9} {'wall s':>8} {'Mpst/s':>7} {'MDR kg/s/m':>11} {'dMDR':>7} "
          f"{'v_out':>7} {'dv':>7} {'rho_out':>8} {'drho':>7} {'MFI':>6}")
    for r in rows:
        def rel(k):
            return r[k] / ref[k] - 1
        print(f"{r['cell']:6.3f} {r['particles']:9d} {r['wall']:8.1f} {r['psteps'] / r['wall'] / 1e6:7.3f} "
              f"{r['mdr_full']:11.2f} {rel('mdr'):+7.3f} {r['v_out']:7.3f} {rel('v_out'):+7.3f} "
              f"{r['rho_out']:8.1f} {rel('rho_out'):+7.3f} {r['mfi']:6.3f}")
    print("MDR: full hopper (twice the half model), per metre of depth; v_out, rho_out: outlet path means "
          "(last 3 frames); d*: relative to the reference; wall s: of the run that made the figures")


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
    c.add_argument("--cells", type=float, nargs="+", default=[0.1, 0.07, 0.05])
    s = sub.add_parser("sweep", help="MDR and flow mode vs b and theta (first look)")
    s.add_argument("--outlets", type=float, nargs="+", default=[0.15, 0.25, 0.35])
    s.add_argument("--thetas", type=float, nargs="+", default=[15.0, 30.0, 45.0])
    s.add_argument("--cell", type=float, default=0.05)
    for name, q in (("convergence", c), ("sweep", s)):
        q.add_argument("--discharge", type=float, default=1.5)
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
