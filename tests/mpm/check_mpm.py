#!/usr/bin/env python3
"""MPM acceptance checks (issue 5): run bin/bulkflow on a scene of inputs/mpm/ and check its figures.

    check_mpm.py <kind> <scene.inp> --bulkflow <exe> --workdir <dir>

kinds:
  column     K0 column (2D or 3D): sigma_xx/sigma_yy and sigma_zz/sigma_yy = nu/(1-nu) within 2 %,
             sigma_yy = -rho g (H - y) within 2 % as the mean over each layer of grid cells below
             0.8 H (the two particle rows of a cell carry an equal and opposite offset of ~200 Pa,
             a sub-cell mode the grid does not see; its size is printed), the floor's reaction the
             weight (1e-4) and every plane's normal to it, exact mass balance
  incline    block sliding on an inclined wall: a = g (sin a - mu cos a) within 2 %
  heap       collapsed c = 0 column: surface slope within 3 deg of phi
  mpi        the same hopper on 1 rank and twice on 2 ranks (--mpiexec): the 2-rank runs are
             identical (deterministic), the fill step agrees with 1 rank to round-off (1e-9),
             exact mass balance and particle counts on 2 ranks, the frame holds every particle
  mirror     a symmetric collapse as a half model (symmetry plane on a node line; the scene given)
             and as the full model (mirror_full_2d.inp beside it): every half-model particle
             follows its full-model twin to 1e-6 m, energies are half the full model's to 1e-6,
             no particle is put back onto the plane (GUARDED = 0): src/mpm/mpm_mirror.f90
  mass       hopper with outlet, outflow and inflow: initial + in - out = in domain exactly
             (particle counts exact, masses to round-off), and both flows present
  mass_mu_of_i  the mass checks on a hopper whose MC material has the mu(I) block
             (docs/mu_of_i.md), and every frame's S, V, SDV finite; the friction angle used (SDV7)
             between the static angle (prop 3) and phi2 everywhere, and above the static angle
             somewhere in the discharge (the rate acted)
  plate      a rigid plate (a *SURFACE, TYPE=SEGMENTS on a *RIGID BODY node moved by *BOUNDARY) pushed
             into an elastic column in a frictionless box (plate_oedometer_2d.inp): its reaction
             against the oedometric force balance F = M W |ln(1 - u/H)|, M = E(1-nu)/((1+nu)(1-2nu)),
             within 2 % at the end and along the push (rows past 40 % of the push, against the
             mean of F over the row); floor = plate (static balance, 1e-3), side walls
             K0 F H / W (1 %), the plate's work in ALLWK balances ALLIE (ETOTAL < 1 % of ALLWK),
             no particle put back; stopped mid-push and restarted: identical history and frames
  bowl       particles settled in a bowl of two fixed CIRCL surfaces (bowl_arcs_2d.inp): the two
             arcs carry the weight (1e-3), each the horizontal thrust of a fluid at rest on its
             vertical projection rho g L^2 / 2 (3 %: the arc's normals), no particle outside the
             circle but every 5 deg sector's outermost within a particle spacing of it (on the arcs,
             not their chords), the pressure at the bottom within 10 % of rho g times its depth
  restart    on --ranks N: a run uninterrupted, one stopped with --stop-after K (in the
             discharge, after outflow and inflow began) and continued with --restart: every
             particle and grid frame (datasets and attributes), the XDMF files and the history
             CSV identical bit for bit; the *RESTART checkpoint left by the full run is at its
             last increment and a --restart from it changes nothing; refused restarts (no
             checkpoint, a changed scene, another number of ranks) exit with status 2 and a
             `file: ...; expected ...` message, no backtrace, no MPI_Abort
Every kind also checks the effects line and the timing table (MPM effects with shares).
Figures are printed so the test log holds them.
"""
import argparse
import math
import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np


def run(exe, scene, workdir):
    workdir.mkdir(parents=True, exist_ok=True)
    base = workdir / Path(scene).stem
    r = subprocess.run([exe, scene, "--output", str(base), "--quiet"], capture_output=True, text=True)
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    if r.returncode != 0:
        fail(f"bulkflow exited with status {r.returncode}")
    hist = np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)
    return base, r.stdout, hist


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def check(cond, msg):
    print(("ok    " if cond else "FAIL  ") + msg)
    if not cond:
        sys.exit(1)


def last_frame(base):
    f = h5py.File(str(base) + ".h5", "r")
    frames = sorted(f["particles"].keys())
    return f["particles"][frames[-1]]


def check_report(out, needed, absent=()):
    effects = next((l for l in out.splitlines() if l.strip().startswith("effects")), "")
    for e in needed:
        check(e in effects, f"effect '{e}' listed as active")
    timing = out.split("timing (wall seconds):")[-1]
    for e in absent:
        check(e not in effects and e not in timing, f"unused effect '{e}' neither listed nor timed")
    check("timing (wall seconds)" in out and "p2g" in out.split("timing")[-1],
          "timing table lists the MPM phases")


def mass_balance(hist, exact_counts=None):
    err = np.abs(hist["MASS_ERROR"]).max()
    m0 = hist["MASS"][0]
    check(err <= 1e-12 * m0, f"mass balance: max |M0 + Min - Mout - M| = {err:.3e} kg (M0 = {m0:.6g} kg)")


def paraview_check(base, n_particles):
    """With pvpython on PATH: ParaView opens BASE.xmf (particles) and BASE_grid.xmf (grid)."""
    import shutil
    pv = shutil.which("pvpython")
    if pv is None:
        print("      (pvpython not found: ParaView check skipped)")
        return
    script = f"""
from paraview.simple import XDMFReader, servermanager
for f in ['{base}.xmf', '{base}_grid.xmf']:
    r = XDMFReader(FileNames=[f])
    r.UpdatePipeline(r.TimestepValues[-1])
    d = servermanager.Fetch(r)
    pd = d.GetPointData()
    print('PV', f, d.GetNumberOfPoints(), sorted(pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays())))
"""
    r = subprocess.run([pv, "-c", script], capture_output=True, text=True, timeout=120)
    lines = [l.split(" ", 2) for l in r.stdout.splitlines() if l.startswith("PV ")]
    check(len(lines) == 2 and "Error" not in r.stdout + r.stderr, "ParaView reads the particle and grid XDMF files")
    check(int(lines[0][2].split(" ")[0]) == n_particles and "'S'" in lines[0][2] and "'V'" in lines[1][2],
          f"ParaView: {n_particles} particles with S and V, grid with V")


def column(args):
    base, out, hist = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["p2g", "g2p", "material", "walls", "gravity", "damping"], ["outflow", "inflow", "user field"])
    g = last_frame(base)
    x, s = g["coordinates"][:], g["S"][:]
    rho, grav, nu, height = 1600.0, 9.81, 0.2, 1.0
    k0 = nu / (1 - nu)
    y = x[:, 1]
    h = float(h5py.File(str(base) + ".h5", "r")["grid"].attrs["h"][0])
    layer = np.floor(y / h).astype(int)
    worst_k, worst_s, offset = 0.0, 0.0, 0.0
    for c in np.unique(layer):
        m = layer == c
        if y[m].max() > 0.8 * height:
            continue
        syy = s[m, 1].mean()
        expected = -rho * grav * (height - y[m]).mean()
        worst_s = max(worst_s, abs(syy / expected - 1))
        worst_k = max(worst_k, abs(s[m, 0].mean() / syy / k0 - 1), abs(s[m, 2].mean() / syy / k0 - 1))
        offset = max(offset, np.abs(s[m, 1] + rho * grav * (height - y[m])).max())
    print(f"      largest particle deviation from -rho g (H - y): {offset:.0f} Pa "
          f"(bottom stress {rho * grav * height:.0f} Pa)")
    check(worst_k < 0.02, f"K0: max |(sigma_h/sigma_v)/K0 - 1| = {worst_k:.2e} (K0 = {k0:.4f})")
    check(worst_s < 0.02, f"sigma_yy vs -rho g (H - y): max relative error {worst_s:.2e}")
    check(hist["ALLKE"][-1] < 1e-6 * max(hist["ALLIE"][-1], 1e-30), "column at rest (ALLKE << ALLIE)")
    # every wall is a mirrored symmetry plane, the floor folded after the side planes: its reaction
    # is the weight, and each plane's reaction is normal to it (main reported 2x and 6x the weight)
    weight = hist["MASS"][-1] * grav
    floor = -hist["WALLF2_FLOOR"][-1]
    check(abs(floor / weight - 1) < 1e-4, f"floor reaction {floor:.3f} N = weight {weight:.3f} N")
    for name in [n[len("WALLF1_"):] for n in hist.dtype.names if n.startswith("WALLF1_")]:
        f = np.array([hist[f"WALLF{i}_{name}"][-1] for i in (1, 2, 3)])
        check(np.sort(np.abs(f))[-2] <= 1e-9 * weight, f"wall {name}: reaction {f} normal to the plane")
    mass_balance(hist)
    paraview_check(base, len(x))


def slide_acceleration(hist, what, a=math.radians(30.0), mu=0.2, grav=9.81):
    """The centre of mass's acceleration down a 30 deg slope (+x, -y) from 0.1 s against
    g (sin a - mu cos a) within 2 %; returns it, the slide velocity and the rows used."""
    t = hist["time"]
    vs = hist["VCM1"] * math.cos(a) - hist["VCM2"] * math.sin(a)
    m = t >= 0.1
    acc = np.polyfit(t[m], vs[m], 1)[0]
    expected = grav * (math.sin(a) - mu * math.cos(a))
    err = acc / expected - 1
    check(abs(err) < 0.02, f"{what}: a = {acc:.5f} m/s2, g(sin a - mu cos a) = {expected:.5f}, error {err:+.2e}")
    return acc, vs, m


def incline(args):
    base, out, hist = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["walls", "gravity"], ["damping", "outflow", "inflow"])
    slide_acceleration(hist, "incline")
    mass_balance(hist)


def heap(args):
    base, out, hist = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["walls", "damping", "material"])
    phi = 30.0
    x = last_frame(base)["coordinates"][:]
    dx = 0.025
    bins = np.floor(x[:, 0] / dx).astype(int)
    xs = np.array([(b + 0.5) * dx for b in np.unique(bins)])
    ys = np.array([x[bins == b, 1].max() for b in np.unique(bins)])
    top = ys.max()
    m = (ys > 0.2 * top) & (ys < 0.8 * top)
    check(m.sum() >= 5, f"slope region has {m.sum()} columns")
    slope = math.degrees(math.atan(-np.polyfit(xs[m], ys[m], 1)[0]))
    check(abs(slope - phi) < 3.0, f"heap slope {slope:.2f} deg vs phi = {phi:g} deg (|diff| < 3 deg)")
    check(hist["ALLKE"][-1] < 1e-3 * hist["ALLWK"][-1], "heap at rest (ALLKE << ALLWK)")
    mass_balance(hist)


def mass(args):
    base, out, hist = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["outflow", "inflow", "walls", "user field"])
    mass_balance(hist)
    n0, n = int(hist["particles"][0]), int(hist["particles"][-1])
    import re
    mm = re.search(r"particles (\d+) \((\d+) in, (\d+) out\)", out)
    check(mm is not None, "summary line with particle counts")
    nend, nin, nout = (int(v) for v in mm.groups())
    check(nin > 0 and nout > 0, f"inflow ({nin} particles) and outflow ({nout} particles) both happened")
    check(n0 + nin - nout == nend == n, f"particle count: {n0} + {nin} - {nout} = {nend}")
    mp = hist["MASS"][0] / n0      # all particles of this scene have the same mass
    check(abs(hist["MASS_OUT"][-1] - nout * mp) <= 1e-12 * hist["MASS"][0], "MASS_OUT = n_out m_p")
    check(abs(hist["MASS_IN"][-1] - nin * mp) <= 1e-12 * hist["MASS"][0], "MASS_IN = n_in m_p")
    fill = hist["step"] == 1
    check(hist["MASS_OUT"][fill].max() == 0, "no outflow while the outlet is closed (step FILL)")
    # MDR integrates to the discharged mass
    dt = np.diff(hist["time"])
    integral = np.sum(hist["MDR"][1:] * dt)
    check(abs(integral - hist["MASS_OUT"][-1]) <= 1e-9 * hist["MASS"][0],
          f"integral of MDR = {integral:.6g} kg = MASS_OUT")


def mass_mu_of_i(args):
    mass(args)
    base = args.workdir / Path(args.scene).stem
    text = Path(args.scene).read_text()
    block = re.search(r"\*USER MATERIAL, CONSTANTS=(\d+)\n((?:[^*].*\n)+)", text)
    props = [float(v) for v in block.group(2).replace("\n", ",").split(",") if v.strip()]
    check(len(props) == int(block.group(1)) and props[-5] == 1, "the material has the mu(I) block")
    phi_s, phi2 = props[2], props[-4]
    f = h5py.File(str(base) + ".h5", "r")
    frames = sorted(f["particles"])
    raised = 0.0
    for k in frames[1:]:
        g = f["particles"][k]
        check(all(np.isfinite(g[name][()]).all() for name in ("S", "V", "SDV")), f"frame {k}: S, V, SDV finite")
        phi = g["SDV"][()][:, 6]
        check(phi.min() >= phi_s - 1e-9 and phi.max() <= phi2 + 1e-9,
              f"frame {k}: PHI in [{phi_s}, {phi2}] (got {phi.min():.6f} .. {phi.max():.6f})")
        raised = max(raised, float(np.median(phi)) - phi_s)
    check(raised > 0, f"the rate raised the median friction angle (by {raised:.3g} deg at most)")


def mirror(args):
    half_base, out, half = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["walls", "damping"])
    full_scene = str(Path(args.scene).with_name("mirror_full_2d.inp"))
    full_base, _, full = run(args.bulkflow, full_scene, args.workdir)

    def by_start(base):
        f = h5py.File(str(base) + ".h5", "r")
        frames = sorted(f["particles"].keys())
        first, last = f["particles"][frames[0]], f["particles"][frames[-1]]
        start = dict(zip(first["id"][:], np.round(first["coordinates"][:, :2], 9).tolist()))
        end = dict(zip(last["id"][:], last["coordinates"][:, :2].tolist()))
        return {tuple(start[i]): np.array(end[i]) for i in end}

    h, fl = by_start(half_base), by_start(full_base)
    twins = [(h[k], fl[k]) for k in h if k in fl]
    check(len(twins) == len(h) and 2 * len(h) == len(fl),
          f"{len(h)} half-model particles, each with a twin among the {len(fl)} of the full model")
    worst = max(np.abs(a - b).max() for a, b in twins)
    moved = max(np.abs(b - np.array(k)).max() for k, b in ((k, fl[k]) for k in h))
    check(moved > 0.05, f"the column collapses: the largest displacement is {moved:.3f} m")
    check(worst < 1e-6, f"half model follows the full model: max position difference {worst:.2e} m")
    for k in ["ALLKE", "ALLIE", "ALLWK", "ALLDMD"]:
        rel = abs(2 * half[k][-1] - full[k][-1]) / abs(full[k][-1])
        check(rel < 1e-6, f"{k}: 2 x half {2 * half[k][-1]:.6g} vs full {full[k][-1]:.6g} (rel {rel:.1e})")
    check(half["GUARDED"][-1] == 0, f"no particle put back onto the plane (GUARDED {half['GUARDED'][-1]:g})")
    mass_balance(half)


def mpi(args):
    import filecmp
    import os
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    args.workdir.mkdir(parents=True, exist_ok=True)
    hist = {}
    for tag, np_ in [("np1", 1), ("np2a", 2), ("np2b", 2)]:
        base = args.workdir / tag
        cmd = [args.bulkflow, args.scene, "--output", str(base), "--quiet"]
        if np_ > 1:
            cmd = [args.mpiexec, "-np", str(np_)] + cmd
        r = subprocess.run(cmd, capture_output=True, text=True, env=env)
        sys.stdout.write(r.stdout)
        sys.stderr.write(r.stderr)
        check(r.returncode == 0, f"{tag}: bulkflow on {np_} rank(s) exit status {r.returncode}")
        hist[tag] = np.genfromtxt(str(base) + "_history.csv", delimiter=",", names=True)
    check(filecmp.cmp(args.workdir / "np2a_history.csv", args.workdir / "np2b_history.csv", shallow=False),
          "two runs on 2 ranks give identical history files")
    a, b = hist["np1"], hist["np2a"]
    fill = a["step"] == 1
    worst = 0.0
    for k in ["ALLKE", "ALLIE", "XCM1", "XCM2", "VCM2", "WALLF1_WALL", "WALLF2_WALL"]:
        scale = np.abs(a[k][fill]).max()
        worst = max(worst, np.abs(a[k][fill] - b[k][fill]).max() / scale)
    check(worst < 1e-9, f"fill step: 2 ranks vs 1 rank, max relative difference {worst:.2e}")
    mass_balance(b)
    check(b["MASS_OUT"][-1] > 0 and b["MASS_IN"][-1] > 0, "outflow and inflow on 2 ranks")
    n_frame = int(h5py.File(str(args.workdir / "np2a") + ".h5", "r")["particles"][
        sorted(h5py.File(str(args.workdir / "np2a") + ".h5", "r")["particles"].keys())[-1]].attrs["count"][0])
    check(n_frame == int(b["particles"][-1]), f"last frame holds all {n_frame} particles (each rank writes its own rows)")


def mpi_env():
    import os
    return dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                OMPI_MCA_rmaps_base_oversubscribe="1")


def launch(args, scene, base, ranks, extra=()):
    """bulkflow on `ranks` ranks (1: without mpiexec); returns the CompletedProcess."""
    cmd = [args.bulkflow, str(scene), "--output", str(base), "--quiet", *extra]
    if ranks > 1:
        cmd = [args.mpiexec, "-np", str(ranks)] + cmd
    return subprocess.run(cmd, capture_output=True, text=True, env=mpi_env())


def checkpoint_header(path):
    """The header of a checkpoint file (output_checkpoint.f90): ranks, rank, step, increment, times."""
    import struct
    raw = Path(path).read_bytes()[:8 + 5 * 4 + 3 * 8 + 2 * 4]
    magic = raw[:8]
    version, nranks, rank, step, inc = struct.unpack("<5i", raw[8:28])
    step_time, total_time, dt = struct.unpack("<3d", raw[28:52])
    frames, rows = struct.unpack("<2i", raw[52:60])
    return dict(magic=magic, nranks=nranks, rank=rank, step=step, increment=inc, step_time=step_time,
                total_time=total_time, frames=frames, rows=rows)


def h5_items(path):
    """{name: (array or None for a group, {attribute: array})} of every object in the file."""
    items = {}
    with h5py.File(str(path), "r") as f:
        def visit(name, obj):
            data = obj[()] if isinstance(obj, h5py.Dataset) else None
            items[name] = (data, {k: np.asarray(v) for k, v in obj.attrs.items()})
        f.visititems(visit)
    return items


def same_h5(a, b):
    """Names of the objects (datasets, attributes) that differ between two HDF5 files."""
    ia, ib = h5_items(a), h5_items(b)
    bad = sorted(set(ia) ^ set(ib))
    for name in sorted(set(ia) & set(ib)):
        (da, aa), (db, ab) = ia[name], ib[name]
        if (da is None) != (db is None) or (da is not None and (da.dtype != db.dtype or da.shape != db.shape
                                                                or da.tobytes() != db.tobytes())):
            bad.append(name)
        if set(aa) != set(ab) or any(aa[k].tobytes() != ab[k].tobytes() for k in aa):
            bad.append(name + " (attributes)")
    return bad, len(ia)


def compare_runs(ref, other, what):
    bad, n = same_h5(str(ref) + ".h5", str(other) + ".h5")
    frames = len([k for k in h5_items(str(ref) + ".h5") if k.count("/") == 1 and k.startswith("particles/")])
    check(not bad, f"{what}: {frames} particle frames + grid frames, {n} HDF5 objects identical bit for bit"
          + (f" (differ: {', '.join(bad[:6])})" if bad else ""))
    for suffix in (".xmf", "_grid.xmf", "_history.csv"):
        ta, tb = Path(str(ref) + suffix).read_text(), Path(str(other) + suffix).read_text()
        # the XDMF files name their HDF5 file
        tb = tb.replace(Path(other).name + ".h5:", Path(ref).name + ".h5:")
        if suffix == "_history.csv" and ta != tb:
            ra, rb = ta.splitlines(), tb.splitlines()
            row = next((i for i, (x, y) in enumerate(zip(ra, rb)) if x != y), min(len(ra), len(rb)))
            print(f"      first difference in line {row + 1}: {len(ra)} vs {len(rb)} lines")
        check(ta == tb, f"{what}: {Path(str(ref) + suffix).name[len(Path(str(ref)).name):]} identical"
              + (f" ({len(ta.splitlines()) - 1} rows)" if suffix == "_history.csv" else ""))


def refused(r, what, needles):
    """A restart that must be refused: status 2, the reason, no backtrace, no MPI_Abort."""
    text = r.stdout + r.stderr
    msg = next((l for l in r.stderr.splitlines() if l.startswith("bulkflow: error:")), "")
    print(f"      {what}: exit {r.returncode}: {msg}")
    check(r.returncode == 2, f"{what}: refused with exit status 2")
    check(all(n in msg for n in needles) and "expected" in msg,
          f"{what}: the message names the file and the problem and says what was expected")
    check(r.stderr.count("bulkflow: error:") == 1, f"{what}: said once (rank 0)")
    check("Backtrace" not in text and "MPI_ABORT" not in text and "Error termination" not in text,
          f"{what}: no backtrace, no MPI_Abort")


def restart(args):
    import shutil
    n, k = args.ranks, args.stop_after
    wd = args.workdir
    if wd.exists():
        shutil.rmtree(wd)
    wd.mkdir(parents=True)
    scene = Path(args.scene).resolve()
    print(f"{scene.name}: restart after increment {k} on {n} rank(s)")

    full = wd / "full"
    r = launch(args, scene, full, n)
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    check(r.returncode == 0, f"uninterrupted run on {n} rank(s): exit status {r.returncode}")
    hist = np.genfromtxt(str(full) + "_history.csv", delimiter=",", names=True)
    last_inc = int(hist["increment"][-1])
    # The scene's last step writes a checkpoint every TIME INTERVAL (not at its end): the full
    # run leaves the one of the last multiple, as a run killed after it would.
    restart_lines = [l for l in scene.read_text().splitlines() if l.upper().startswith("*RESTART")]
    interval = float(restart_lines[-1].upper().split("TIME INTERVAL=")[1].split(",")[0])
    period = float(hist["step_time"][-1])
    mark = interval * math.floor(period / interval + 1e-9)
    hdr = [checkpoint_header(f"{full}.rst.{rank}") for rank in range(n)]
    check(all(h["magic"] == b"BFLOWRST" and h["nranks"] == n and h["step"] == int(hist["step"][-1])
              and 0 <= h["step_time"] - mark < 1e-3 and h["increment"] == hdr[0]["increment"] < last_inc
              for h in hdr),
          f"*RESTART, WRITE, TIME INTERVAL={interval:g} left a checkpoint per rank at step time "
          f"{hdr[0]['step_time']:.5f} (increment {hdr[0]['increment']} of {last_inc})")

    stopped = wd / "restarted"
    r = launch(args, scene, stopped, n, ["--stop-after", str(k)])
    check(r.returncode == 0 and f"stopped after increment {k}" in r.stdout,
          f"interrupted run stopped after increment {k}")
    h = checkpoint_header(f"{stopped}.rst.0")
    part = np.genfromtxt(str(stopped) + "_history.csv", delimiter=",", names=True)
    check(h["increment"] == k and h["step"] == 2, f"its checkpoint is at increment {k} in step {h['step']}")
    check(part["MASS_OUT"][-1] > 0 and part["MASS_IN"][-1] > 0,
          f"outflow ({part['MASS_OUT'][-1]:.4g} kg) and inflow ({part['MASS_IN'][-1]:.4g} kg) before the stop")
    saved = wd / "saved"
    for rank in range(n):
        shutil.copy(f"{stopped}.rst.{rank}", f"{saved}.rst.{rank}")
    for suffix in (".h5", "_history.csv"):
        shutil.copy(str(stopped) + suffix, str(saved) + suffix)

    r = launch(args, scene, stopped, n, ["--restart"])
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    check(r.returncode == 0 and f"restart   from increment {k}" in r.stdout,
          f"--restart continued from increment {k}: exit status {r.returncode}")
    compare_runs(full, stopped, "stopped + restarted vs uninterrupted")

    # A run killed after its last *RESTART checkpoint: its outputs hold frames and rows written
    # after it; the restart drops them and writes them again.
    crash = wd / "crashed"
    for suffix in [f".rst.{rank}" for rank in range(n)] + [".h5", "_history.csv"]:
        shutil.copy(str(full) + suffix, str(crash) + suffix)
    r = launch(args, scene, crash, n, ["--restart"])
    check(r.returncode == 0, f"--restart from the *RESTART checkpoint (outputs run past it): exit status {r.returncode}")
    compare_runs(full, crash, "restart from the *RESTART checkpoint vs uninterrupted")

    # Refused restarts.
    refused(launch(args, scene, wd / "none", n, ["--restart"]), "no checkpoint",
            [f"none.rst.0: cannot open the file"])
    changed = wd / "changed.inp"
    text = scene.read_text()
    check("*MPM CONTROLS, DAMPING=0." in text, "the scene has the discharge's damping to change")
    changed.write_text(text.replace("*MPM CONTROLS, DAMPING=0.", "*MPM CONTROLS, DAMPING=0.05"))
    for suffix in [f".rst.{rank}" for rank in range(n)] + [".h5", "_history.csv"]:
        shutil.copy(str(saved) + suffix, str(wd / "changed") + suffix)
    edited_line = next(i for i, l in enumerate(changed.read_text().splitlines(), 1) if "DAMPING=0.05" in l)
    refused(launch(args, changed, wd / "changed", n, ["--restart"]), "changed scene",
            [f"changed.inp:{edited_line}: differs from the scene the checkpoint was written for"])
    check(Path(str(wd / "changed") + "_history.csv").read_text() == Path(str(saved) + "_history.csv").read_text(),
          "changed scene: the outputs of the interrupted run are left untouched")
    other = 2 if n == 1 else 1
    refused(launch(args, scene, saved, other, ["--restart"]), f"restart on {other} rank(s) of a {n}-rank checkpoint",
            [f"saved.rst.", f"written by a run on {n} ranks, this run has {other}"])


def plate(args):
    base, out, hist = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["walls"], ["gravity", "damping", "outflow", "inflow"])
    e, nu, width, height, push, ramp = 1.0e7, 0.3, 0.2, 0.5, 0.0025, 0.1
    modulus = e * (1 - nu) / ((1 + nu) * (1 - 2 * nu))

    def smooth(t):   # *AMPLITUDE, DEFINITION=SMOOTH STEP from (0, 0) to (ramp, 1)
        xi = np.clip(t / ramp, 0.0, 1.0)
        return xi ** 3 * (10 - 15 * xi + 6 * xi ** 2)

    def force(t):
        return modulus * width * np.abs(np.log(1 - push * smooth(t) / height))

    t, f = hist["time"], hist["WALLF2_PLATE"]
    final = force(ramp)
    err = f[-1] / final - 1
    check(abs(err) < 0.02, f"plate reaction {f[-1]:.1f} N/m vs M W |ln(1 - u/H)| = {final:.1f} N/m, "
          f"error {err:+.2e}")
    worst = 0.0
    for k in range(1, len(t)):
        if t[k - 1] < 0.4 * ramp:
            continue
        ts = np.linspace(t[k - 1], t[k], 201)
        worst = max(worst, abs(f[k] - force(ts).mean()) / final)
    check(worst < 0.02, f"plate reaction along the push: max |F - M W |ln(1 - u/H)|| = {worst:.2e} of the final")
    floor = hist["WALLF2_FLOOR"][-1]
    check(abs(floor + f[-1]) < 1e-3 * f[-1], f"floor reaction {floor:.1f} N/m balances the plate's")
    k0 = nu / (1 - nu)
    side = k0 * f[-1] / width * height
    for w in ("LEFT", "RIGHT"):
        fs = abs(hist["WALLF1_" + w][-1])
        check(abs(fs / side - 1) < 0.01, f"side wall {w}: {fs:.1f} N/m vs K0 F H / W = {side:.1f} N/m")
    work = hist["ALLWK"][-1]
    check(abs(work - hist["ALLIE"][-1]) < 0.01 * work and abs(hist["ETOTAL"][-1]) < 0.01 * work,
          f"plate work ALLWK = {work:.4f} J/m, ALLIE = {hist['ALLIE'][-1]:.4f}, ETOTAL = {hist['ETOTAL'][-1]:.2e}")
    check(hist["GUARDED"][-1] == 0, "no particle put back behind a wall")
    mass_balance(hist)
    # stopped during the push (the reference node's displacement is in the checkpoint) and
    # restarted: the same history and frames bit for bit
    part = args.workdir / "restarted"
    for extra in (["--stop-after", "700"], ["--restart"]):
        r = subprocess.run([args.bulkflow, args.scene, "--output", str(part), "--quiet"] + extra,
                           capture_output=True, text=True)
        check(r.returncode == 0, f"run {' '.join(extra)} exits 0")
    same_rows = Path(f"{part}_history.csv").read_bytes() == Path(f"{base}_history.csv").read_bytes()
    bad, n = same_h5(f"{part}.h5", f"{base}.h5")
    check(same_rows and not bad, f"stopped at increment 700 and restarted: history and {n} HDF5 objects identical")


def bowl(args):
    base, out, hist = run(args.bulkflow, args.scene, args.workdir)
    check_report(out, ["walls", "gravity", "damping"], ["outflow", "inflow"])
    rho, grav, radius, ppc = 1600.0, 9.81, 0.5, 2
    weight = hist["MASS"][-1] * grav
    fy = hist["WALLF2_LEFT"][-1] + hist["WALLF2_RIGHT"][-1]
    check(abs(fy + weight) < 1e-3 * weight, f"the arcs carry the weight: {-fy:.2f} vs M g = {weight:.2f} N/m")
    g = last_frame(base)
    x, s = g["coordinates"][:], g["S"][:]
    h = float(h5py.File(str(base) + ".h5", "r")["grid"].attrs["h"][0])
    level = x[:, 1].max() + h / (2 * ppc)          # the free surface: top particles' upper edge
    thrust = rho * grav * level ** 2 / 2
    for w, sign in (("LEFT", -1), ("RIGHT", 1)):
        fx = sign * hist["WALLF1_" + w][-1]
        check(abs(fx / thrust - 1) < 0.03, f"arc {w}: horizontal thrust {fx:.2f} N/m vs rho g L^2/2 = "
              f"{thrust:.2f} (L = {level:.4f} m)")
    r = np.hypot(x[:, 0], x[:, 1] - radius)
    check(r.max() <= radius, f"no particle outside the circle: max r = {r.max():.5f} m (R = {radius})")
    # the material lies on the arcs, not on their chords (which pass up to R(1 - cos 40 deg) = 0.12 m
    # inside): in every 5 deg sector below the free surface the outermost particle is within one
    # particle spacing of the circle
    phi = np.degrees(np.arctan2(x[:, 0], radius - x[:, 1]))
    top = math.degrees(math.acos(1 - (level - h) / radius))
    gaps = [radius - r[(phi >= a) & (phi < a + 5)].max() for a in np.arange(-top, top - 5, 5.0)]
    check(max(gaps) < h / ppc, f"the material rests on the arcs: largest gap to the circle {max(gaps):.4f} m "
          f"in {len(gaps)} sectors (spacing {h / ppc} m)")
    check(hist["GUARDED"][-1] == 0, "no particle put back behind an arc")
    m = (np.abs(x[:, 0]) < 2 * h) & (x[:, 1] < 2 * h)
    pressure = -(s[m, 0] + s[m, 1] + s[m, 2]).mean() / 3
    expected = rho * grav * (level - x[m, 1].mean())
    check(abs(pressure / expected - 1) < 0.10, f"pressure at the bottom {pressure:.0f} Pa vs rho g depth = "
          f"{expected:.0f} Pa")
    check(hist["ALLKE"][-1] < 1e-4 * hist["ALLIE"][-1], "settled (ALLKE << ALLIE)")
    mass_balance(hist)


def sort(args):
    """*MPM CONTROLS, SORT=n (particles in cell order, particle-major P2G and remap) against the
    scene as it is (SORT=0): the same particles in and out, exact mass balance, history values
    and every particle's position and stress (matched by id) equal to round-off; a run stopped
    and restarted with SORT gives the uninterrupted run's history bit for bit."""
    args.workdir.mkdir(parents=True, exist_ok=True)
    text = Path(args.scene).read_text()
    check("SORT" not in text, "the reference scene has no SORT")
    sorted_scene = args.workdir / "sorted.inp"
    sorted_scene.write_text(re.sub(r"^(\*MPM CONTROLS, FLIP[^\n]*)$", r"\1, SORT=7", text, count=1, flags=re.M))
    base0, out0, h0 = run(args.bulkflow, args.scene, args.workdir / "block")
    base1, out1, h1 = run(args.bulkflow, str(sorted_scene), args.workdir / "cell")
    mass_balance(h1)
    for name in ("particles", "MASS_IN", "MASS_OUT", "GUARDED"):
        check(np.array_equal(h0[name], h1[name]), f"{name} the same in every row")
    for name in ("ALLKE", "ALLIE", "ALLWK", "XCM1", "XCM2", "VCM2", "YTOP", "WALLF1_WALL", "WALLF2_WALL", "MDR"):
        d = np.max(np.abs(h0[name] - h1[name])) / np.max(np.abs(h0[name]))
        check(d <= 1e-10, f"{name}: sorted vs block order {d:.1e} of its largest value (round-off)")
    f0, f1 = last_frame(base0), last_frame(base1)
    i0, i1 = np.argsort(f0["id"][()]), np.argsort(f1["id"][()])
    check(np.array_equal(f0["id"][()][i0], f1["id"][()][i1]), "the same particle ids in the last frame")
    dx = np.max(np.abs(f0["coordinates"][()][i0] - f1["coordinates"][()][i1]))
    check(dx <= 1e-10, f"positions by id within {dx:.1e} m")
    s0, s1 = f0["S"][()][i0], f1["S"][()][i1]
    ds = np.max(np.abs(s0 - s1)) / np.max(np.abs(s0))
    check(ds <= 1e-8, f"stresses by id within {ds:.1e} of the largest")
    # restart: the sort falls on the same increments as in the uninterrupted run
    stop = 137
    part = args.workdir / "part" / "sorted"
    part.parent.mkdir(parents=True, exist_ok=True)
    for extra in (["--stop-after", str(stop)], ["--restart"]):
        r = subprocess.run([args.bulkflow, str(sorted_scene), "--output", str(part), "--quiet"] + extra,
                           capture_output=True, text=True)
        check(r.returncode == 0, f"run with {' '.join(extra)} exits 0")
    same = Path(f"{part}_history.csv").read_bytes() == Path(f"{base1}_history.csv").read_bytes()
    check(same, f"stopped after {stop} and restarted: history identical to the uninterrupted sorted run")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("kind", choices=["column", "incline", "heap", "mirror", "mass", "mass_mu_of_i", "mpi", "restart", "plate", "bowl",
                                       "sort"])
    p.add_argument("--mpiexec", default="mpirun")
    p.add_argument("--ranks", type=int, default=1, help="restart: number of ranks")
    p.add_argument("--stop-after", type=int, default=0, help="restart: increment to stop after")
    p.add_argument("scene")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True, type=Path)
    args = p.parse_args()
    globals()[args.kind](args)
    print("PASS")


if __name__ == "__main__":
    main()
