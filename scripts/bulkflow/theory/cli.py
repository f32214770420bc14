"""bulkflow-theory: critical outlet widths (McLean, Jenike, Enstad) and related hopper estimates.

    bulkflow-theory --case B --height 2
    bulkflow-theory --theta 30 --height 2 --rho 400 --phi 20 --phi-w 0 --k 0 --c0 800 --outlet-width 0.3
    bulkflow-theory --case sic --reading fc0 --json
    bulkflow-theory --table-6-3

Heights are vertical heights of the free surface above the hopper APEX (R = H/cos θ).
"""
from __future__ import annotations

import argparse
import json
import math
import sys

from . import beverloo, enstad, flow_mode
from .cases import CASES, EL_HEIGHT, READINGS, TABLE_6_3, case
from .jenike import JENIKE_BETA_READINGS
from .model import CONSOLIDATION_ROUTES, DEFAULT_READINGS, Hopper, Material, critical_width_estimates
from .mohr import fc_from_c

THEORIES = ("mclean", "jenike", "enstad")
LABEL = {"mclean": "McLean (eq. 6.5)", "jenike": "Jenike (eq. 6.4)", "enstad": "Enstad (eqs. 6.6-6.8)"}


def _cm(x):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if math.isinf(x):
        return "no flow at any width" if x > 0 else "-inf"
    return f"{100.0 * x:.1f}"


def _clean(obj):
    """JSON: inf/nan as strings ('inf', 'nan') so the output is strict JSON."""
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return "nan" if math.isnan(obj) else ("inf" if obj > 0 else "-inf")
    return obj


def build_parser():
    p = argparse.ArgumentParser(prog="bulkflow-theory", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--case", choices=sorted(CASES, key=str.lower),
                   help="thesis case: A, B (Table 6.1), polymer, sic (Table 6.2)")
    p.add_argument("--reading", choices=READINGS, default="c0",
                   help="polymer/sic: tabulated 'c0' is c0 (eq. 6.9, default) or fc0 itself")
    g = p.add_argument_group("hopper")
    g.add_argument("--theta", type=float, help="half-angle from the vertical (deg)")
    g.add_argument("--height", type=float, help="free-surface height above the apex (m)")
    g.add_argument("--heights", type=str, help="comma list of heights: an Enstad height sweep")
    g.add_argument("--outlet-width", type=float, help="outlet width B (m): flow question, MDR")
    g.add_argument("--outlet-length", type=float, help="slot length l (m) for Beverloo (default: per m)")
    m = p.add_argument_group("material")
    m.add_argument("--rho", type=float, help="bulk density (kg/m^3)")
    m.add_argument("--phi", type=float, help="internal friction angle (deg)")
    m.add_argument("--phi-w", type=float, help="wall friction angle (deg)")
    m.add_argument("--k", type=float, help="flow-function slope")
    c = m.add_mutually_exclusive_group()
    c.add_argument("--fc0", type=float, help="unconfined yield strength at zero consolidation (Pa)")
    c.add_argument("--c0", type=float, help="cohesion at zero consolidation (Pa), eq. 6.9 -> fc0")
    m.add_argument("--flow", choices=("linear", "bilinear"), default=None,
                   help="flow function: linear (eq. 6.1) or bilinear (thesis Fig. 6.11)")
    d = p.add_argument_group("discharge (Beverloo / Rose-Tanaka, cohesionless)")
    d.add_argument("--particle-diameter", type=float, help="d (m)")
    d.add_argument("--beverloo-C", type=float, default=beverloo.C_DEFAULT)
    d.add_argument("--beverloo-k", type=float, default=beverloo.K_SPHERES)
    r = p.add_argument_group("readings")
    r.add_argument("--jenike-beta", choices=JENIKE_BETA_READINGS, default=DEFAULT_READINGS["jenike_beta"])
    r.add_argument("--enstad-beta", choices=("omega", "omega_cap", "phiw_cap"),
                   default=DEFAULT_READINGS["enstad_beta"])
    r.add_argument("--consolidation", choices=CONSOLIDATION_ROUTES,
                   default=DEFAULT_READINGS["consolidation"])
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--table-6-3", action="store_true",
                   help="our values for the Eckhoff & Leversen powders beside thesis Table 6.3")
    return p


def _material_hopper(args, parser):
    if args.case:
        cs = case(args.case)
        reading = args.reading if args.reading in cs.readings else "c0"
        base_m = cs.material(reading)
        base_h = cs.hopper()
    else:
        missing = [n for n in ("theta", "height", "rho", "phi", "phi_w", "k") if getattr(args, n) is None]
        if args.fc0 is None and args.c0 is None:
            missing.append("fc0 or c0")
        if missing:
            parser.error("without --case give: " + ", ".join("--" + n.replace("_", "-") for n in missing))
        base_m = Material(rho=args.rho, phi_deg=args.phi, phi_w_deg=args.phi_w, k=args.k,
                          fc0=args.fc0 if args.fc0 is not None else fc_from_c(args.c0, args.phi))
        base_h = Hopper(theta_deg=args.theta, height=args.height)
    mk = {}
    for flag, key in (("rho", "rho"), ("phi", "phi_deg"), ("phi_w", "phi_w_deg"), ("k", "k"), ("flow", "flow")):
        if getattr(args, flag) is not None:
            mk[key] = getattr(args, flag)
    if args.case and args.fc0 is not None:
        mk["fc0"] = args.fc0
    mat = base_m.replace(**mk)
    if args.case and args.c0 is not None:
        mat = mat.replace(fc0=fc_from_c(args.c0, mat.phi_deg))
    hk = {}
    if args.theta is not None:
        hk["theta_deg"] = args.theta
    if args.height is not None:
        hk["height"] = args.height
    if args.outlet_width is not None:
        hk["outlet_width"] = args.outlet_width
    if args.outlet_length is not None:
        hk["length"] = args.outlet_length
    return mat, base_h.replace(**hk)


def _extras(h, m, est, args):
    """Enstad arch geometry, discharge rates and flow mode (dict)."""
    ex = {}
    r_star = est["r_star"]
    if math.isfinite(r_star):
        c, a = enstad.arch_centre(r_star, h.theta_deg, est["beta_enstad_arch_deg"])
        ex["enstad_critical_arch"] = {"r_wall": r_star, "centre_height_above_apex": float(c),
                                      "radius": float(a)}
    if h.outlet_width is not None:
        ro = h.outlet_radius()
        c, a = enstad.arch_centre(ro, h.theta_deg, est["beta_enstad_arch_deg"])
        ex["outlet_arch"] = {"r_wall": ro, "enstad_centre_height_above_apex": float(c),
                             "enstad_radius": float(a), "apex_centred_radius": ro}
        if args.particle_diameter is not None:
            l = h.length if h.length is not None else 1.0
            mb = beverloo.beverloo_rect(h.outlet_width, l if h.length is not None else 1e6,
                                        args.particle_diameter, m.rho, args.beverloo_C, args.beverloo_k)
            if h.length is None:
                mb /= 1e6   # long-slot limit: per metre of slot length
            ex["discharge"] = {
                "beverloo_kg_s": mb, "rose_tanaka_kg_s": mb * beverloo.rose_tanaka_factor(h.theta_deg),
                "rose_tanaka_factor": beverloo.rose_tanaka_factor(h.theta_deg),
                "per": "total" if h.length is not None else "per metre of slot length (l >> b)",
                "C": args.beverloo_C, "k": args.beverloo_k,
                "note": "cohesionless correlations; C not given by the thesis (0.58 assumed)"}
    d = est["delta_mod_deg"]
    ex["flow_mode"] = {"conical_mass_flow_limit_deg": flow_mode.conical_mass_flow_limit(d, m.phi_w_deg),
                       "plane_rule_of_thumb": flow_mode.plane_boundary_rule_of_thumb(d, m.phi_w_deg)}
    return ex


def print_estimates(h, m, est, ex, sweep=None, out=None):
    w = (out or sys.stdout).write
    w(f"bulkflow-theory: {m.name or 'material'}\n")
    w(f"  hopper : theta = {h.theta_deg:g} deg, H = {h.height:g} m above the apex (R = {est['R']:.3f} m along the wall)\n")
    w(f"  material: rho = {m.rho:g} kg/m3, phi = {m.phi_deg:g} deg, phi_w = {m.phi_w_deg:g} deg, "
      f"k = {m.k:g}, fc0 = {m.fc0:.1f} Pa (c0 = {m.c0:.1f} Pa by eq. 6.9), flow function {m.flow}\n")
    w(f"  delta_mod = {est['delta_mod_deg']:.2f} deg, omega_p = {est['omega_p_deg']:.2f} deg, "
      f"X = {est['X']:.3f}, X_b = {est['X_b']:.3f}, W = {est['W']:.3f}, Y = {est['Y']:.3f}\n\n")
    flows = est.get("flows")
    head = f"  {'theory':24s} {'B_crit (cm)':>20s}  {'fc at arch (Pa)':>15s}  {'cons. sigma1 (Pa)':>17s}"
    if flows:
        head += f"  flows at B = {100 * h.outlet_width:.1f} cm?"
    w(head + "\n")
    for t in THEORIES:
        fc = est[f"fc_{t}"]
        s1 = est["sigma1_cons_enstad"] if t == "enstad" else est[f"sigma1_outlet_{t}"]
        line = f"  {LABEL[t]:24s} {_cm(est[t]):>20s}  {fc:15.1f}  {s1:17.4g}"
        if flows:
            line += "  " + ("flow" if flows[t] else "NO FLOW").ljust(len("flows at B = 00.0 cm?"))
        if m.k == 0.0 and t != "enstad":
            line += "  (sigma1 unused: k = 0)"
        w(line + "\n")
    w("\n  Jenike under every beta reading (cm): " +
      ", ".join(f"{k} {_cm(v)}" for k, v in est["jenike_by_beta"].items()) + "\n")
    w(f"  beta: Jenike {est['beta_jenike_deg']:.2f} deg, Enstad arch {est['beta_enstad_arch_deg']:.2f} deg, "
      f"Enstad consolidation {est['beta_enstad_cons_deg']:.2f} deg; H_McLean = {est['H_mclean']:.3f}, "
      f"sin 2beta = {est['H_jenike']:.3f}, S = sigma1/(rho g B) = {est['S']:.4g}\n")
    if "enstad_critical_arch" in ex:
        a = ex["enstad_critical_arch"]
        w(f"  Enstad critical arch: r* = {a['r_wall']:.4f} m along the wall, centre {a['centre_height_above_apex']:.4f} m "
          f"above the apex, radius {a['radius']:.4f} m\n")
    if "outlet_arch" in ex:
        a = ex["outlet_arch"]
        w(f"  outlet arch (B = {100 * h.outlet_width:.1f} cm): r_out = {a['r_wall']:.4f} m; Enstad's arc centre "
          f"{a['enstad_centre_height_above_apex']:.4f} m above the apex, radius {a['enstad_radius']:.4f} m\n")
    if "discharge" in ex:
        dd = ex["discharge"]
        w(f"  Beverloo {dd['beverloo_kg_s']:.4g} kg/s, Rose-Tanaka {dd['rose_tanaka_kg_s']:.4g} kg/s "
          f"(factor {dd['rose_tanaka_factor']:.3f}; {dd['per']}; C = {dd['C']}, k = {dd['k']}; {dd['note']})\n")
    fm = ex["flow_mode"]
    w(f"  mass-flow limit: conical {fm['conical_mass_flow_limit_deg']:.1f} deg (closed form); plane flow ~"
      f"{fm['plane_rule_of_thumb']['theta_c_deg']:.1f} deg APPROXIMATE ({fm['plane_rule_of_thumb']['caveat']})\n")
    if sweep:
        w("\n  height sweep (H above apex, m -> Enstad B_crit, cm): " +
          ", ".join(f"{H:g} -> {_cm(B)}" for H, B in sweep) + "\n")
    w("\n  assumptions:\n")
    for k, v in est["assumptions"].items():
        w(f"    {k}: {v}\n")
    for n in est["notes"]:
        w(f"    note: {n}\n")


def table_6_3(height=EL_HEIGHT, readings=DEFAULT_READINGS):
    """Rows for --table-6-3: our values (m) under both c0 readings beside the thesis (cm)."""
    rows = []
    for key in ("polymer", "sic"):
        cs = case(key)
        for reading in READINGS:
            est = critical_width_estimates(cs.hopper(height), cs.material(reading), **readings)
            rows.append({"powder": key, "reading": reading, "fc0": cs.fc0(reading), "height": height,
                         **{t: est[t] for t in THEORIES},
                         "jenike_beta_omega": est["jenike_by_beta"]["omega"],
                         "thesis_cm": TABLE_6_3[key]})
    return rows


def print_table_6_3(rows, readings, out=None):
    w = (out or sys.stdout).write
    w("Thesis Table 6.3 (theory columns) against bulkflow.theory, Eckhoff & Leversen powders.\n")
    w(f"Fill height {rows[0]['height']:g} m above the apex (not reported by E&L; assumed). Readings: "
      + ", ".join(f"{k} = {v}" for k, v in readings.items()) + ".\n")
    w("Reading 'c0': tabulated c0 -> fc0 = 2 c0 cos(phi)/(1 - sin(phi)) (eq. 6.9, as the thesis documents);\n"
      "reading 'fc0': the tabulated value is fc0 itself. Values NOT tuned to the thesis.\n\n")
    w(f"  {'powder':8s} {'source':14s} {'fc0 (Pa)':>9s} {'McLean':>8s} {'Jenike':>8s} {'Enstad':>8s} "
      f"{'Jenike(b=w)':>12s}   (cm)\n")
    done = set()
    for r in rows:
        if r["powder"] not in done:
            t = r["thesis_cm"]
            w(f"  {r['powder']:8s} {'thesis':14s} {'':>9s} {t['mclean']:8.1f} {t['jenike']:8.1f} {t['enstad']:8.1f}\n")
            done.add(r["powder"])
        w(f"  {r['powder']:8s} {'reading ' + r['reading']:14s} {r['fc0']:9.1f} {_cm(r['mclean']):>8s} "
          f"{_cm(r['jenike']):>8s} {_cm(r['enstad']):>8s} {_cm(r['jenike_beta_omega']):>12s}\n")
    w("\n  The thesis row values cannot be reproduced with one consistent reading "
      "(docs/theory/hopper_theory.md section i): the 'c0' reading is what the thesis documents;\n"
      "  the 'fc0' reading comes closer for the polymer but far below for SiC.\n")


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    readings = {"jenike_beta": args.jenike_beta, "enstad_beta": args.enstad_beta,
                "consolidation": args.consolidation}
    if args.table_6_3:
        height = args.height if args.height is not None else EL_HEIGHT
        rows = table_6_3(height, readings)
        if args.json:
            json.dump(_clean({"readings": readings, "rows": rows}), sys.stdout, indent=2)
            sys.stdout.write("\n")
        else:
            print_table_6_3(rows, readings)
        return 0
    if not args.case and args.theta is None and args.rho is None:
        parser.error("give --case, a full material/hopper description, or --table-6-3")
    try:
        m, h = _material_hopper(args, parser)
    except ValueError as err:
        parser.error(str(err))
    est = critical_width_estimates(h, m, **readings)
    ex = _extras(h, m, est, args)
    sweep = None
    if args.heights:
        sweep = []
        for H in (float(x) for x in args.heights.split(",") if x.strip()):
            sweep.append((H, critical_width_estimates(h.replace(height=H), m, **readings)["enstad"]))
    if args.json:
        doc = {"hopper": {"theta_deg": h.theta_deg, "height": h.height, "outlet_width": h.outlet_width,
                          "length": h.length},
               "material": {"name": m.name, "rho": m.rho, "phi_deg": m.phi_deg, "phi_w_deg": m.phi_w_deg,
                            "k": m.k, "fc0": m.fc0, "c0": m.c0, "flow": m.flow, "E": m.E, "nu": m.nu},
               "estimates": est, **ex}
        if sweep:
            doc["height_sweep"] = [{"height": H, "enstad": B} for H, B in sweep]
        json.dump(_clean(doc), sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print_estimates(h, m, est, ex, sweep)
    return 0


if __name__ == "__main__":
    sys.exit(main())
