#!/usr/bin/env python3
"""MPM throughput benchmark (a script that prints figures; not a test).

    .venv/bin/python scripts/bench_mpm.py [--bulkflow build/bin/bulkflow] [--increments 3000]
                                         [--compare OLD_BINARY [--rounds 3]]
                                         [--discharge SECONDS --cell H --np N
                                          --discharge-sort N --decomposition spatial [--timing]
                                          [--capacity]]

1. The ch. 4 wedge hopper's FILL step (--stop-after N increments) in 2D (cell 0.05 m, 2x2 PPC,
   uGIMP and linear shapes) and in 3D (the same wedge as a slab of 4 cells between two mirrored
   symmetry planes, cell 0.1 m, 2x2x2 PPC, uGIMP; --increments-3d), on 1 and 2 ranks: particle-
   steps per second from the solver's own count (Σ particles over increments) divided by
   - the wall time of its time loop ("wall"), which on this shared machine measures the load as
     much as the code, and
   - the user CPU time of each rank's process ("cpu", per core: every rank's particle-steps over
     its own CPU seconds), which the other jobs on the machine disturb far less;
   and each rank's peak memory (max RSS). On 2 ranks (particle decomposition, replicated grid)
   the CPU time includes what a rank spins in MPI while it waits for the other at the grid sums.
2. --compare OLD_BINARY: every case above with OLD, NEW (the same deck: SORT=0, the old sums bit
   for bit) and NEW with *MPM CONTROLS, SORT=N (--sort, cell order) alternated (forward, then
   backward, for --rounds rounds), in this one run, so all see the same machine; prints the
   medians and the ratios to OLD (higher is faster), the memory per rank, and whether the
   history CSV is byte-identical to OLD's (else the largest difference of a history value
   relative to its column's largest magnitude).
3. --discharge S: the wall time of the whole ch. 4 hopper run (1 s fill + S s discharge with
   inflow) at cell --cell (default 0.125/4.5 = 0.0278 m: the outlet half-width 4.5 cells with its
   edge mid-cell, within 0.6 % of 5.5 cells in the outlet centre velocity and 2.3 % in the MDR;
   bulkflow-mpm-study convergence, src/mpm/README.md), on --np ranks, the wall time per simulated
   second and the MDR; --discharge-sort N and --decomposition spatial run it with cell-ordered
   particles and the spatial decomposition (target: under 150 s for 5 s of discharge on 2 cores).
4. --capacity (with --discharge): the machine's capacity around the --np run — two 1-rank runs
   at once, the --np run, one 1-rank run alone, back to back — and the speed-up as a share of it
   (docs/scaling.md: on this 2-core VM the capacity itself moves between about 1.6 and 1.9).
Needs the release build (scripts/build.sh release).
"""
import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

root = Path(__file__).resolve().parent
sys.path.insert(0, str(root))
from bulkflow.mpm.hopper_scene import hopper_scene  # noqa: E402

# Runs one rank's process and writes its peak RSS [kB] and user/system CPU seconds to
# PREFIX<rank> (the launcher's children only: the solver).
RUSAGE_WRAPPER = (
    "import os, resource, subprocess, sys\n"
    "r = subprocess.run(sys.argv[2:])\n"
    "u = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
    "rank = os.environ.get('OMPI_COMM_WORLD_RANK', '0')\n"
    "open(sys.argv[1] + rank, 'w').write(f'{u.ru_maxrss} {u.ru_utime} {u.ru_stime}')\n"
    "sys.exit(r.returncode)\n")


def hopper_scene_3d(cell=0.1, ppc=2, depth_cells=4, theta=30.0, outlet=0.25, height=3.0, wall_friction=5.0,
                    fill_time=1.0, ramp=0.6, history_dt=0.1):
    """The ch. 4 wedge hopper (hopper_scene's geometry and material) as a 3D slab: the same
    half model in x-y, depth depth_cells cells between symmetry planes z = 0 and z = depth on
    node planes (mirrored), the inclined wall and the closed outlet as planes limited to boxes.
    Fill step only (the benchmark stops in it)."""
    t = math.radians(theta)
    y0 = 0.5 * outlet / math.tan(t)
    ytop = y0 + height
    xtop = ytop * math.tan(t)
    mu = math.tan(math.radians(wall_friction))
    depth = depth_cells * cell
    lo = (-4 * cell, y0 - 8 * cell, -3 * cell)
    ymax = ytop + 0.5 * height / 3 + 4 * cell
    hi = (ymax * math.tan(t) + 4 * cell, ymax, depth + 3 * cell)
    # the 2D scene's material (hopper_scene, dilation table and VUSDFLD)
    two_d = hopper_scene(cell=cell, ppc=ppc, theta=theta, outlet=outlet, height=height,
                         wall_friction=wall_friction)
    material = two_d[two_d.index("*MATERIAL"):two_d.index("*PARTICLES")]
    name = re.search(r"\*MATERIAL, NAME=(\S+)", material).group(1)
    nx, ny = -math.cos(t), math.sin(t)
    lines = [
        "*HEADING",
        f"MPM wedge hopper (thesis ch. 4) as a 3D slab of {depth_cells} cells: cell {cell:g} m, PPC {ppc}",
        f"*MPM GRID, CELL={cell:.12g}, SHAPE=GIMP",
        f"{lo[0]:.9f}, {lo[1]:.9f}, {lo[2]:.9f}",
        f"{hi[0]:.9f}, {hi[1]:.9f}, {hi[2]:.9f}",
        "*MPM CONTROLS, FLIP=0.99, CFL=0.3, DAMPING=0.1",
        material.rstrip("\n"),
        f"*PARTICLES, MATERIAL={name}, PPC={ppc}, TYPE=POLYGON, Z1=0., Z2={depth:.9f}",
    ]
    lines += [f"{x:.9f}, {y:.9f}" for x, y in [(0.0, y0), (0.5 * outlet, y0), (xtop, ytop), (0.0, ytop)]]
    lines += [
        "*MPM WALL, NAME=AXIS, TYPE=SYMMETRY", "0., 0., 0., 1., 0., 0.",
        "*MPM WALL, NAME=FRONT, TYPE=SYMMETRY", "0., 0., 0., 0., 0., 1.",
        "*MPM WALL, NAME=BACK, TYPE=SYMMETRY", f"0., 0., {depth:.9f}, 0., 0., -1.",
        f"*MPM WALL, NAME=WALL, FRICTION={mu:.7f}",
        f"{0.5 * outlet:.9f}, {y0:.9f}, 0., {nx:.9f}, {ny:.9f}, 0.",
        f"{lo[0]:.9f}, {y0:.9f}, {lo[2]:.9f}", f"{hi[0]:.9f}, {hi[1]:.9f}, {hi[2]:.9f}",
        f"*MPM WALL, NAME=OUTLET, FRICTION={mu:.7f}",
        f"0., {y0:.9f}, 0., 0., 1., 0.",
        f"{lo[0]:.9f}, {lo[1]:.9f}, {lo[2]:.9f}", f"{0.5 * outlet:.9f}, {y0:.9f}, {hi[2]:.9f}",
        f"*OUTFLOW, BELOW={y0 - 2 * cell:.9f}",
        "*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP, TIME=TOTAL TIME", f"0., 0., {ramp:g}, 1.",
        "*STEP, NAME=FILL", "*DYNAMIC, EXPLICIT", f", {fill_time:g}",
        "*DLOAD, AMPLITUDE=RAMP", ", GRAV, 9.81, 0., -1., 0.",
        "*OUTPUT, FIELD, NUMBER INTERVAL=1", "*ELEMENT OUTPUT", "S, SDV",
        f"*OUTPUT, HISTORY, TIME INTERVAL={history_dt:g}", "*ENERGY OUTPUT", "*END STEP",
    ]
    return "\n".join(lines) + "\n"


def run(cmd, env=None):
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    return r, time.perf_counter() - t0


def throughput(out):
    m = re.search(r"throughput (\d+) particle-steps,\s+([0-9.E+-]+) per second \(time loop\s+([0-9.]+) s", out)
    return (int(m.group(1)), float(m.group(2)), float(m.group(3))) if m else None


def mpi_env():
    return dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                OMPI_MCA_rmaps_base_oversubscribe="1")


def measured_run(binary, scene, out, increments, ranks):
    """One run of `binary` on `scene`: particle-steps, time-loop wall, per-rank max RSS [MB] and
    user CPU [s] (lists over ranks), the stdout."""
    prefix = f"{out}.rusage."
    cmd = [sys.executable, "-c", RUSAGE_WRAPPER, prefix, binary, str(scene), "--output", str(out), "--quiet",
           "--stop-after", str(increments)]
    if ranks > 1:
        cmd = ["mpirun", "-np", str(ranks)] + cmd
    r, _ = run(cmd, env=mpi_env())
    t = throughput(r.stdout)
    if r.returncode != 0 or t is None:
        print(r.stdout, r.stderr)
        sys.exit(1)
    rss, cpu = [], []
    for k in range(ranks):
        kb, user, _system = Path(f"{prefix}{k}").read_text().split()
        rss.append(int(kb) / 1024)
        cpu.append(float(user))
    return {"steps": t[0], "loop": t[2], "rss": rss, "cpu": cpu, "stdout": r.stdout}


def history_difference(a, b):
    """'identical' if the history CSVs are the same bytes, else the largest |a − b| of a value
    relative to its scale: the column's largest |a|; for a vector (WALLFk_<wall>, XCMk, VCMk) the
    largest of its components (a component that is round-off noise, as the force normal to a
    mirrored plane or the out-of-plane velocity of a slab between mirrors, is not its own
    scale), for ETOTAL (a balance of terms) the largest energy."""
    ta, tb = Path(a).read_bytes(), Path(b).read_bytes()
    if ta == tb:
        return "identical"
    import numpy as np
    ha = np.genfromtxt(a, delimiter=",", names=True)
    hb = np.genfromtxt(b, delimiter=",", names=True)
    if ha.shape != hb.shape:
        return f"different rows ({ha.shape[0]} vs {hb.shape[0]})"
    names = ha.dtype.names

    def scale(name):
        m = re.match(r"(WALLF|XCM|VCM)\d(.*)", name)
        if m:
            group = [f"{m.group(1)}{k}{m.group(2)}" for k in (1, 2, 3)]
            return max(np.max(np.abs(ha[g])) for g in group if g in names)
        if name == "ETOTAL":
            return max(np.max(np.abs(ha[n])) for n in names if n.startswith("ALL"))
        return np.max(np.abs(ha[name]))

    worst = []
    for name in names:
        sc = scale(name)
        if sc > 0:
            worst.append((float(np.max(np.abs(ha[name] - hb[name])) / sc), name))
    worst.sort(reverse=True)
    return "differ: max relative " + ", ".join(f"{d:.1e} ({n})" for d, n in worst[:2])


def cases(tmp, a):
    scene2 = tmp / "hopper_2d_gimp.inp"
    scene2.write_text(hopper_scene(cell=0.05, shape="GIMP", field_frames=1, history_dt=0.1))
    scene3 = tmp / "hopper_3d_gimp.inp"
    scene3.write_text(hopper_scene_3d())
    out = []
    for ranks in (1, 2):
        out.append((f"2D uGIMP, {ranks} rank{'s' if ranks > 1 else ' '}", scene2, a.increments, ranks))
        out.append((f"3D uGIMP, {ranks} rank{'s' if ranks > 1 else ' '}", scene3, a.increments_3d, ranks))
    return out


def describe(res, ranks):
    per_core_cpu = res["steps"] / sum(res["cpu"])
    per_core_wall = res["steps"] / res["loop"] / ranks
    return per_core_cpu, per_core_wall


def plain(tmp, a):
    scene = tmp / "hopper_2d_linear.inp"
    scene.write_text(hopper_scene(cell=0.05, shape="LINEAR", field_frames=1, history_dt=0.1))
    runs = cases(tmp, a) + [("2D linear, 1 rank ", scene, a.increments, 1)]
    print("  case                  particles  incr.   per core: cpu        wall      max RSS per rank")
    for label, sc, incr, ranks in runs:
        res = measured_run(a.bulkflow, sc, tmp / f"{sc.stem}_np{ranks}", incr, ranks)
        npart = re.search(r"(\d+) particles,", res["stdout"]).group(1)
        cpu, wall = describe(res, ranks)
        print(f"  {label:20s}  {npart:>9s}  {incr:5d}   {cpu:.3e}  {wall:.3e}   "
              + ", ".join(f"{m:.0f}" for m in res["rss"]) + " MB")
    print(f"  (particle-steps/s; load average at the end {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")


def with_sort(scene, every, tmp):
    """The scene with SORT=every on its *MPM CONTROLS lines (a copy; the old binary does not
    know the option)."""
    text = re.sub(r"^(\*MPM CONTROLS[^\n]*)$", lambda m: f"{m.group(1)}, SORT={every}", scene.read_text(), flags=re.M)
    out = tmp / f"{scene.stem}_sort{every}.inp"
    out.write_text(text)
    return out


def compare(tmp, a):
    variants = [("old", a.compare, 0), ("new", a.bulkflow, 0)] + ([("sorted", a.bulkflow, a.sort)] if a.sort else [])
    print(f"  old    {a.compare}\n  new    {a.bulkflow} (SORT=0: block order, bit for bit the old sums)")
    if a.sort:
        print(f"  sorted {a.bulkflow} with *MPM CONTROLS, SORT={a.sort} (cell order, particle-major transfers)")
    print(f"  {a.rounds} rounds, the variants alternated (forward, then backward)")
    print("  case                 variant  per core: cpu  x old | wall      x old | max RSS/rank | history vs old")
    for label, sc, incr, ranks in cases(tmp, a):
        got = {tag: [] for tag, _, _ in variants}
        for k in range(a.rounds):
            for tag, binary, every in (variants if k % 2 == 0 else variants[::-1]):
                scene = with_sort(sc, every, tmp) if every else sc
                got[tag].append(measured_run(binary, scene, tmp / f"{sc.stem}_np{ranks}_{tag}", incr, ranks))
        med = {}
        for tag, _, _ in variants:
            med[tag] = (statistics.median(describe(r, ranks)[0] for r in got[tag]),
                        statistics.median(describe(r, ranks)[1] for r in got[tag]),
                        max(max(r["rss"]) for r in got[tag]))
        for tag, _, _ in variants:
            o, n = med["old"], med[tag]
            hist = "" if tag == "old" else history_difference(tmp / f"{sc.stem}_np{ranks}_old_history.csv",
                                                              tmp / f"{sc.stem}_np{ranks}_{tag}_history.csv")
            print(f"  {label:20s} {tag:7s}  {n[0]:.3e} {n[0] / o[0]:5.2f} | {n[1]:.3e} {n[1] / o[1]:5.2f} |"
                  f" {n[2]:8.0f} MB  | {hist}")
    print(f"  (particle-steps/s per core, medians of {a.rounds} runs; {a.increments} increments 2D, {a.increments_3d} 3D;"
          f" load average at the end {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")


def discharge_scene(tmp, a):
    """The --discharge deck (SORT and decomposition as asked) and how it was made."""
    scene = tmp / "hopper_discharge.inp"
    scene.write_text(hopper_scene(cell=a.cell, discharge_time=a.discharge, field_frames=5, history_dt=0.01))
    how = "block order (SORT=0)"
    if a.discharge_sort:
        scene = with_sort(scene, a.discharge_sort, tmp)
        how = f"SORT={a.discharge_sort}"
    if a.decomposition != "replicated":
        # model data: before the first step
        text = scene.read_text().replace("*STEP", f"*MPM CONTROLS, DECOMPOSITION={a.decomposition.upper()}\n*STEP", 1)
        scene = tmp / f"{scene.stem}_{a.decomposition}.inp"
        scene.write_text(text)
    how += f", {a.decomposition} decomposition"
    return scene, how


def discharge(tmp, a):
    env = mpi_env()
    scene, how = discharge_scene(tmp, a)
    # not --quiet: the solver's "step 1/2 ... done ... wall X s" line splits the fill from the discharge
    cmd = [a.bulkflow, str(scene), "--output", str(tmp / "hopper_discharge")]
    if a.np > 1:
        cmd = ["mpirun", "-np", str(a.np)] + cmd
    r, wall = run(cmd, env=env)
    t = throughput(r.stdout)
    if r.returncode != 0 or t is None:
        print(r.stdout, r.stderr)
        sys.exit(1)
    npart = re.search(r"(\d+) particles,", r.stdout).group(1)
    print(f"  ch. 4 hopper, {a.np} rank(s), {how}, cell {a.cell:g} m ({npart} particles), 1 s fill + "
          f"{a.discharge:g} s discharge with inflow: wall time {wall:.1f} s ({wall / (1 + a.discharge):.1f} s per simulated second), "
          f"{t[1]:.3e} particle-steps/s")
    done = [float(x) for x in re.findall(r"^\s+step 1/\d+ .* done .* wall\s+([0-9.]+) s", r.stdout, re.M)]
    fill = done[0] if done else float("nan")
    rest = t[2] - fill
    print(f"    of it: fill step {fill:.1f} s, discharge step {rest:.1f} s (time loop {t[2]:.1f} s; "
          f"set-up and output close {wall - t[2]:.1f} s)")
    target = 150.0 * a.discharge / 5.0   # issue 19: 5 s of discharge under 2.5 minutes on 2 cores
    print(f"    target: under 150 s for 5 s of discharge at the converged cell on 2 cores ({target:.0f} s for "
          f"{a.discharge:g} s): the discharge step {'meets' if rest < target else 'does NOT meet'} it "
          f"({rest:.0f} s); fill + discharge {'also meets' if wall < target else 'does not'} ({wall:.0f} s); "
          f"load average at the end {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    import numpy as np
    from bulkflow.mpm.discharge import mean_discharge_rate
    hist = np.genfromtxt(str(tmp / "hopper_discharge_history.csv"), delimiter=",", names=True)
    print(f"    steady MDR (full hopper, from 0.5 s after opening): {2 * mean_discharge_rate(hist):.1f} kg/s/m; "
          f"history: {tmp / 'hopper_discharge_history.csv'}")
    if a.timing:
        # the solver's end report: its timing table (max and mean over the ranks) and the
        # decomposition's counts, where a 2-rank run's extra time shows
        m = re.search(r"^.*ranks, \d+ re-partitions.*$", r.stdout, re.M)
        if m:
            print("    " + m.group(0).strip())
        m = re.search(r"^timing \(.*?(?=^\S|\Z)", r.stdout, re.M | re.S)
        print("    " + (m.group(0).rstrip().replace("\n", "\n    ") if m else "(no timing table in the solver's output)"))


def capacity(tmp, a):
    """--capacity: what this machine gives two jobs at once, around the --np run: two 1-rank runs
    of the discharge deck at once, the --np run, then one 1-rank run alone (back to back, so all
    see the same hour). Prints the capacity 2 T1/T(two at once), the speed-up T1/Tnp and the
    speed-up over the capacity: an MPI run cannot beat two jobs that never wait for each other."""
    env = mpi_env()
    scene, how = discharge_scene(tmp, a)

    def solver(name):
        return [a.bulkflow, str(scene), "--output", str(tmp / name), "--quiet"]

    # each run's own end: waiting on them in turn would give the second the first's end when it
    # finished earlier (both walls then read the same, and the capacity came out low)
    errs = [tmp / f"cap{k}.stderr" for k in (1, 2)]
    sinks = [err.open("w") for err in errs]
    t0 = time.perf_counter()
    pair = [subprocess.Popen(solver(f"cap{k}"), stdout=subprocess.DEVNULL, stderr=sink)
            for k, sink in zip((1, 2), sinks)]
    walls = [None, None]
    while None in walls:
        for k, proc in enumerate(pair):
            if walls[k] is None and proc.poll() is not None:
                walls[k] = time.perf_counter() - t0
        time.sleep(0.05)
    for sink in sinks:
        sink.close()
    for proc, err in zip(pair, errs):
        if proc.returncode != 0:
            sys.exit(f"bench_mpm --capacity: a 1-rank run failed:\n{err.read_text()[-2000:]}")
    both = statistics.mean(walls)
    cmd = solver("capnp")
    if a.np > 1:
        cmd = ["mpirun", "-np", str(a.np)] + cmd
    r, t_np = run(cmd, env=env)
    r1, t_1 = run(solver("cap1alone"), env=env)
    if r.returncode != 0 or r1.returncode != 0:
        sys.exit(f"bench_mpm --capacity: a run failed:\n{(r.stderr + r1.stderr)[-2000:]}")
    cap = 2 * t_1 / both
    print(f"  capacity ({how}, 1 s fill + {a.discharge:g} s discharge): two 1-rank runs at once "
          f"{walls[0]:.1f} / {walls[1]:.1f} s, one alone {t_1:.1f} s: the machine gives two jobs {cap:.2f} "
          f"times one's speed now")
    print(f"    {a.np} ranks {t_np:.1f} s: speed-up {t_1 / t_np:.2f}, {100 * t_1 / t_np / cap:.0f} % of the capacity")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bulkflow", default=str(root.parent / "build" / "bin" / "bulkflow"))
    p.add_argument("--increments", type=int, default=3000, help="2D increments (default 3000)")
    p.add_argument("--increments-3d", type=int, default=300, help="3D increments (default 300)")
    p.add_argument("--compare", metavar="OLD_BINARY", help="alternate OLD_BINARY and --bulkflow, print ratios")
    p.add_argument("--rounds", type=int, default=3, help="--compare: runs of each binary per case (default 3)")
    p.add_argument("--sort", type=int, default=20, metavar="N",
                   help="--compare: also run the new binary with *MPM CONTROLS, SORT=N (default 20; 0: not)")
    p.add_argument("--discharge", type=float, default=0.0)
    # the converged resolution of study a (src/mpm/README.md): outlet half-width 4.5 cells, edge mid-cell
    p.add_argument("--cell", type=float, default=0.125 / 4.5)
    p.add_argument("--np", type=int, default=1, help="ranks for the --discharge run")
    p.add_argument("--discharge-sort", type=int, default=0, metavar="N",
                   help="--discharge: *MPM CONTROLS, SORT=N (default 0: block order, the old sums)")
    p.add_argument("--decomposition", choices=("replicated", "spatial"), default="replicated",
                   help="--discharge: *MPM CONTROLS, DECOMPOSITION= (default replicated)")
    p.add_argument("--skip-throughput", action="store_true", help="only the --discharge run")
    p.add_argument("--capacity", action="store_true",
                   help="--discharge: also measure the machine's 2-job capacity around an --np run "
                        "(two 1-rank runs at once, the --np run, one 1-rank run alone)")
    p.add_argument("--timing", action="store_true",
                   help="--discharge: also print the solver's timing table (max and mean over the ranks)")
    a = p.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_mpm_"))
    print(f"bulkflow MPM benchmark ({a.bulkflow}); scratch {tmp}")
    if a.compare:
        compare(tmp, a)
    elif not a.skip_throughput:
        plain(tmp, a)
    if a.discharge > 0:
        discharge(tmp, a)
        if a.capacity:
            capacity(tmp, a)


if __name__ == "__main__":
    main()
