#!/usr/bin/env python3
"""Solver benchmark (issue 3): element-steps per second per core, parallel speed-up, CalculiX,
and the effects check. A benchmark script that prints figures, not a test.

  .venv/bin/python scripts/bench_solver.py [--repeats 3] [--increments 600] [--only throughput,ccx,effects]
                                           [--build build] [--ccx-increments 40]

Takes about 15 minutes on 2 cores (most of it CalculiX; the baseline build of part 4 adds ~2 min once).

0. Machine capacity: two independent 1-rank runs at once against one alone. On a shared machine
   (other developers' jobs) the second core may not be free; then no 2-rank speed-up is possible
   and the figure says so (2.00 = two free cores).
1. Throughput: element-steps/s per core (= elements × increments / (loop seconds × ranks)) for
   CPE4R and C3D8R, elastic and Mohr-Coulomb, on 1 and 2 ranks, and the 2-rank speed-up. The
   scenes are wedge hoppers of ≈ 20 000 elements (inputs/bench/, written by the generator
   scripts/bulkflow/scenes/wedge_hopper.py): contact with the frictional rigid walls and outlet
   plate, gravity at once, bulk viscosity, a geostatic initial stress σh = σzz = K_a σv with the
   active Rankine ratio K_a = (1 − sin φ)/(1 + sin φ) = 0.49 (φ = 20°: the fill starts on the
   yield surface; in the last increment about 55 % (CPE4R) and 28 % (C3D8R) of the points return
   to it, nearly all have PEEQ > 0), history output only. "Loop seconds" is the `total` of the solver's timing
   table (max over ranks: from the effects registry to the end of the run, so reading the scene
   and partitioning are outside); the process wall time is shown too.
2. CalculiX: the same elastic scene with the walls replaced by pinned nodes (no contact: CalculiX
   has no analytic rigid walls in explicit), run by `ccx` (one thread, NLGEOM, its own stable
   increment) and by bulkflow (1 rank, its own stable increment). Each code runs two lengths; the
   cost per element per increment is the difference of the process wall times divided by the
   difference of element-increments, so set-up time cancels and the two codes need not take the
   same increments. Ratio = ccx cost / bulkflow cost (> 1: bulkflow faster). CalculiX's increments
   = period / its "SELECTED time increment" (constant); bulkflow's from its own report. A missing
   `ccx` is installed first (apt-get install calculix-ccx, as root or through sudo -n; --no-install
   skips that, and then this part).
3. Effects check: the Mohr-Coulomb CPE4R scene with a user field (*USER DEFINED FIELD; the ψ table
   is flat, ψ = 0 at both ends, so the mechanics are identical) and without: both timing tables,
   that 'user field' has no line when absent, peak memory (max RSS of a 1-rank run, /usr/bin/time -v)
   and that both give the same energies.

4. Instruction set: the build against a baseline-x86-64 build of the same source (made in
   build-baseline/, the bulkflow target only), runs interleaved: the gain of the AVX2 default
   (cmake/BulkflowFlags.cmake) and that both give byte-identical histories.

Targets: ≥ 5 M CPE4R Mohr-Coulomb element-steps/s per core; ≥ 1.8× speed-up on 2 ranks for
≥ 20 000 elements; faster than ccx. The machine may be shared: every figure is the median of
`--repeats` runs with the range in brackets, and the 1-minute load average is printed per case.
"""
from __future__ import annotations

import argparse
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "scripts"))
from bulkflow.scenes.wedge_hopper import WedgeHopper  # noqa: E402

TARGET_MC_CPE4R = 5.0e6
TARGET_SPEEDUP = 1.8
FLAT_PSI_TABLE = ((0.0, 0.0), (0.0, 0.2))       # ψ = 0 at ε_v = 0 and 0.2: a user field that changes nothing


# ---- scenes -------------------------------------------------------------------------------------
K_ACTIVE = (1 - math.sin(math.radians(20.0))) / (1 + math.sin(math.radians(20.0)))


def scene_2d(**kw) -> WedgeHopper:
    base = dict(n_across=67, initial_k=K_ACTIVE, ramp=0.0, field_frames=0, history_points=20)
    base.update(kw)
    return WedgeHopper(**base)


def scene_3d(**kw) -> WedgeHopper:
    base = dict(dim=3, bottom="flat", n_across=24, n_depth=8, depth=0.1, initial_k=K_ACTIVE, ramp=0.0,
                field_frames=0, history_points=20)
    base.update(kw)
    return WedgeHopper(**base)


def bench_scenes(increments: int) -> dict[str, WedgeHopper]:
    """Name -> scene; each lasts about `increments` stable increments."""
    scenes = {
        "cpe4r_elastic": scene_2d(elastic=True),
        "cpe4r_mc": scene_2d(),
        "cpe4r_mc_field": scene_2d(dilation_table=FLAT_PSI_TABLE),
        "c3d8r_elastic": scene_3d(elastic=True),
        "c3d8r_mc": scene_3d(),
        "cpe4r_elastic_pinned": scene_2d(elastic=True, walls="pinned"),
        "c3d8r_elastic_pinned": scene_3d(elastic=True, walls="pinned"),
    }
    for s in scenes.values():
        s.hold = increments * s.stable_dt()
        s.title = ""
    return scenes


def write_scenes(directory: Path, scenes: dict[str, WedgeHopper], force: bool) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    for name, s in scenes.items():
        path = directory / f"{name}.inp"
        text = s.inp_text()
        if force or not path.exists() or path.read_text() != text:
            path.write_text(text)


# ---- running ------------------------------------------------------------------------------------
def mpi_command(ranks: int) -> list[str]:
    if ranks == 1:
        return []
    return ["mpirun", "-np", str(ranks), "--oversubscribe"]


def load_average() -> float:
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


TIMING_ROW = re.compile(r"^\s+(\S(?:.*?\S)?)\s{2,}([0-9.]+)(?:\s+([0-9.]+))?\s+([0-9.]+) %\s+(\d+)\s*$")
OTHER_ROW = re.compile(r"^\s+other\s+([0-9.]+)\s+([0-9.]+) %\s*$")
TOTAL_ROW = re.compile(r"^\s+total\s+([0-9.]+)(?:\s+([0-9.]+))?\s*$")


def parse_run(stdout: str) -> dict:
    """Increments, the timing table (phase -> max seconds), its total and the effects line."""
    info = {"phases": {}, "shares": {}, "table": [], "effects": ""}
    m = re.search(r"bulkflow: done, (\d+) increments", stdout)
    if not m:
        raise RuntimeError("no 'bulkflow: done' line in the output:\n" + stdout[-2000:])
    info["increments"] = int(m.group(1))
    m = re.search(r"model\s+(\d+) nodes, (\d+) elements", stdout)
    info["elements"] = int(m.group(2))
    m = re.search(r"^\s+effects\s+(.*)$", stdout, re.M)
    info["effects"] = m.group(1).strip() if m else ""
    m = re.search(r"energies\s+ALLKE ALLIE ALLVD ALLFD ALLWK ALLAE:\s+(.*)$", stdout, re.M)
    info["energies"] = [float(v) for v in m.group(1).split()] if m else []
    in_table = False
    for line in stdout.splitlines():
        if line.startswith("timing (wall seconds"):
            in_table = True
            info["table"].append(line)
            continue
        if not in_table:
            continue
        info["table"].append(line)
        t = TOTAL_ROW.match(line)
        if t:
            info["total"] = float(t.group(1))
            break
        o = OTHER_ROW.match(line)
        if o:
            info["shares"]["other"] = float(o.group(2))
            continue
        r = TIMING_ROW.match(line)
        if r and r.group(1) != "phase":
            info["phases"][r.group(1)] = float(r.group(2))
            info["shares"][r.group(1)] = float(r.group(4))
    if "total" not in info:
        raise RuntimeError("no timing table in the output:\n" + stdout[-2000:])
    return info


def run_bulkflow(exe: Path, scene: Path, ranks: int, workdir: Path, measure_memory: bool = False) -> dict:
    workdir.mkdir(parents=True, exist_ok=True)
    base = workdir / scene.stem
    cmd = mpi_command(ranks) + [str(exe), str(scene), "--output", str(base), "--quiet"]
    if measure_memory and ranks == 1 and Path("/usr/bin/time").exists():
        cmd = ["/usr/bin/time", "-v"] + cmd
    load = load_average()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    info = parse_run(p.stdout)
    info["wall"] = wall
    info["load"] = load
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    if m:
        info["max_rss_kb"] = int(m.group(1))
    return info


def run_ccx(ccx: str, inp: Path, workdir: Path) -> dict:
    """Run CalculiX (one thread) on inp; wall time, its increment and the increments done."""
    workdir.mkdir(parents=True, exist_ok=True)
    job = workdir / inp.stem
    if inp.resolve() != job.with_suffix(".inp").resolve():
        shutil.copy(inp, job.with_suffix(".inp"))
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_STIFFNESS="1", CCX_NPROC_RESULTS="1",
               CCX_NPROC_EQUATION_SOLVER="1", NUMBER_OF_CPUS="1")
    load = load_average()
    t0 = time.perf_counter()
    p = subprocess.run([ccx, "-i", job.name], cwd=workdir, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if p.returncode != 0 or "Job finished" not in p.stdout:
        raise RuntimeError(f"ccx failed on {inp}:\n{p.stdout[-2000:]}\n{p.stderr[-1000:]}")
    m = re.search(r"SELECTED time increment:\s*([0-9.eE+-]+)", p.stdout)
    dt = float(m.group(1))
    text = inp.read_text()
    period = float(re.search(r"\*DYNAMIC, EXPLICIT\n[^,]*,\s*([0-9.eE+-]+)", text).group(1))
    for f in workdir.glob(job.name + ".*"):
        if f.suffix in (".frd", ".dat", ".12d", ".cvg", ".sta"):
            f.unlink()
    return {"wall": wall, "dt": dt, "increments": math.ceil(period / dt - 1e-9), "load": load}


# ---- reporting ----------------------------------------------------------------------------------
def med_range(values, scale=1.0, fmt="{:.2f}") -> str:
    v = sorted(x / scale for x in values)
    med = statistics.median(v)
    if len(v) == 1:
        return fmt.format(med)
    return f"{fmt.format(med)} [{fmt.format(v[0])}–{fmt.format(v[-1])}]"


def machine_capacity(exe, scene: Path, work: Path, repeats: int) -> float:
    """How many cores' worth of throughput two processes get now: 2 × (solo loop time) / (loop
    time of two independent 1-rank runs at once). 2.0 on two free cores; about 1 when another job
    keeps a core busy (then no 2-rank speed-up is possible, whatever the code)."""
    caps = []
    for _ in range(repeats):
        solo = run_bulkflow(exe, scene, 1, work / "capacity")["total"]
        cmd = [str(exe), str(scene), "--quiet"]
        procs = [subprocess.Popen(cmd + ["--output", str(work / "capacity" / f"pair{k}")], stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True) for k in range(2)]
        outs = [p.communicate()[0] for p in procs]
        pair = max(parse_run(o)["total"] for o in outs)
        caps.append(2 * solo / pair)
    print(f"\n== 0. machine capacity now: two independent 1-rank runs of {scene.stem} at once get "
          f"{med_range(caps)} cores' worth (2.00 = two free cores; this bounds the 2-rank speed-up)")
    return statistics.median(caps)


def throughput(exe, scene_dir, work, repeats, cases, capacity=None):
    print("\n== 1. throughput: element-steps per second per core (M/s), median [min–max] of "
          f"{repeats} runs")
    print(f"{'case':16s} {'elements':>8s} {'incs':>6s} {'ranks':>5s} {'loop s':>18s} {'M el-steps/s/core':>22s} "
          f"{'process wall s':>18s} {'load':>5s}")
    results = {}
    for case in cases:
        scene = scene_dir / f"{case}.inp"
        for ranks in (1, 2):
            runs = [run_bulkflow(exe, scene, ranks, work / case) for _ in range(repeats)]
            n_el, n_inc = runs[0]["elements"], runs[0]["increments"]
            rates = [n_el * r["increments"] / (r["total"] * ranks) for r in runs]
            results[(case, ranks)] = runs
            print(f"{case:16s} {n_el:8d} {n_inc:6d} {ranks:5d} {med_range([r['total'] for r in runs]):>18s} "
                  f"{med_range(rates, 1e6):>22s} {med_range([r['wall'] for r in runs]):>18s} "
                  f"{statistics.median([r['load'] for r in runs]):5.2f}")
    print("\nspeed-up on 2 ranks (loop time 1 rank / 2 ranks; medians, range over pairs of runs):")
    for case in cases:
        one, two = results[(case, 1)], results[(case, 2)]
        s = [a["total"] / b["total"] for a in one for b in two]
        sw = [a["wall"] / b["wall"] for a in one for b in two]
        med = statistics.median(a["total"] for a in one) / statistics.median(b["total"] for b in two)
        verdict = "meets" if med >= TARGET_SPEEDUP else "below"
        bound = f"; {med / capacity:.0%} of the capacity measured now ({capacity:.2f})" if capacity else ""
        print(f"  {case:16s} {one[0]['elements']:6d} elements: {med:.2f}× (pairs {min(s):.2f}–{max(s):.2f}; "
              f"process wall {statistics.median(sw):.2f}×{bound})  target ≥ {TARGET_SPEEDUP}×: {verdict}")
    if ("cpe4r_mc", 1) in results:
        best = max(statistics.median(c["elements"] * c["increments"] / (c["total"] * r) for c in results[("cpe4r_mc", r)])
                   for r in (1, 2))
        print(f"\nCPE4R Mohr-Coulomb: {best / 1e6:.2f} M element-steps/s per core (best median of 1 and 2 ranks); "
              f"target ≥ {TARGET_MC_CPE4R / 1e6:.0f} M/s: {'meets' if best >= TARGET_MC_CPE4R else 'below'}")
    print("\nshare of the loop per phase (median over runs, 1 rank):")
    phases = []
    for case in cases:
        for name in results[(case, 1)][0]["shares"]:
            if name not in phases:
                phases.append(name)
    print(f"  {'phase':16s}" + "".join(f"{c:>16s}" for c in cases))
    for ph in phases:
        row = []
        for case in cases:
            vals = [r["shares"].get(ph) for r in results[(case, 1)] if ph in r["shares"]]
            row.append(f"{statistics.median(vals):15.1f}%" if vals else f"{'–':>16s}")
        print(f"  {ph:16s}" + "".join(row))
    return results


def ccx_comparison(exe, ccx, scenes, work, repeats, increments, ccx_increments):
    print("\n== 2. CalculiX (ccx, 1 thread) against bulkflow (1 rank), the same elastic scene, pinned walls")
    print("   cost per element-increment from two run lengths each (set-up cancels); median [min–max]")
    for case in ("cpe4r_elastic_pinned", "c3d8r_elastic_pinned"):
        s = scenes[case]
        n_el = s.n_elements()
        costs = {"bulkflow": [], "ccx": []}
        last = {}
        for code, lengths in (("bulkflow", (increments // 2, increments)), ("ccx", (ccx_increments, 2 * ccx_increments))):
            for rep in range(repeats):
                runs = []
                for n in lengths:
                    sc = WedgeHopper(**dict(s.__dict__))
                    sc.hold = n * s.stable_dt()      # n bulkflow increments; ccx takes smaller ones
                    d = work / "ccx"
                    d.mkdir(parents=True, exist_ok=True)
                    if code == "bulkflow":
                        inp = d / f"{case}_{n}.inp"
                        inp.write_text(sc.inp_text())
                        runs.append(run_bulkflow(exe, inp, 1, d))
                    else:
                        inp = d / f"{case}_{n}_ccx.inp"
                        inp.write_text(sc.calculix_text())
                        runs.append(run_ccx(ccx, inp, d))
                costs[code].append((runs[1]["wall"] - runs[0]["wall"])
                                   / (n_el * (runs[1]["increments"] - runs[0]["increments"])))
                last[code] = runs
        ratio = [c / b for c in costs["ccx"] for b in costs["bulkflow"]]
        ratio_med = statistics.median(costs["ccx"]) / statistics.median(costs["bulkflow"])
        bf, cx = last["bulkflow"], last["ccx"]
        print(f"  {case}: {n_el} elements")
        print(f"    bulkflow: {med_range(costs['bulkflow'], 1e-9, '{:.1f}')} ns per element-increment "
              f"= {1e-6 / statistics.median(costs['bulkflow']):.2f} M el-steps/s; increments {bf[0]['increments']}/{bf[1]['increments']}, "
              f"process wall {bf[0]['wall']:.2f}/{bf[1]['wall']:.2f} s (last repeat)")
        print(f"    ccx:      {med_range(costs['ccx'], 1e-9, '{:.1f}')} ns per element-increment "
              f"= {1e-6 / statistics.median(costs['ccx']):.3f} M el-steps/s; increments {cx[0]['increments']}/{cx[1]['increments']}, "
              f"process wall {cx[0]['wall']:.2f}/{cx[1]['wall']:.2f} s (last repeat)")
        print(f"    ratio ccx/bulkflow cost per element-increment: {ratio_med:.1f}× (range {min(ratio):.1f}–{max(ratio):.1f}); "
              f"ccx's stable increment {cx[0]['dt']:.3g} s vs bulkflow's {s.stable_dt():.3g} s (estimate): "
              f"per simulated second ccx needs {s.stable_dt() / cx[0]['dt']:.2f}× the increments")


def effects_check(exe, scene_dir, work, repeats):
    print("\n== 3. effects check: the CPE4R Mohr-Coulomb scene without and with a user field (1 rank)")
    out = {}
    for case in ("cpe4r_mc", "cpe4r_mc_field"):
        runs = [run_bulkflow(exe, scene_dir / f"{case}.inp", 1, work / "effects", measure_memory=True)
                for _ in range(repeats)]
        out[case] = runs
        r = runs[len(runs) // 2]
        print(f"\n  {case}: effects: {r['effects']}")
        for line in r["table"]:
            print("    " + line)
    a, b = out["cpe4r_mc"], out["cpe4r_mc_field"]
    has_line = any("user field" in line for line in a[0]["table"])
    print(f"\n  without a user field, 'user field' in the effects line: {'user field' in a[0]['effects']}, "
          f"in the timing table: {has_line}  ({'OK' if not has_line and 'user field' not in a[0]['effects'] else 'NOT OK'})")
    for name, runs in (("without", a), ("with", b)):
        rss = [r.get("max_rss_kb", 0) / 1024 for r in runs]
        print(f"  {name:7s} user field: loop {med_range([r['total'] for r in runs])} s, "
              f"user field phase {med_range([r['phases'].get('user field', 0.0) for r in runs], fmt='{:.3f}')} s, "
              f"material {med_range([r['phases'].get('material', 0.0) for r in runs])} s, "
              f"max RSS {med_range(rss, fmt='{:.1f}')} MB")
    same = a[0]["energies"] == b[0]["energies"]
    print(f"  final energies identical with and without the (flat) user field: {same}"
          + ("" if same else f"  {a[0]['energies']} vs {b[0]['energies']}"))


def build_march(build: Path) -> str:
    """The -march of a build's optimised flags, from its CMake cache (BulkflowFlags.cmake)."""
    cache = (build / "CMakeCache.txt").read_text() if (build / "CMakeCache.txt").exists() else ""
    def value(key):
        m = re.search(rf"^{key}:\w+=(.*)$", cache, re.M)
        return m.group(1).strip() if m else ""
    if value("BULKFLOW_NATIVE") in ("ON", "TRUE", "1"):
        return "native"
    arch = value("BULKFLOW_ARCH") or "auto"
    if arch == "auto":
        return "x86-64-v3" if value("BULKFLOW_HOST_RUNS_X86_64_V3") in ("1", "TRUE", "ON") else "compiler default"
    return arch


def instruction_set(exe, build: Path, scene_dir, work, repeats, baseline_dir: Path):
    """The benchmark's build against a baseline-x86-64 build of the same source: throughput of
    each and whether their histories agree byte for byte (they must: FMA is off)."""
    print(f"\n== 4. instruction set: {build.name} (-march={build_march(build)}) against a baseline build "
          f"({baseline_dir.name}, the compiler's default -march), 1 rank, runs interleaved")
    base_exe = baseline_dir / "bin" / "bulkflow"
    cfg = ["cmake", "-S", str(REPO), "-B", str(baseline_dir), "-DCMAKE_BUILD_TYPE=Release", "-DBULKFLOW_ARCH=default",
           f"-DPython3_EXECUTABLE={sys.executable}"]
    if not (baseline_dir / "CMakeCache.txt").exists() and shutil.which("ninja"):
        cfg += ["-G", "Ninja"]
    for cmd in (cfg, ["cmake", "--build", str(baseline_dir), "--target", "bulkflow", "--parallel", str(os.cpu_count())]):
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            print(f"  building the baseline failed; skipped\n{p.stdout[-1500:]}{p.stderr[-1500:]}")
            return
    for case in ("cpe4r_mc", "c3d8r_mc"):
        scene = scene_dir / f"{case}.inp"
        runs = {"this": [], "baseline": []}
        for _ in range(repeats):
            for key, e in (("this", exe), ("baseline", base_exe)):
                runs[key].append(run_bulkflow(e, scene, 1, work / "arch" / key))
        hist = [(work / "arch" / key / f"{case}_history.csv").read_bytes() for key in ("this", "baseline")]
        n_el, n_inc = runs["this"][0]["elements"], runs["this"][0]["increments"]
        rate = {k: [n_el * r["increments"] / r["total"] for r in v] for k, v in runs.items()}
        ratio = statistics.median(rate["this"]) / statistics.median(rate["baseline"])
        print(f"  {case:10s} {build_march(build):>16s}: {med_range(rate['this'], 1e6)} M el-steps/s; baseline: "
              f"{med_range(rate['baseline'], 1e6)}; ratio {ratio:.2f}×; histories byte-identical: {hist[0] == hist[1]}")


def install_ccx() -> None:
    """Debian's CalculiX (package calculix-ccx) for part 2, when root (or sudo) and apt-get are
    there; otherwise nothing (part 2 then says how to install it)."""
    if not shutil.which("apt-get"):
        return
    prefix = [] if os.geteuid() == 0 else (["sudo", "-n"] if shutil.which("sudo") else None)
    if prefix is None:
        return
    print("installing CalculiX for part 2: apt-get install -y calculix-ccx (--no-install skips this)", flush=True)
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    for cmd in (["apt-get", "update", "-qq"], ["apt-get", "install", "-y", "-qq", "calculix-ccx"]):
        p = subprocess.run(prefix + cmd, capture_output=True, text=True, env=env)
        if p.returncode != 0:
            print(f"  {' '.join(cmd)} failed: {p.stderr.strip()[-300:]}")
            return


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default=str(REPO / "build"))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--increments", type=int, default=600, help="increments per throughput run (about)")
    ap.add_argument("--ccx-increments", type=int, default=40,
                    help="short CalculiX run: this many bulkflow-sized increments of time (the long one: twice)")
    ap.add_argument("--only", default="throughput,ccx,effects,arch",
                    help="any of capacity, throughput (includes capacity), ccx, effects, arch")
    ap.add_argument("--baseline-build", default=str(REPO / "build-baseline"),
                    help="arch: where the baseline-instruction-set build is made (bulkflow target only)")
    ap.add_argument("--cases", default="cpe4r_elastic,cpe4r_mc,c3d8r_elastic,c3d8r_mc")
    ap.add_argument("--scenes", default=str(REPO / "inputs" / "bench"), help="where the scenes are written")
    ap.add_argument("--work", default=str(REPO / "out" / "bench"), help="outputs of the runs")
    ap.add_argument("--ccx", default=shutil.which("ccx") or "ccx")
    ap.add_argument("--no-install", action="store_true",
                    help="do not apt-get install calculix-ccx when ccx is missing (part 2 is then skipped)")
    a = ap.parse_args()

    exe = Path(a.build) / "bin" / "bulkflow"
    if not exe.exists():
        sys.exit(f"{exe} not found: build first (bash scripts/build.sh release)")
    if os.geteuid() == 0:
        os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        os.environ.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    scenes = bench_scenes(a.increments)
    scene_dir, work = Path(a.scenes), Path(a.work)
    write_scenes(scene_dir, scenes, force=False)
    only = set(a.only.split(","))
    print(f"bulkflow solver benchmark: {exe} (-march={build_march(Path(a.build))}), {os.cpu_count()} cores, "
          f"load average {load_average():.2f}; "
          f"scenes in {scene_dir}")
    for name, s in scenes.items():
        print(f"  {name:22s} {s.n_elements():6d} {'CPE4R' if s.dim == 2 else 'C3D8R'}, "
              f"{'elastic' if s.elastic else 'Mohr-Coulomb'}{', user field' if s.user_field else ''}, walls {s.walls}, "
              f"~{round(s.hold / s.stable_dt())} increments")
    capacity = None
    if "throughput" in only or "capacity" in only:
        capacity = machine_capacity(exe, scene_dir / "cpe4r_elastic.inp", work, a.repeats)
    if "throughput" in only:
        throughput(exe, scene_dir, work, a.repeats, a.cases.split(","), capacity)
    if "ccx" in only:
        if not shutil.which(a.ccx) and not a.no_install:
            install_ccx()
        if shutil.which(a.ccx):
            ccx_comparison(exe, a.ccx, scenes, work, a.repeats, a.increments, a.ccx_increments)
        else:
            print("\n== 2. CalculiX: ccx not found (apt-get install -y calculix-ccx, Debian's CalculiX); skipped")
    if "effects" in only:
        effects_check(exe, scene_dir, work, a.repeats)
    if "arch" in only:
        instruction_set(exe, Path(a.build), scene_dir, work, a.repeats, Path(a.baseline_build))
    return 0


if __name__ == "__main__":
    sys.exit(main())
