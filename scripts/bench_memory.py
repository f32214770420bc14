#!/usr/bin/env python3
"""Memory per rank of a spatially decomposed MPM run on 1, 2 and 4 ranks (issue 19 point 3:
"memory per rank falls as 1/N"). A script that prints figures; not a test.

    .venv/bin/python scripts/bench_memory.py [--bulkflow build/bin/bulkflow] [--cell 0.01]
                                            [--increments 20] [--ranks 1 2 4] [--compare OLD]

For each rank count N it runs the ch. 4 hopper's fill (bulkflow-make-mpm-hopper's scene,
`*MPM CONTROLS, DECOMPOSITION=SPATIAL`) at --cell for --increments increments, and the same
scene at a coarse cell (0.125 m: a few hundred particles) as the process base of N ranks (the
executable, MPI and HDF5 libraries: what no decomposition can divide). Printed per N: every
rank's peak RSS, the largest, the base's largest, their difference (the run's data: particles,
grid, buffers — what should divide by N), its ratio to 1 rank's against 1/N, and the solver's
own figures (particles and held grid nodes of the busiest rank). With --compare OLD the same runs
with another binary are printed beside (e.g. a build from before a memory change).
4 ranks on a 2-core machine are oversubscribed: memory is what they show, not speed.
"""
import argparse
import os
import re
import sys
import tempfile
from pathlib import Path

root = Path(__file__).resolve().parent
sys.path.insert(0, str(root))
from bench_mpm import measured_run  # noqa: E402
from bench_scaling import spatial  # noqa: E402
from bulkflow.mpm.hopper_scene import hopper_scene  # noqa: E402


def figures(binary, text, name, increments, ranks, tmp):
    scene = tmp / f"{name}.inp"
    scene.write_text(spatial(text))
    res = measured_run(binary, scene, tmp / f"{name}_np{ranks}", increments, ranks)
    out = res["stdout"]
    particles = int(re.search(r"(\d+) particles,", out).group(1))
    nodes = int(re.search(r"particles, (\d+) grid nodes", out).group(1))
    p_max, held = particles, nodes
    d = re.search(r"particles per rank now max (\d+),.*?grid nodes held per rank now max (\d+)", out)
    if d:
        p_max, held = int(d.group(1)), int(d.group(2))
    return {"rss": res["rss"], "particles": particles, "p_max": p_max, "held": held, "nodes": nodes}


def measure(binary, cell, increments, rank_counts, tmp, tag):
    big = hopper_scene(cell=cell, shape="GIMP", field_frames=1, history_dt=0.1)
    small = hopper_scene(cell=0.125, shape="GIMP", field_frames=1, history_dt=0.1)
    rows = []
    for n in rank_counts:
        run = figures(binary, big, f"{tag}_big", increments, n, tmp)
        base = figures(binary, small, f"{tag}_base", increments, n, tmp)
        data = max(run["rss"]) - max(base["rss"])
        rows.append({"ranks": n, **run, "base": max(base["rss"]), "data": data})
    return rows


def report(title, rows):
    print(f"\n{title}")
    print("   ranks  particles  P_max   held  peak RSS per rank [MB]        max   base   data  data/data(1)   1/N")
    d1 = rows[0]["data"]
    for r in rows:
        per = ", ".join(f"{x:.1f}" for x in r["rss"])
        print(f"   {r['ranks']:5d} {r['particles']:10d} {r['p_max']:6d} {r['held']:6d}  {per:28s} {max(r['rss']):6.1f} "
              f"{r['base']:6.1f} {r['data']:6.1f}  {r['data'] / d1:12.3f} {1 / r['ranks']:6.3f}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bulkflow", default=str(root.parent / "build" / "bin" / "bulkflow"))
    p.add_argument("--compare", help="another bulkflow binary, measured the same way")
    p.add_argument("--cell", type=float, default=0.01)
    p.add_argument("--increments", type=int, default=20)
    p.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    a = p.parse_args()
    for b in [a.bulkflow] + ([a.compare] if a.compare else []):
        if not os.access(b, os.X_OK):
            sys.exit(f"bench_memory: {b} is not an executable (bash scripts/build.sh release)")
    if a.ranks[0] != 1:
        sys.exit("bench_memory: the first rank count must be 1 (the reference of the ratios)")
    print(f"bench_memory: {a.bulkflow}; ch. 4 hopper fill, cell {a.cell} m, {a.increments} increments, "
          f"spatial decomposition; {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        rows = measure(a.bulkflow, a.cell, a.increments, a.ranks, tmp, "new")
        report(f"{a.bulkflow}", rows)
        if a.compare:
            report(f"{a.compare} (--compare)", measure(a.compare, a.cell, a.increments, a.ranks, tmp, "old"))
    last = rows[-1]
    print(f"\n   data per rank on {last['ranks']} ranks: {last['data'] / rows[0]['data']:.3f} of 1 rank's "
          f"(1/N = {1 / last['ranks']:.3f}); particles on the busiest rank {last['p_max'] / rows[0]['p_max']:.3f}, "
          f"held grid nodes {last['held'] / rows[0]['held']:.3f}")


if __name__ == "__main__":
    main()
