"""bulkflow-accuracy KIND [--quick] [--out DIR] [--ranks N]: run a convergence family and write
its error against wall time (out/accuracy/<kind>/<kind>.csv, .png, .json), the reference, the
observed order and the cheapest member for ±1, 2 and 5 %. docs/accuracy.md describes the kinds."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import arching_cow, bin_mdr, bin_tss, hopper_mdr, incline, k0_column, wave_bar
from .study import resummarise, run_family

KINDS = {k["name"]: k for k in (wave_bar.KIND, wave_bar.KIND_BV, k0_column.KIND, incline.KIND, hopper_mdr.KIND,
                                 arching_cow.KIND, bin_tss.KIND, bin_mdr.KIND)}
# the kinds whose scenes take *MPM CONTROLS, PIC TIME and the μ(I) block
MPM_FLOW = {"hopper-mdr": hopper_mdr, "bin-tss": bin_tss, "bin-mdr": bin_mdr}
REGULARISED = ("hopper-mdr", "bin-mdr")
NOT_DONE: tuple[str, ...] = ()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="bulkflow-accuracy", description=" ".join(__doc__.split()))
    parser.add_argument("kind", help=f"one of {', '.join(KINDS)}")
    parser.add_argument("--quick", action="store_true", help="the smaller family (seconds to minutes)")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default out/accuracy/KIND)")
    parser.add_argument("--ranks", type=int, default=1, help="MPI ranks per run (default 1)")
    parser.add_argument("--solver", default=None, help="bulkflow binary (default BULKFLOW_BIN or build/bin/bulkflow)")
    parser.add_argument("--criterion", default=None, choices=arching_cow.CRITERIA,
                        help="arching-cow only: FLOW at 3 %% of the outlet width (physical, the default) or at "
                             "half an outlet element (half-element, the thesis's rule)")
    parser.add_argument("--flow-rule", default=None, choices=arching_cow.FLOW_RULES,
                        help="arching-cow only: the thesis's non-associated material (default) or Davis's "
                             "associated material of equal strength (scripts/bulkflow/arching/README.md)")
    parser.add_argument("--cow-case", default=None, choices=sorted(arching_cow.CASES),
                        help="arching-cow only: thesis Case B (default) or the polymer powder (fc0 reading), 1 m")
    parser.add_argument("--n-arcs", default=None, metavar="LIST",
                        help="arching-cow only: the members, elements along the outlet, comma-separated "
                             "(at least three) instead of the family's default or --quick list")
    parser.add_argument("--pic-time", type=float, default=None, metavar="TAU",
                        help="hopper-mdr, bin-tss, bin-mdr: *MPM CONTROLS, PIC TIME=TAU [s] in every member, "
                             "the PIC/FLIP blend as a rate (docs/accuracy.md); 0: FLIP=0.99 (the default of "
                             "hopper-mdr and bin-tss; bin-mdr's is 0.01)")
    parser.add_argument("--inertial-friction", default=None, metavar="PHI2,I0,D,RHOS",
                        help="hopper-mdr, bin-mdr: the regularised family, μ(I) in every member's Mohr-Coulomb "
                             "sand (docs/mu_of_i.md: φ2 [deg], I0, grain diameter d [m], grain density [kg/m3]); "
                             "default output folder out/accuracy/KIND-mu-i")
    parser.add_argument("--edge-cells", default=None, metavar="LIST",
                        help="hopper-mdr, bin-tss, bin-mdr: the members, comma-separated (hopper-mdr: the outlet "
                             "half-width in cells, n + 1/2, cell 0.125/n m; the bins: k, cell b/(2k+1)) instead of "
                             "the family's default or --quick list")
    parser.add_argument("--hopper-scene", action="append", default=[], metavar="KEY=VALUE",
                        help="hopper-mdr only, repeatable: a keyword of bulkflow.mpm.hopper_scene in every member "
                             "(a number, or true/false), e.g. wall_friction=0 or psi_constant=0; default output "
                             "folder out/accuracy/hopper-mdr-KEY-VALUE")
    parser.add_argument("--open-edge", action="store_true",
                        help="hopper-mdr, bin-tss, bin-mdr: the wall at the outlet's edge holds the particles, not "
                             "the grid nodes (*MPM WALL, OPEN=; docs/accuracy.md); default output folder "
                             "out/accuracy/KIND-open-edge")
    parser.add_argument("--reuse", action="store_true",
                        help="do not run again a member whose deck, rank count and solver binary ran to the end "
                             "in OUT/runs before (its measured times are kept): continues an interrupted family, "
                             "extends one by --edge-cells; not for arching-cow")
    parser.add_argument("--summarise-only", action="store_true",
                        help="no runs: the summary and outputs again from the measured rows of OUT/KIND.json")
    args = parser.parse_args(argv)
    if args.kind not in KINDS:
        extra = f" ({args.kind} is not implemented yet)" if args.kind in NOT_DONE else ""
        parser.error(f"unknown kind {args.kind!r}{extra}; expected one of {', '.join(KINDS)}")
    if args.ranks < 1:
        parser.error("--ranks must be at least 1")
    kind = KINDS[args.kind]
    suffix = ""
    cow_options = (args.criterion, args.flow_rule, args.cow_case, args.n_arcs)
    if any(v is not None for v in cow_options):
        if args.kind != "arching-cow":
            parser.error("--criterion, --flow-rule, --cow-case and --n-arcs apply to arching-cow only")
        if args.n_arcs is not None:
            n_arcs = n_arcs_list(args.n_arcs)
            if isinstance(n_arcs, str):
                parser.error(f"--n-arcs {args.n_arcs!r}: {n_arcs}")
            arching_cow.N_ARCS = n_arcs
        arching_cow.CRITERION = args.criterion
        arching_cow.FLOW_RULE = args.flow_rule or "nonassociated"
        arching_cow.CASE = args.cow_case or "B"
        kind = dict(kind, title=arching_cow.title(), expected_order=arching_cow.expected_order())
        for value, default in ((args.cow_case, "B"), (args.flow_rule, "nonassociated"), (args.criterion, "physical")):
            if value not in (None, default):
                suffix += f"-{value}"
    if args.reuse and "run" in kind:
        parser.error(f"--reuse: a member of {args.kind} is a search of several runs; it cannot be reused")
    if args.pic_time is not None:
        if args.kind not in MPM_FLOW:
            parser.error(f"--pic-time applies to {', '.join(MPM_FLOW)} only")
        if args.pic_time < 0:
            parser.error("--pic-time must be >= 0")
        MPM_FLOW[args.kind].PIC_TIME = args.pic_time
    if args.edge_cells is not None:
        if args.kind not in MPM_FLOW:
            parser.error(f"--edge-cells applies to {', '.join(MPM_FLOW)} only")
        cells = edge_cells_list(args.edge_cells, half=args.kind == "hopper-mdr")
        if isinstance(cells, str):
            parser.error(f"--edge-cells {args.edge_cells!r}: {cells}")
        MPM_FLOW[args.kind].EDGE_CELLS = MPM_FLOW[args.kind].QUICK_EDGE_CELLS = cells
    if args.hopper_scene:
        if args.kind != "hopper-mdr":
            parser.error("--hopper-scene applies to hopper-mdr only")
        extra = hopper_scene_keywords(args.hopper_scene)
        if isinstance(extra, str):
            parser.error(f"--hopper-scene: {extra}")
        hopper_mdr.SCENE_EXTRA = extra
        kind = dict(kind, title=f"{kind['title']}, with " + ", ".join(args.hopper_scene))
        suffix += "".join(f"-{k}-{v:g}" if not isinstance(v, bool) else f"-{k}-{v}" for k, v in extra.items())
    if args.open_edge:
        if args.kind not in MPM_FLOW:
            parser.error(f"--open-edge applies to {', '.join(MPM_FLOW)} only")
        MPM_FLOW[args.kind].OPEN_EDGE = True
        kind = dict(kind, title=f"{kind['title']}, outlet edge open (OPEN=)")
        suffix += "-open-edge"
    if args.inertial_friction is not None:
        if args.kind not in REGULARISED:
            parser.error(f"--inertial-friction applies to {', '.join(REGULARISED)} only")
        block = inertial_friction_block(args.inertial_friction)
        if isinstance(block, str):
            parser.error(f"--inertial-friction {args.inertial_friction!r}: {block}")
        MPM_FLOW[args.kind].INERTIAL_FRICTION = block
        kind = dict(kind, title=f"{kind['title']}, with μ(I) (φ2 {block[0]:g}°, I0 {block[1]:g}, "
                                f"d {block[2]:g} m, ρs {block[3]:g} kg/m³)")
        suffix += "-mu-i"
    out = args.out or Path("out") / "accuracy" / f"{args.kind}{suffix}"
    print(f"{kind['name']}: {kind['title']}{' (quick)' if args.quick else ''}")
    if args.summarise_only:
        if not (out / f"{kind['name']}.json").exists():
            parser.error(f"--summarise-only: {out / kind['name']}.json does not exist (run the family first)")
        s = resummarise(kind, out)
    else:
        try:
            s = run_family(kind, args.quick, out, ranks=args.ranks, solver=args.solver, reuse=args.reuse)
        except (FileNotFoundError, RuntimeError) as exc:      # no solver, or a run that failed
            print(f"bulkflow-accuracy: {exc}", file=sys.stderr)
            return 2
    if s["reference_kind"] == "exact":
        ref = "exact"
    elif s["reference"] is None:
        ref = f"none: {s['reference_note']}"
    else:
        ref = (f"Richardson {s['reference']:.6g} ± {s['reference_uncertainty']:.2g} "
               f"(GCI {100 * s['gci_finest']:.2g} %)")
    print(f"reference: {ref}; error measure: {s['error_measure']}")
    note = "" if s.get("monotone", True) else " (the error does not fall over the three finest: no order)"
    print(f"observed order (three finest): {s['observed_order']:.2f}{note}; expected {s['expected_order']}")
    fe = "n/a" if s["finest_error"] is None else f"{100 * s['finest_error']:.3g} %"
    print(f"finest ({s['finest_label']}): error {fe}; total wall {s['total_wall']:.1f} s")
    for rec in s["recommendations"]:
        print(rec["line"])
    for key, e in s.get("also", {}).items():
        ref = (f"Richardson {e['reference']:.6g} ± {e['uncertainty']:.2g} (observed order {e['observed_order']:.2f}, "
               f"finest {100 * e['finest_error']:.2g} % from it)" if e["reference"] is not None
               else f"no reference: {e['note']}")
        print(f"also {e['what']}: {ref}")
    print(f"wrote {out / kind['name']}.csv, .png, .json, .md")
    return 0


def _distinct_members(text: str, kind, what: str):
    """The comma-separated values of `text` converted by `kind`, or what is wrong (a str): `what` when
    one does not convert; fewer than three, or a repeated one, is refused (an observed order needs three)."""
    try:
        vals = [kind(v) for v in text.split(",")]
    except ValueError:
        return what
    if len(vals) < 3 or len(set(vals)) != len(vals):
        return "expected at least three distinct members (an observed order needs three)"
    return vals


def edge_cells_list(text: str, half: bool):
    """The members of --edge-cells (at least three, distinct), or what is wrong with the list (a str).
    half: hopper-mdr's values n + 1/2 (the outlet edge mid-cell); else whole k ≥ 1 (the bins)."""
    vals = _distinct_members(text, float, "expected comma-separated numbers")
    if isinstance(vals, str):
        return vals
    if half:
        if any(v < 1.5 or (v - 0.5) != int(v - 0.5) for v in vals):
            return "hopper-mdr's members are n + 1/2 with n ≥ 1 (the outlet edge mid-cell): 1.5, 2.5, …"
        return vals
    if any(v < 1 or v != int(v) for v in vals):
        return "the bins' members are whole numbers k ≥ 1 (cell b/(2k + 1))"
    return [int(v) for v in vals]


def n_arcs_list(text: str):
    """The members of --n-arcs (at least three distinct whole numbers ≥ 4), or what is wrong (a str)."""
    vals = _distinct_members(text, int, "expected comma-separated whole numbers (elements along the outlet)")
    if isinstance(vals, str):
        return vals
    if any(v < 4 for v in vals):
        return "a member needs at least 4 elements along the outlet"
    return sorted(vals)


def hopper_scene_keywords(items):
    """{keyword: value} from --hopper-scene KEY=VALUE items, or what is wrong (a str): each KEY must be a
    keyword of hopper_scene that a family does not set itself, each VALUE a number or true/false."""
    import inspect

    from ..mpm.hopper_scene import hopper_scene

    allowed = set(inspect.signature(hopper_scene).parameters) - {
        "cell", "ppc", "shape", "field_frames", "discharge_frames", "pic_time", "title", "command"}
    out = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or key not in allowed:
            return f"{item!r}: expected KEY=VALUE with KEY one of {', '.join(sorted(allowed))}"
        low = text.strip().lower()
        if low in ("true", "false"):
            out[key] = low == "true"
            continue
        try:
            out[key] = float(text)
        except ValueError:
            return f"{item!r}: VALUE must be a number or true/false"
    return out


def inertial_friction_block(text: str):
    """(φ2, I0, d, ρs) from "PHI2,I0,D,RHOS", or what is wrong with it (a str): the ranges of
    *INERTIAL FRICTION (docs/keywords.md), which the solver checks again against the sand's φ."""
    try:
        vals = tuple(float(v) for v in text.split(","))
    except ValueError:
        return "expected four numbers PHI2,I0,D,RHOS"
    if len(vals) != 4:
        return f"expected four numbers PHI2,I0,D,RHOS, got {len(vals)}"
    phi2, i0, d, rho_s = vals
    if not 0 < phi2 <= 89:
        return "φ2 must be in (0, 89] degrees"
    if not (i0 > 0 and d > 0 and rho_s > 0):
        return "I0, d and ρs must be > 0"
    return vals


if __name__ == "__main__":
    sys.exit(main())
