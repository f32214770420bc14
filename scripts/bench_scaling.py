#!/usr/bin/env python3
"""MPM scaling model: measured costs, predictions for 2 and 4 ranks against measured runs, and
weak and strong scaling of a 3D silo of 10^8 particles to 64 and 1024 ranks (issue 19 point 3;
docs/scaling.md says what the model assumes). A script that prints figures; not a test.

    .venv/bin/python scripts/bench_scaling.py [--bulkflow build/bin/bulkflow] [--increments 1000]
                                             [--increments-3d 150] [--json out/scaling.json]

1. Runs (release build, `*MPM CONTROLS, DECOMPOSITION=SPATIAL`, the ch. 4 hopper's fill step,
   `--stop-after` increments): 2D at cell 0.05 m and 0.025 m on 1, 2 and 4 ranks, 3D slab (cell
   0.1 m) on 1 and 2 ranks. From each: the solver's timing table (per phase, max and mean over
   the ranks), its decomposition figures (particles per rank, ghost nodes, nodes sent + received
   per exchange, neighbours) and every rank's peak RSS. 4 ranks on a 2-core machine are
   oversubscribed: their timings are printed but not used as speed.
2. Costs: c_p, the seconds of particle work (every phase but the grid exchange, migration,
   output and checkpoint) per particle-step on 1 rank, 2D and 3D; the grid exchange per
   increment on 2 ranks without its waiting (the rank with the most work waits least: on 2 ranks
   its time is 2 mean - max) fitted as 4 k alpha + c_h H over the two 2D cells (k neighbours, 4
   messages per neighbour and increment, H nodes sent + received per exchange, two exchanges
   per increment: alpha the latency of a message, c_h the cost per halo node and exchange);
   migration per increment per rank; memory: peak RSS = m_0 + m_p P_rank + m_g G_rank fitted by
   least squares over all runs (P_rank the rank's particles, G_rank its held grid nodes).
3. Predictions for the measured runs on 2 and 4 ranks from their decomposition figures: time
   loop = increments x (c_p P_max + 4 k alpha + c_h H + migration); oversubscribed 4 ranks
   also x ranks/cores.
4. The 3D silo, 10^8 particles, 2x2x2 per cell, cubic rank boxes: strong scaling (10^8 total) and
   weak scaling (10^8/1024 per rank) on N = 1 .. 1024 ranks, with this machine's shared-memory
   alpha and a cluster network (alpha_net 2 us, 10 GB/s, assumptions named in docs/scaling.md);
   the particles' migration as one collective whose latency grows with N (MPI_Alltoallv,
   pairwise: (N - 1) alpha) and the increment's all-reduces (2 per increment, 2 log2 N alpha).
"""
import argparse
import json
import math
import os
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

root = Path(__file__).resolve().parent
sys.path.insert(0, str(root))
from bench_mpm import hopper_scene_3d, measured_run  # noqa: E402
from bulkflow.mpm.hopper_scene import hopper_scene  # noqa: E402

PARTICLE_PHASES = ("p2g", "grid update", "g2p", "kinematics", "material", "walls", "outflow", "inflow",
                   "side friction")
NET_ALPHA = 2.0e-6        # s per message on a cluster network (assumption, docs/scaling.md)
NET_BANDWIDTH = 10.0e9    # bytes/s per link (assumption)
ALLREDUCES = 2            # small all-reduces per increment (stable increment, accounts)


def spatial(text):
    """The scene with DECOMPOSITION=SPATIAL on its model-data *MPM CONTROLS line."""
    return re.sub(r"^(\*MPM CONTROLS[^\n]*)$", r"\1, DECOMPOSITION=SPATIAL", text, count=1, flags=re.M)


def timing(out):
    """{phase: (max, mean)} of the solver's timing table (one rank: (time, time))."""
    table = {}
    start = out.find("timing (wall seconds")
    for line in out[start:].splitlines()[2:]:
        m = re.match(r"\s{2}(\S.*?\S)\s{2,}([0-9.]+)(?:\s+([0-9.]+))?\s+[0-9.]+ %", line)
        if not m:
            continue
        a = float(m.group(2))
        table[m.group(1)] = (a, float(m.group(3)) if m.group(3) else a)
    return table


def decomposition(out, ranks, particles):
    """Particles per rank (max), held grid nodes (max), ghost nodes, halo nodes per exchange,
    neighbours; on 1 rank the whole grid and no halo."""
    nodes = int(re.search(r"particles, (\d+) grid nodes", out).group(1))
    if ranks == 1:
        return {"p_max": particles, "held": nodes, "ghost": 0, "halo": 0, "neighbours": 0, "nodes": nodes}
    d = re.search(r"particles per rank now max (\d+), max/mean\s+([0-9.]+); grid nodes held per rank now max (\d+)", out)
    h = re.search(r"halo per rank now max: (\d+) ghost nodes, (\d+) nodes sent \+ received per exchange.*?, (\d+) neighbours",
                  out)
    return {"p_max": int(d.group(1)), "imbalance": float(d.group(2)), "held": int(d.group(3)),
            "ghost": int(h.group(1)), "halo": int(h.group(2)), "neighbours": int(h.group(3)), "nodes": nodes}


def one_run(binary, scene_text, name, increments, ranks, tmp):
    scene = tmp / f"{name}.inp"
    scene.write_text(spatial(scene_text))
    res = measured_run(binary, scene, tmp / f"{name}_np{ranks}", increments, ranks)
    out = res["stdout"]
    particles = int(re.search(r"(\d+) particles,", out).group(1))
    t = timing(out)
    steps = res["steps"]
    work_max = sum(t[p][0] for p in PARTICLE_PHASES if p in t)
    work_mean = sum(t[p][1] for p in PARTICLE_PHASES if p in t)
    ex = t.get("grid exchange", (0.0, 0.0))
    mig = t.get("migration", (0.0, 0.0))
    return {"name": name, "ranks": ranks, "increments": increments, "particles": particles, "steps": steps,
            "loop": res["loop"], "rss": res["rss"], "work_max": work_max, "work_mean": work_mean,
            "exchange_max": ex[0], "exchange_mean": ex[1], "migration_max": mig[0], "migration_mean": mig[1],
            "output": t.get("output", (0.0, 0.0))[0], **decomposition(out, ranks, particles)}


def fit_exchange(two_rank_runs):
    """alpha, c_h from the 2-rank runs' exchange time per increment without waiting."""
    rows, rhs = [], []
    for r in two_rank_runs:
        t = (2 * r["exchange_mean"] - r["exchange_max"]) / r["increments"]
        rows.append([4.0 * r["neighbours"], 2.0 * r["halo"]])
        rhs.append(t)
    a, c = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
    return float(a), float(c)


def fit_memory(runs):
    rows, rhs = [], []
    for r in runs:
        rows.append([1.0, r["p_max"], r["held"]])
        rhs.append(max(r["rss"]) * 1.0e6)
    m = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
    return [float(x) for x in m]


def predict(run, cp, alpha, ch, migration, cores):
    per_inc = cp * run["p_max"] + 4 * run["neighbours"] * alpha + 2 * ch * run["halo"]
    if run["ranks"] > 1:
        per_inc += migration * run["ranks"] / 2
    t = per_inc * run["increments"]
    return t * max(1.0, run["ranks"] / cores)


def silo(n_ranks, particles, cp3, alpha, ch, mig2, net):
    """One increment of the 3D silo on n_ranks ranks (cubic boxes, 8 particles per cell)."""
    cells = particles / n_ranks / 8.0
    s = cells ** (1.0 / 3.0)
    # uGIMP: one node layer below a cut and two above (src/mpm/README.md); interior box
    held, owned = (s + 1 + 3) ** 3, (s + 1) ** 3
    ghost = held - owned if n_ranks > 1 else 0.0
    halo = 2 * ghost                       # sent (ghosts) + received (owned nodes others hold)
    k = min(26, n_ranks - 1)
    a = NET_ALPHA if net else alpha
    values = 2 * (7 + 3)                   # p2g: mass, 3 momentum, 3 force; remap: 3 momentum; there and back
    transfer = 4 * k * a + 2 * ch * halo + (values * 8 * ghost / NET_BANDWIDTH if net else 0.0)
    work = cp3 * particles / n_ranks
    migration = (mig2 + (n_ranks - 1) * a) if n_ranks > 1 else 0.0
    reduce = ALLREDUCES * 2 * math.log2(n_ranks) * a if n_ranks > 1 else 0.0
    return {"work": work, "exchange": transfer, "migration": migration, "reduce": reduce,
            "total": work + transfer + migration + reduce, "ghost": ghost, "box": s}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bulkflow", default=str(root.parent / "build" / "bin" / "bulkflow"))
    p.add_argument("--increments", type=int, default=1000)
    p.add_argument("--increments-3d", type=int, default=150)
    p.add_argument("--json", type=Path)
    a = p.parse_args()
    if not os.access(a.bulkflow, os.X_OK):
        sys.exit(f"bench_scaling: {a.bulkflow} is not an executable (bash scripts/build.sh release)")
    cores = os.cpu_count() or 1
    print(f"bench_scaling: {a.bulkflow}; {cores} cores, load average {os.getloadavg()[0]:.2f} at the start")
    runs = []
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for cell in (0.05, 0.125 / 4.5):
            text = hopper_scene(cell=cell, shape="GIMP", field_frames=1, history_dt=0.1)
            for ranks in (1, 2, 4):
                runs.append(one_run(a.bulkflow, text, f"hopper2d_{cell:.4g}", a.increments, ranks, tmp))
        text3 = hopper_scene_3d()
        for ranks in (1, 2):
            runs.append(one_run(a.bulkflow, text3, "hopper3d_0.1", a.increments_3d, ranks, tmp))
    print("\n1. runs (time loop wall; work = particle phases, max over ranks; exchange and migration: max/mean)")
    print("   scene           ranks particles  P_max  held  ghost  halo  nbrs   loop [s]  work [s]  exchange [s]   migration [s]  RSS/rank [MB]")
    for r in runs:
        print(f"   {r['name']:15s} {r['ranks']:5d} {r['particles']:9d} {r['p_max']:6d} {r['held']:5d} {r['ghost']:6d} "
              f"{r['halo']:5d} {r['neighbours']:5d} {r['loop']:9.3f} {r['work_max']:9.3f} "
              f"{r['exchange_max']:6.3f}/{r['exchange_mean']:6.3f} {r['migration_max']:6.3f}/{r['migration_mean']:6.3f}  "
              + ", ".join(f"{x:.0f}" for x in r["rss"]))
    one = {r["name"]: r for r in runs if r["ranks"] == 1}
    cp2 = sum(r["work_max"] for r in one.values() if "2d" in r["name"]) / sum(
        r["steps"] for r in one.values() if "2d" in r["name"])
    cp3 = one["hopper3d_0.1"]["work_max"] / one["hopper3d_0.1"]["steps"]
    two = [r for r in runs if r["ranks"] == 2 and "2d" in r["name"]]
    alpha, ch = fit_exchange(two)
    mig2 = float(np.mean([r["migration_mean"] / r["increments"] for r in two]))
    mem = fit_memory(runs)
    print("\n2. measured costs")
    print(f"   particle work c_p: 2D {cp2 * 1e9:.0f} ns, 3D {cp3 * 1e9:.0f} ns per particle-step (1 rank)")
    print(f"   grid exchange (2 ranks, waiting removed): alpha {alpha * 1e6:.2f} us per message, "
          f"c_h {ch * 1e9:.1f} ns per halo node and exchange (shared memory)")
    print(f"   migration: {mig2 * 1e6:.1f} us per increment on 2 ranks")
    print(f"   memory: peak RSS = {mem[0] / 1e6:.1f} MB + {mem[1]:.0f} B x particles + {mem[2]:.0f} B x held grid nodes "
          "(least squares over every run)")
    print("\n3. predicted against measured time loop")
    print("   scene           ranks  predicted [s]  measured [s]  ratio   speed-up measured (1 rank / N ranks)")
    preds = []
    for r in runs:
        cp = cp3 if "3d" in r["name"] else cp2
        pr = predict(r, cp, alpha, ch, mig2, cores) + r["output"]
        ref = one[r["name"]]["loop"]
        note = " (oversubscribed)" if r["ranks"] > cores else ""
        preds.append({"name": r["name"], "ranks": r["ranks"], "predicted": pr, "measured": r["loop"]})
        print(f"   {r['name']:15s} {r['ranks']:5d}  {pr:13.3f}  {r['loop']:12.3f}  {r['loop'] / pr:5.2f}   "
              f"{ref / r['loop']:.2f}{note}")
    print("\n4. 3D silo, 10^8 particles (2x2x2 per cell), cubic boxes; seconds per increment")
    table = []
    for label, net in (("this machine's alpha", False), ("cluster network", True)):
        print(f"   {label}: alpha {NET_ALPHA * 1e6 if net else alpha * 1e6:.2f} us"
              + (f", {NET_BANDWIDTH / 1e9:.0f} GB/s" if net else ""))
        print("     N       strong: work    exchange  migration  reduce   total     efficiency |"
              "  weak (97 656/rank): total  efficiency")
        strong1 = silo(1, 1.0e8, cp3, alpha, ch, mig2, net)["total"]
        weak1 = silo(1, 1.0e8 / 1024, cp3, alpha, ch, mig2, net)["total"]
        for n in (1, 2, 4, 8, 64, 512, 1024):
            s = silo(n, 1.0e8, cp3, alpha, ch, mig2, net)
            w = silo(n, 1.0e8 / 1024 * n, cp3, alpha, ch, mig2, net)
            table.append({"network": label, "ranks": n, "strong": s, "weak": w})
            print(f"     {n:5d}  {s['work']:10.4f} {s['exchange']:10.5f} {s['migration']:10.5f} {s['reduce']:8.6f} "
                  f"{s['total']:9.4f}  {strong1 / (n * s['total']):8.3f}   | {w['total']:9.4f}  {weak1 / w['total']:8.3f}")
    if a.json:
        a.json.parent.mkdir(parents=True, exist_ok=True)
        a.json.write_text(json.dumps({"runs": runs, "costs": {"cp2": cp2, "cp3": cp3, "alpha": alpha, "ch": ch,
                                                              "migration2": mig2, "memory": mem},
                                      "predictions": preds, "silo": table}, indent=1))
    print(f"\n(load average at the end {os.getloadavg()[0]:.1f} on {cores} cores)")


if __name__ == "__main__":
    main()
