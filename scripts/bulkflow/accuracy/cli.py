"""bulkflow-accuracy KIND [--quick] [--out DIR] [--ranks N]: run a convergence family and write
its error against wall time (out/accuracy/<kind>/<kind>.csv, .png, .json), the reference, the
observed order and the cheapest member for ±1, 2 and 5 %. docs/accuracy.md describes the kinds."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import arching_cow, bin_tss, hopper_mdr, incline, k0_column, wave_bar
from .study import resummarise, run_family

KINDS = {k["name"]: k for k in (wave_bar.KIND, wave_bar.KIND_BV, k0_column.KIND, incline.KIND, hopper_mdr.KIND,
                                 arching_cow.KIND, bin_tss.KIND)}
NOT_DONE: tuple[str, ...] = ()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="bulkflow-accuracy", description=" ".join(__doc__.split()))
    parser.add_argument("kind", help=f"one of {', '.join(KINDS)}")
    parser.add_argument("--quick", action="store_true", help="the smaller family (seconds to minutes)")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default out/accuracy/KIND)")
    parser.add_argument("--ranks", type=int, default=1, help="MPI ranks per run (default 1)")
    parser.add_argument("--solver", default=None, help="bulkflow binary (default BULKFLOW_BIN or build/bin/bulkflow)")
    parser.add_argument("--criterion", default=None,
                        help="arching-cow only: the flow criterion, passed to bulkflow.arching when it takes one")
    parser.add_argument("--pic-time", type=float, default=0.0, metavar="TAU",
                        help="hopper-mdr and bin-tss only: *MPM CONTROLS, PIC TIME=TAU [s] in every member, "
                             "the PIC/FLIP blend as a rate (docs/accuracy.md); 0: the scenes' FLIP=0.99")
    parser.add_argument("--summarise-only", action="store_true",
                        help="no runs: the summary and outputs again from the measured rows of OUT/KIND.json")
    args = parser.parse_args(argv)
    if args.kind not in KINDS:
        extra = f" ({args.kind} is not implemented yet)" if args.kind in NOT_DONE else ""
        parser.error(f"unknown kind {args.kind!r}{extra}; expected one of {', '.join(KINDS)}")
    if args.ranks < 1:
        parser.error("--ranks must be at least 1")
    kind = KINDS[args.kind]
    if args.criterion is not None:
        if args.kind != "arching-cow":
            parser.error("--criterion applies to arching-cow only")
        if arching_cow.criterion_supported() is None:
            parser.error("--criterion: this checkout's bulkflow.arching has no flow criterion option")
        arching_cow.CRITERION = args.criterion
    if args.pic_time:
        if args.kind not in ("hopper-mdr", "bin-tss"):
            parser.error("--pic-time applies to hopper-mdr and bin-tss only")
        if args.pic_time < 0:
            parser.error("--pic-time must be >= 0")
        (hopper_mdr if args.kind == "hopper-mdr" else bin_tss).PIC_TIME = args.pic_time
    out = args.out or Path("out") / "accuracy" / args.kind
    print(f"{kind['name']}: {kind['title']}{' (quick)' if args.quick else ''}")
    if args.summarise_only:
        if not (out / f"{kind['name']}.json").exists():
            parser.error(f"--summarise-only: {out / kind['name']}.json does not exist (run the family first)")
        s = resummarise(kind, out)
    else:
        try:
            s = run_family(kind, args.quick, out, ranks=args.ranks, solver=args.solver)
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


if __name__ == "__main__":
    sys.exit(main())
