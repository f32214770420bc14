#!/usr/bin/env python3
"""Scene checks of the MPM's spatial decomposition (issue 19; src/mpm/mpm_domain.f90).

Each kind runs a scene on 1 rank (the replicated grid, as main does) and with
`*MPM CONTROLS, DECOMPOSITION=SPATIAL` (inserted into a copy of the deck, model data) on
several ranks (--oversubscribe through OMPI_MCA_rmaps_base_oversubscribe):

  agree      1 rank vs spatial on --ranks (e.g. 1 2 3 4): every history column and every particle
             field of every frame (matched by particle id) within --tol relative to the column's or
             field's largest magnitude, the grid frames (mass, V) too; the mass balance exact
             (|M0 + Min - Mout - M| <= 1e-12 M0); on 1 rank the spatial deck gives the replicated
             run's files bit for bit; optional --stop-after; --corner checks the 4-rank migration
             counts: particles went across every rank boundary the block crosses and straight
             across the corner of the four ranks (rank 0 -> 3)
  discharge  the whole scene (outflow, inflow) on --ranks: mass balance exact, particles migrated, the
             fill step within --tol of 1 rank, the discharged mass within --mass-tol; two runs on the
             last rank count bit for bit the same (deterministic)
  rebalance  spatial with REBALANCE=--rebalance on --ranks: at least one re-partition, and the same
             agreement with 1 rank
  restart    spatial with REBALANCE=--rebalance on --ranks: the restart check of check_mpm.py
             (stopped + restarted and restarted from *RESTART bit for bit against the uninterrupted
             run, refused restarts), with re-partitions before the stop
Figures are printed so the test log holds them.
"""
import argparse
import re
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import check_mpm  # noqa: E402  (launch, compare_runs, restart, check)

check = check_mpm.check


def spatial_deck(scene, workdir, extra=""):
    """A copy of the scene with the spatial decomposition asked for in its model data."""
    text = Path(scene).read_text()
    lines = text.splitlines()
    first_step = next(i for i, l in enumerate(lines) if l.upper().startswith("*STEP"))
    lines.insert(first_step, "*MPM CONTROLS, DECOMPOSITION=SPATIAL" + extra)
    out = Path(workdir) / (Path(scene).stem + "_spatial.inp")
    out.write_text("\n".join(lines) + "\n")
    return out


def run(args, scene, base, ranks, extra=()):
    r = check_mpm.launch(args, scene, base, ranks, extra)
    sys.stderr.write(r.stderr)
    summary = [l for l in r.stdout.splitlines() if l.startswith("  ")]
    print("\n".join(f"      {l.strip()}" for l in summary[:8]))
    check(r.returncode == 0, f"{Path(base).name}: bulkflow on {ranks} rank(s), exit status {r.returncode}")
    return r.stdout


def history(base):
    return np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)


def compare(ref, other, tol, what):
    """Largest relative differences of the history columns and of the frames' fields."""
    a, b = history(ref), history(other)
    check(a.shape == b.shape, f"{what}: {len(a)} history rows in both")
    worst, where = 0.0, ""
    for k in a.dtype.names:
        scale = np.abs(a[k]).max()
        # a vector component at round-off level (the tangential force of a symmetry plane, the
        # centre of mass on a symmetry axis, the sideways velocity of a block) against the vector
        if k.startswith("WALLF"):
            scale = max(np.abs(a[c]).max() for c in a.dtype.names if c.startswith("WALLF") and c[6:] == k[6:])
        elif k[:3] in ("XCM", "VCM"):
            scale = max(np.abs(a[c]).max() for c in a.dtype.names if c[:3] == k[:3])
        if scale == 0:
            continue
        d = np.abs(a[k] - b[k]).max() / scale
        if d > worst:
            worst, where = d, k
    check(worst <= tol, f"{what}: history, max relative difference {worst:.2e} (column {where or '-'})")
    fa, fb = h5py.File(str(ref) + ".h5", "r"), h5py.File(str(other) + ".h5", "r")
    frames = sorted(fa["particles"].keys())
    check(frames == sorted(fb["particles"].keys()), f"{what}: the same {len(frames)} particle frames, each with "
          "the same particles (ids)")
    # each field's scale: its largest magnitude over all frames (a field at round-off level in
    # one frame, the stress of the translating block, is compared against its real size)
    scale = {}
    for fr in frames:
        for grp, prefix in ((fa["particles"][fr], ""), (fa["grid"][fr], "grid ")):
            for name in grp.keys():
                scale[prefix + name] = max(scale.get(prefix + name, 0.0), float(np.abs(grp[name][()]).max(initial=0)))
    worst, where = 0.0, ""
    for fr in frames:
        pa, pb = fa["particles"][fr], fb["particles"][fr]
        ia, ib = pa["id"][()], pb["id"][()]
        if sorted(ia) != sorted(ib):
            check(False, f"{what}: frame {fr} holds the same {len(ia)} particles")
        oa, ob = np.argsort(ia), np.argsort(ib)
        for name in pa.keys():
            if name in ("id",):
                continue
            xa, xb = pa[name][()][oa], pb[name][()][ob]
            if scale[name] > 0 and len(xa):
                d = np.abs(xa - xb).max() / scale[name]
                if d > worst:
                    worst, where = d, f"{name} frame {fr}"
        ga, gb = fa["grid"][fr], fb["grid"][fr]
        for name in ga.keys():
            xa, xb = ga[name][()], gb[name][()]
            if scale["grid " + name] > 0:
                d = np.abs(xa - xb).max() / scale["grid " + name]
                if d > worst:
                    worst, where = d, f"grid {name} frame {fr}"
    check(worst <= tol, f"{what}: particle and grid fields of every frame, max relative difference "
          f"{worst:.2e} ({where or '-'})")
    err = np.abs(b["MASS_ERROR"]).max()
    check(err <= 1e-12 * b["MASS"][0], f"{what}: mass balance |M0 + Min - Mout - M| <= {err:.2e} kg")


def migrations(out, n):
    line = next(l for l in out.splitlines() if "particles migrated from rank r" in l)
    counts = [int(v) for v in line.split(":")[-1].split()]
    return np.array(counts).reshape(n, n)


def repartitions(out):
    m = re.search(r"spatial decomposition: (\d+) ranks, (\d+) re-partitions", out)
    check(m is not None, "the summary reports the spatial decomposition")
    return int(m.group(2))


def fresh_reference(args, extra=()):
    """An emptied work directory and the scene's 1-rank (replicated) run in it."""
    wd = args.workdir
    if wd.exists():
        shutil.rmtree(wd)
    wd.mkdir(parents=True)
    ref = wd / "np1"
    run(args, args.scene, ref, 1, extra)
    return wd, ref


def agree(args):
    extra = ["--stop-after", str(args.stop_after)] if args.stop_after else []
    wd, ref = fresh_reference(args, extra)
    deck = spatial_deck(args.scene, wd)
    for n in args.ranks:
        base = wd / f"spatial_np{n}"
        out = run(args, deck, base, n, extra)
        if n == 1:
            check_mpm.compare_runs(ref, base, "spatial deck on 1 rank vs replicated")
            continue
        check(repartitions(out) >= 0, f"{n} ranks: spatial decomposition on")
        compare(ref, base, args.tol, f"{n} ranks vs 1")
        if args.corner and n == 4:
            mv = migrations(out, 4)
            print(f"      migrations (row: from rank, column: to rank):\n{mv}")
            for a, b in [(0, 1), (0, 2), (1, 3), (2, 3)]:
                check(mv[a, b] > 0, f"particles migrated across the boundary of ranks {a} -> {b}: {mv[a, b]}")
            check(mv[0, 3] > 0, f"particles crossed the corner of the four ranks in one increment (0 -> 3): "
                  f"{mv[0, 3]}")
    if args.deterministic:
        n = args.ranks[-1]
        again = wd / f"spatial_np{n}_again"
        run(args, deck, again, n, extra)
        check_mpm.compare_runs(wd / f"spatial_np{n}", again, f"two runs on {n} ranks")


def discharge(args):
    """The whole scene (fill and discharge with outflow and inflow) on --ranks: two runs on the
    last rank count identical; mass balance exact; the discharged mass within --mass-tol of one
    rank's (the flow through the outlet amplifies round-off: figures printed)."""
    wd, ref = fresh_reference(args)
    a = history(ref)
    deck = spatial_deck(args.scene, wd)
    for n in args.ranks:
        base = wd / f"spatial_np{n}"
        out = run(args, deck, base, n)
        b = history(base)
        mv = migrations(out, n)
        check(mv.sum() > 0, f"{n} ranks: {mv.sum()} particle migrations, {repartitions(out)} re-partitions")
        err = np.abs(b["MASS_ERROR"]).max()
        check(err <= 1e-12 * b["MASS"][0], f"{n} ranks: mass balance |M0 + Min - Mout - M| <= {err:.2e} kg")
        check(b["MASS_OUT"][-1] > 0 and b["MASS_IN"][-1] > 0,
              f"{n} ranks: outflow {b['MASS_OUT'][-1]:.4g} kg, inflow {b['MASS_IN'][-1]:.4g} kg")
        fill = a["step"] == 1
        d = max(np.abs(a[k][fill] - b[k][fill]).max() / np.abs(a[k][fill]).max()
                for k in ("ALLKE", "ALLIE", "XCM1", "XCM2"))
        rel = abs(b["MASS_OUT"][-1] / a["MASS_OUT"][-1] - 1)
        check(d <= args.tol, f"{n} ranks: fill step, energies and centre of mass within {d:.2e} of 1 rank")
        check(rel <= args.mass_tol, f"{n} ranks: discharged mass {b['MASS_OUT'][-1]:.6g} kg vs 1 rank "
              f"{a['MASS_OUT'][-1]:.6g} kg ({rel:.2e} relative)")
    n = args.ranks[-1]
    again = wd / f"spatial_np{n}_again"
    run(args, deck, again, n)
    check_mpm.compare_runs(wd / f"spatial_np{n}", again, f"two runs on {n} ranks")


def rebalance(args):
    wd, ref = fresh_reference(args)
    deck = spatial_deck(args.scene, wd, f", REBALANCE={args.rebalance}")
    for n in args.ranks:
        base = wd / f"spatial_np{n}"
        out = run(args, deck, base, n)
        k = repartitions(out)
        check(k >= 1, f"{n} ranks: {k} re-partitions mid-run (imbalance above {args.rebalance})")
        compare(ref, base, args.tol, f"{n} ranks with re-partitions vs 1")


def restart(args):
    wd = args.workdir
    wd.mkdir(parents=True, exist_ok=True)
    decks = wd.parent / (wd.name + "_deck")
    decks.mkdir(parents=True, exist_ok=True)
    args.scene = str(spatial_deck(args.scene, decks, f", REBALANCE={args.rebalance}"))
    args.ranks = args.ranks[0]
    check_mpm.restart(args)
    out = check_mpm.launch(args, args.scene, wd / "count", args.ranks, ["--stop-after", str(args.stop_after)]).stdout
    k = repartitions(out)
    check(k >= 1, f"{k} re-partitions before the stop at increment {args.stop_after}")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("kind", choices=["agree", "discharge", "rebalance", "restart"])
    p.add_argument("scene")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", type=Path, required=True)
    p.add_argument("--mpiexec", default="mpirun")
    p.add_argument("--ranks", type=int, nargs="+", default=[2])
    p.add_argument("--stop-after", type=int, default=0)
    p.add_argument("--tol", type=float, default=1e-10)
    p.add_argument("--rebalance", type=float, default=0.05)
    p.add_argument("--mass-tol", type=float, default=0.005)
    p.add_argument("--corner", action="store_true")
    p.add_argument("--deterministic", action="store_true")
    args = p.parse_args()
    {"agree": agree, "discharge": discharge, "rebalance": rebalance, "restart": restart}[args.kind](args)
    print("PASS")


if __name__ == "__main__":
    main()
