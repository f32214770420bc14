#!/usr/bin/env python3
"""Material-point throughput benchmark (issue 2): updates per second per core.

Runs build/bin/bulkflow-bench-material for each model, first alone (one core busy), then as
two copies at once (both cores busy, as in a 2-rank run), and prints one table with the
figures and the targets (>= 10 M/s plane strain, >= 5 M/s 3D per core, Mohr-Coulomb plastic).
Usage: python3 scripts/bench_material.py [--build build] [--seconds 0.4] [--models MC,DP]
       python3 scripts/bench_material.py --ratio MC,MC-MUI [--repeats 3]
--ratio A,B: one core, A and B alternated --repeats times; prints ns/point of each (best of the
repeats, per dimension and nblock) and the ratio B/A (the cost of the mu(I) option for MC,MC-MUI).
"""
import argparse
import pathlib
import subprocess
import sys

TARGETS = {"plane": 10.0e6, "3D": 5.0e6}


def parse(output):
    rows = {}
    for line in output.splitlines():
        if line.startswith("#") or not line.strip():
            continue
        dim, nblock, rate, plastic = line.split()
        rows[(dim, int(nblock))] = (float(rate), float(plastic))
    return rows


def run(exe, model, seconds, copies):
    procs = [subprocess.Popen([str(exe), model, str(seconds)], stdout=subprocess.PIPE, text=True)
             for _ in range(copies)]
    outs = [p.communicate()[0] for p in procs]
    if any(p.returncode for p in procs):
        sys.exit(f"bulkflow-bench-material {model} failed")
    return [parse(o) for o in outs]


def ratio(exe, models, seconds, repeats):
    """ns per point of two models, alternated, best of the repeats; and their ratio."""
    a, b = models.split(",")
    best = {a: {}, b: {}}
    for _ in range(repeats):
        for model in (a, b):
            for key, (rate, _) in run(exe, model, seconds, 1)[0].items():
                best[model][key] = max(best[model].get(key, 0.0), rate)
    print(f"ns per point update, one core, best of {repeats} alternated runs")
    print(f"{'dim':6s} {'nblock':>6s} {a:>10s} {b:>10s} {'ratio':>7s}")
    for key in sorted(best[a], key=lambda k: (k[0] != "plane", k[1])):
        ta, tb = 1e9 / best[a][key], 1e9 / best[b][key]
        print(f"{key[0]:6s} {key[1]:6d} {ta:10.2f} {tb:10.2f} {tb / ta:7.3f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--seconds", type=float, default=0.4)
    ap.add_argument("--models", default="MC,MC-TABLE,DP,ELASTIC")
    ap.add_argument("--ratio", default="", help="A,B: ns/point of A and B alternated, and B/A")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    exe = pathlib.Path(args.build) / "bin" / "bulkflow-bench-material"
    if not exe.exists():
        sys.exit(f"{exe} not found: build first (bash scripts/build.sh release)")
    if args.ratio:
        ratio(exe, args.ratio, args.seconds, args.repeats)
        return

    print("material-point updates per second per core (M/s), every update through vumat")
    print(f"{'model':9s} {'dim':6s} {'nblock':>6s} {'1 core':>8s} {'2 cores':>8s} {'plastic':>8s}")
    summary = []
    for model in args.models.split(","):
        alone = run(exe, model, args.seconds, 1)[0]
        pair = run(exe, model, args.seconds, 2)
        for key in sorted(alone, key=lambda k: (k[0] != "plane", k[1])):
            dim, nblock = key
            r1, plastic = alone[key]
            r2 = sum(p[key][0] for p in pair) / 2
            print(f"{model:9s} {dim:6s} {nblock:6d} {r1 / 1e6:8.2f} {r2 / 1e6:8.2f} {plastic:8.3f}")
        for dim in ("plane", "3D"):
            best = max((v[0], k[1]) for k, v in alone.items() if k[0] == dim)
            best2 = max(sum(p[(dim, nb)][0] for p in pair) / 2 for (d, nb) in alone if d == dim)
            summary.append((model, dim, best, best2))
    print()
    print("best over nblock (M/s per core):")
    for model, dim, best, best2 in summary:
        verdict = ""
        if model == "MC":
            verdict = "meets" if best2 >= TARGETS[dim] else "below"
            verdict = f"  target {TARGETS[dim] / 1e6:.0f} M/s: {verdict}"
        print(f"  {model:9s} {dim:6s} 1 core {best[0] / 1e6:6.2f} (nblock {best[1]}), "
              f"2 cores {best2 / 1e6:6.2f}{verdict}")


if __name__ == "__main__":
    main()
