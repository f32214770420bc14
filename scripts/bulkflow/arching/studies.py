"""bulkflow-arching-study: the studies of thesis ch. 6 as one command each, writing CSV and PNG.

    bulkflow-arching-study height      [--quick]   # COW vs material height, Case A and B (Fig. 6.2, 6.8), + Enstad arch
    bulkflow-arching-study parametric  [--quick]   # θ, φw, φ, k around Case A at 2 m (Fig. 6.9)
    bulkflow-arching-study mesh        [--quick]   # elements along the outlet vs COW and wall time (Fig. 6.4)
    bulkflow-arching-study convergence [--n-arcs 16,30,60]  # COW vs mesh, physical vs half-element FLOW rule
    bulkflow-arching-study meshdiag [--variants assoc,davis]  # why the COW drifts with the mesh (issue 21)
    bulkflow-arching-study elastic     [--quick]   # E and ν (Fig. 6.6)
    bulkflow-arching-study stress      [--quick]   # principal stresses along the wall vs Enstad (Fig. 6.7)
    bulkflow-arching-study powders     [--quick]   # Eckhoff & Leversen powders, both c0 readings, linear/bilinear (Table 6.3)
    bulkflow-arching-study benchmark               # full polymer bisection to 2 mm, both readings, wall time
    bulkflow-arching-study cost                    # accuracy cost of mass scaling and of the early stop

Every COW point is a `bulkflow.arching.cow.find_cow` search (coarse bracket, bisection on the
target mesh). `--quick` uses a coarser target mesh and a looser tolerance (the figures then say
so); `--out DIR` (default out/arching/<study>) receives `<study>.csv`, `<study>.png`, a JSON
with every trial and the solver logs. `--np` ranks per run (default 2).
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from .cow import Search, find_cow, refine, table, theory_estimates
from .runner import run_scene
from .scene import CRITERIA, ArchingScene, enstad_beta, scene_from_case


#: FLOW criterion of every study but `convergence` (None: the scene generator's default); --criterion
CRITERION: str | None = None


def case_scene(case: str, reading: str = "c0", **kw) -> ArchingScene:
    if CRITERION is not None:
        kw.setdefault("criterion", CRITERION)
    return scene_from_case(case, reading, **kw)


def _settings(quick: bool) -> dict:
    return dict(n_arc=16, tol=0.004, coarse_n_arc=8) if quick else dict(n_arc=30, tol=0.002, coarse_n_arc=12)


class Study:
    """Collects COW points into rows, a CSV and a JSON."""

    fields = ["study", "case", "reading", "variable", "value", "height", "arch", "state", "flow", "n_arc", "tol",
              "mclean", "jenike", "enstad", "fem_no_flow", "fem_flow", "runs", "solver_wall", "wall"]

    def __init__(self, name: str, out: Path, np_: int):
        self.name, self.out, self.np = name, out, np_
        self.rows: list[dict] = []
        self.results: list[dict] = []
        out.mkdir(parents=True, exist_ok=True)

    def point(self, scene: ArchingScene, *, case: str, reading: str, variable: str, value, tol: float,
              coarse_n_arc: int, bracket=None) -> dict:
        tag = f"{case}_{reading}_{variable}_{value}".replace(".", "p").replace(" ", "")
        res = find_cow(scene, self.out / "runs" / tag, np=self.np, tol=tol, coarse_n_arc=coarse_n_arc,
                       bracket=bracket, log=lambda m: print(m, flush=True))
        print(table(res, f"{self.name}: case {case} ({reading}), {variable} = {value}"), flush=True)
        lo, hi = res["interval"]
        th = res["theory"]
        row = dict(study=self.name, case=case, reading=reading, variable=variable, value=value,
                   height=scene.height, arch=scene.arch, state=scene.state, flow=scene.flow, n_arc=scene.n_arc,
                   tol=tol, mclean=th["mclean"], jenike=th["jenike"], enstad=th["enstad"],
                   fem_no_flow=lo, fem_flow=hi, runs=res["n_runs"], solver_wall=round(res["solver_wall"], 1),
                   wall=round(res["wall"], 1))
        self.rows.append(row)
        res["row"] = row
        self.results.append(res)
        self.save()
        return row

    def save(self) -> None:
        with open(self.out / f"{self.name}.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=self.fields)
            w.writeheader()
            for r in self.rows:
                w.writerow(r)
        (self.out / f"{self.name}.json").write_text(json.dumps(self.results, default=str, indent=1))


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _cm(x):
    return np.nan if x is None or not math.isfinite(float(x)) else 100.0 * float(x)


def _plot_points(ax, rows, x_key="value", label="FEM", colour="k", marker="o"):
    xs = [float(r[x_key]) for r in rows]
    lo = [_cm(r["fem_no_flow"]) for r in rows]
    hi = [_cm(r["fem_flow"]) for r in rows]
    mid = [np.nanmean([a, b]) for a, b in zip(lo, hi)]
    err = [[m - a if math.isfinite(a) else 0 for m, a in zip(mid, lo)],
           [b - m if math.isfinite(b) else 0 for m, b in zip(mid, hi)]]
    ax.errorbar(xs, mid, yerr=err, fmt=marker, color=colour, capsize=3, label=label)


def _theory_curves(ax, xs, rows):
    for key, c in (("jenike", "g"), ("enstad", "r"), ("mclean", "k")):
        ax.plot(xs, [_cm(r[key]) for r in rows], "-", color=c, lw=1, label=key.capitalize())


# ---- studies ------------------------------------------------------------------------------------
def study_height(a) -> Study:
    st = Study("height", a.out, a.np)
    s = _settings(a.quick)
    heights = [1.0, 2.0, 3.0]
    for case in ("A", "B"):
        for h in heights:
            sc = case_scene(case, "c0", height=h, n_arc=s["n_arc"])
            st.point(sc, case=case, reading="c0", variable="height", value=h, tol=s["tol"],
                     coarse_n_arc=s["coarse_n_arc"])
        if case == "A" and not a.quick_skip_enstad:
            for h in ([2.0] if a.quick else heights):
                d = case_scene(case, "c0", height=h)
                beta = enstad_beta(dict(rho=d.density, phi=d.phi, phi_w=d.phi_w, k=d.k, fc0=d.fc0, theta=d.theta,
                                        height=h))
                sc = replace(d, arch="enstad", beta=beta, n_arc=s["n_arc"])
                st.point(sc, case=case, reading="c0", variable="height_enstad_arch", value=h, tol=s["tol"],
                         coarse_n_arc=s["coarse_n_arc"])
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, case in zip(axes, ("A", "B")):
        rows = [r for r in st.rows if r["case"] == case and r["variable"] == "height"]
        hs = np.linspace(0.6, 3.2, 27)
        th = [theory_estimates(case_scene(case, "c0", height=h)) for h in hs]
        for key, c in (("jenike", "g"), ("enstad", "r"), ("mclean", "k")):
            ax.plot(hs, [_cm(t[key]) for t in th], "-", color=c, lw=1, label=key.capitalize())
        _plot_points(ax, rows, label="FEM, arch centred at the apex")
        er = [r for r in st.rows if r["case"] == case and r["variable"] == "height_enstad_arch"]
        if er:
            _plot_points(ax, er, label="FEM, Enstad's arch", colour="b", marker="s")
        ax.set_title(f"Case {case}")
        ax.set_xlabel("material height above the apex H (m)")
        ax.set_ylabel("critical outlet width (cm)")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out / "height.png", dpi=120)
    return st


def study_parametric(a) -> Study:
    st = Study("parametric", a.out, a.np)
    s = _settings(a.quick)
    sweeps = {"theta": [15.0, 30.0, 45.0], "phi_w": [10.0, 20.0, 30.0], "phi": [30.0, 40.0, 50.0],
              "k": [0.0, 0.2, 0.4]}
    if a.quick:
        sweeps = {k: [v[0], v[-1]] for k, v in sweeps.items()}
    base = case_scene("A", "c0", height=2.0, n_arc=s["n_arc"])
    from .scene import fc0_from_c0
    for var, values in sweeps.items():
        for v in values:
            kw = {var: v}
            if var == "phi":                     # c0 fixed, fc0 follows φ (eq. 6.9)
                kw["fc0"] = fc0_from_c0(350.0, v)
            sc = replace(base, **kw)
            st.point(sc, case="A", reading="c0", variable=var, value=v, tol=s["tol"], coarse_n_arc=s["coarse_n_arc"])
    plt = _plt()
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    for ax, var in zip(axes.ravel(), sweeps):
        rows = [r for r in st.rows if r["variable"] == var]
        _theory_curves(ax, [float(r["value"]) for r in rows], rows)
        _plot_points(ax, rows)
        ax.set_xlabel(var)
        ax.set_ylabel("critical outlet width (cm)")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out / "parametric.png", dpi=120)
    return st


def study_mesh(a) -> Study:
    """Elements along the outlet vs the COW and its cost (Case B; 1 m unless --height)."""
    st = Study("mesh", a.out, a.np)
    ns = [10, 20, 30] if a.quick else [10, 20, 30, 60]
    h = a.height or 1.0
    for n in ns:
        sc = case_scene("B", "c0", height=h, n_arc=n)
        st.point(sc, case="B", reading="c0", variable="n_arc", value=n, tol=0.002,
                 coarse_n_arc=10 if n > 10 else 0)
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    _plot_points(ax[0], st.rows)
    ax[0].axhline(_cm(st.rows[0]["enstad"]), color="r", lw=1, label="Enstad")
    ax[0].set_xlabel("elements along the outlet arc")
    ax[0].set_ylabel("critical outlet width (cm)")
    ax[0].legend(fontsize=7)
    ax[1].plot([r["value"] for r in st.rows], [r["wall"] for r in st.rows], "o-")
    ax[1].set_xlabel("elements along the outlet arc")
    ax[1].set_ylabel("wall time of the search (s)")
    fig.tight_layout()
    fig.savefig(a.out / "mesh.png", dpi=120)
    return st


def study_elastic(a) -> Study:
    st = Study("elastic", a.out, a.np)
    s = _settings(a.quick)
    base = case_scene("A", "c0", height=2.0, n_arc=s["n_arc"])
    sweeps = {"young": [5e6, 10e6, 40e6], "poisson": [0.1, 0.2, 0.3]}
    if a.quick:
        sweeps = {k: [v[0], v[-1]] for k, v in sweeps.items()}
    for var, values in sweeps.items():
        for v in values:
            st.point(replace(base, **{var: v}), case="A", reading="c0", variable=var, value=v, tol=s["tol"],
                     coarse_n_arc=s["coarse_n_arc"])
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, var in zip(axes, sweeps):
        _plot_points(ax, [r for r in st.rows if r["variable"] == var])
        ax.set_xlabel(var)
        ax.set_ylabel("FEM flow/no-flow interval (cm)")
        if var == "young":
            ax.set_xscale("log")
    fig.tight_layout()
    fig.savefig(a.out / "elastic.png", dpi=120)
    return st


def study_powders(a) -> Study:
    st = Study("powders", a.out, a.np)
    s = _settings(a.quick)
    for case in ("polymer", "sic"):
        for reading in ("c0", "fc0"):
            for flow in (("linear",) if case == "polymer" else ("linear", "bilinear")):
                h = a.height or (3.0 if (case == "polymer" and reading == "c0") else 1.0)
                sc = case_scene(case, reading, height=h, n_arc=s["n_arc"], flow=flow)
                st.point(sc, case=case, reading=reading, variable="flow", value=flow, tol=s["tol"],
                         coarse_n_arc=s["coarse_n_arc"])
    with open(a.out / "powders_table.txt", "w") as f:
        f.write("Eckhoff & Leversen powders (thesis Tables 6.2, 6.3): B_crit (cm)\n")
        f.write(f"{'case':8s} {'reading':7s} {'flow':9s} {'H (m)':>5s} {'McLean':>7s} {'Jenike':>7s} {'Enstad':>7s}"
                f" {'FEM no-flow':>11s} {'FEM flow':>9s}\n")
        for r in st.rows:
            f.write(f"{r['case']:8s} {r['reading']:7s} {r['value']:9s} {r['height']:5.2f} {_cm(r['mclean']):7.1f} "
                    f"{_cm(r['jenike']):7.1f} {_cm(r['enstad']):7.1f} {_cm(r['fem_no_flow']):11.2f} "
                    f"{_cm(r['fem_flow']):9.2f}\n")
        f.write("thesis Table 6.3 theory values: polymer 35 / 28 / 30, SiC 12 / 10.2 / 10.4 "
                "(experiment and FEM held back)\n")
    print((a.out / "powders_table.txt").read_text())
    return st


def study_benchmark(a) -> Study:
    """Full polymer bisection to 2 mm under both readings: wall time of each (acceptance < 5 min)."""
    st = Study("benchmark", a.out, a.np)
    for reading in ("fc0", "c0"):
        h = a.height or (3.0 if reading == "c0" else 1.0)
        sc = case_scene("polymer", reading, height=h, n_arc=30)
        t0 = time.perf_counter()
        st.point(sc, case="polymer", reading=reading, variable="benchmark", value=h, tol=0.002, coarse_n_arc=12)
        print(f"polymer, reading {reading}, H = {h} m: search wall time {time.perf_counter() - t0:.1f} s", flush=True)
    return st


def study_cost(a) -> Study:
    """What mass scaling and the early stop cost in accuracy, at the two ends of a COW interval.

    --bracket lo,hi: the interval found with the defaults (mass scaling 4, early stop) on the
    target mesh (Case B at 2 m unless --height). Both ends are re-run (1) without mass scaling,
    (2) with stronger mass scaling (10), (3) without the early stop (the opening step runs for
    --t-open; the decision then uses the same rules on the whole step). An end whose outcome
    changes means the interval moved by at least the interval width.
    """
    st = Study("cost", a.out, a.np)
    s = _settings(a.quick)
    h = a.height or 2.0
    if not a.bracket:
        raise SystemExit("cost: give --bracket lo,hi (a COW interval found with the defaults)")
    ends = [float(v) for v in a.bracket.split(",")]
    variants = [("baseline", dict()), ("no mass scaling", dict(mass_scaling_dt_factor=1.0)),
                ("mass scaling 10", dict(mass_scaling_dt_factor=10.0)),
                ("no early stop", dict(t_open=a.t_open, ke_fraction=1e-9, growth=0.0,
                                       hold=a.t_open - 0.05))]
    rows = []
    for name, kw in variants:
        for w in ends:
            sc = case_scene("B", "c0", height=h, n_arc=s["n_arc"], outlet_width=w, field_frames=0, **kw)
            tag = name.replace(" ", "_")
            try:
                rec = run_scene(sc, a.out / "runs" / tag, np=a.np, log=print)
                row = dict(variant=name, width=w, outcome=rec.outcome, umax=rec.decision["umax"],
                           limit=rec.decision["limit"], t_end=rec.decision["t_end"], wall=round(rec.wall, 1),
                           cpu=round(rec.cpu, 1), increments=rec.increments, element_steps=rec.element_steps)
            except RuntimeError as e:            # e.g. a flowing run crushing an element late in a full step
                row = dict(variant=name, width=w, outcome="FAILED (" + str(e).splitlines()[-1][:80] + ")",
                           umax=None, limit=None, t_end=None, wall=None, cpu=None, increments=None,
                           element_steps=None)
            rows.append(row)
            print(row, flush=True)
    with open(a.out / "cost.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with open(a.out / "cost_table.txt", "w") as f:
        f.write(f"Case B, H = {h} m, n_arc {s['n_arc']}: the ends of the interval {ends[0] * 100:.2f} .. "
                f"{ends[1] * 100:.2f} cm re-run\n")
        f.write(f"{'variant':18s} {'B (cm)':>7s} {'outcome':>9s} {'umax (mm)':>9s} {'t_end (s)':>9s} "
                f"{'increments':>10s} {'cpu (s)':>8s} {'wall (s)':>8s}\n")
        for r in rows:
            f.write(f"{r['variant']:18s} {r['width'] * 100:7.2f} {r['outcome']:>9s} "
                    f"{(r['umax'] or 0) * 1e3:9.3f} {(r['t_end'] or 0):9.3f} {(r['increments'] or 0):10d} "
                    f"{(r['cpu'] or 0):8.1f} {(r['wall'] or 0):8.1f}\n")
    print((a.out / "cost_table.txt").read_text())
    return st


def study_stress(a) -> Study:
    """Principal stresses along the wall at the opening vs Enstad's arching stresses (Case B, 2 m)."""
    import h5py
    from bulkflow.theory import Material
    from bulkflow.theory.enstad import arching_solution

    st = Study("stress", a.out, a.np)
    h = a.height or 2.0
    n = 16 if a.quick else 30
    width = a.width or 0.26
    sc = case_scene("B", "c0", height=h, n_arc=n, outlet_width=width, field_frames=20)
    rec = run_scene(sc, a.out / "runs", np=a.np, log=print, name="stress_run")
    with h5py.File(rec.base + ".h5", "r") as f:
        names = sorted(f["frames"].keys())
        pick = None
        for nm in names:
            g = f["frames"][nm]
            if int(g.attrs["step"]) == 3 and float(g.attrs["step_time"]) > 0:
                pick = nm
                break
        pick = pick or names[-1]
        S = f["frames"][pick]["S"][:]
        x0 = f["mesh"]["coordinates"][:]
        conn = f["mesh"]["connectivity"][:]
        t_pick = float(f["frames"][pick].attrs["step_time"])
    nodes, elems, sets = sc.mesh()                 # element k of the mesh is row k of /mesh (ids 1..m)
    wall = sets["e_wall"]
    cen = x0[conn[wall]][:, :, :2].mean(axis=1)
    r = np.hypot(cen[:, 0], cen[:, 1])
    s11, s22, s12 = -S[wall, 0], -S[wall, 1], -S[wall, 3]            # compression positive
    c = 0.5 * (s11 + s22)
    rad = np.sqrt((0.5 * (s11 - s22)) ** 2 + s12 ** 2)
    s1, s2 = c + rad, c - rad
    m = Material(rho=sc.density, phi_deg=sc.phi, phi_w_deg=sc.phi_w, k=sc.k, fc0=sc.fc0)
    R = h / math.cos(math.radians(sc.theta))
    sol = arching_solution(sc.theta, sc.phi, m.delta_mod_deg, 0.0, 0.0, sc.k, sc.fc0, sc.density, R)
    rr = np.linspace(sc.r_out, R, 200)
    kphi = (1 + math.sin(math.radians(sc.phi))) / (1 - math.sin(math.radians(sc.phi)))
    sig2 = np.array([sol(x) for x in rr])
    sig1 = kphi * sig2 + sc.fc0                    # Case B: k = 0, fc = fc0 everywhere
    with open(a.out / "stress.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["r_wall_m", "sigma1_fem_Pa", "sigma2_fem_Pa"])
        for row in zip(r, s1, s2):
            w.writerow([f"{v:.6g}" for v in row])
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(r, s1 / 1e3, "r.", label="FEM sigma1 (wall elements)")
    ax.plot(r, s2 / 1e3, "b.", label="FEM sigma2")
    ax.plot(rr, sig1 / 1e3, "r-", label="Enstad sigma1")
    ax.plot(rr, sig2 / 1e3, "b-", label="Enstad sigma2")
    ax.set_xlabel("distance from the apex along the wall (m)")
    ax.set_ylabel("principal stress, compression positive (kPa)")
    ax.set_title(f"Case B, H = {h} m, B = {width * 100:.1f} cm, {rec.outcome}, step time {t_pick:.3g} s after opening")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out / "stress.png", dpi=120)
    print(f"stress profile: {a.out / 'stress.png'}, {a.out / 'stress.csv'} ({rec.outcome})")
    return st


def study_convergence(a) -> Study:
    """The COW on refined meshes under each FLOW criterion (issue 21): Case B (1 m unless --height)
    and the polymer (fc0 reading, 1 m). Per case and criterion one search runs from the coarsest
    mesh up: bracket and bisect on the first mesh, then on each finer mesh check the previous
    interval widened by --margin on both sides (widened further while it does not bracket) and
    bisect to 2 mm. One CSV row per (case, criterion, mesh): the interval, the runs on that mesh
    and their wall time."""
    st = Study("convergence", a.out, a.np)
    ns = [int(v) for v in a.n_arcs.split(",")]
    crits = a.criteria.split(",") if a.criteria else list(CRITERIA)
    cases = [c for c in (("B", "c0", a.height or 1.0), ("polymer", "fc0", 1.0)) if c[0] in a.cases.split(",")]
    rows = []
    for case, reading, h in cases:
        for crit in crits:
            sc = scene_from_case(case, reading, height=h, n_arc=ns[0], criterion=crit, field_frames=0)
            tag = f"{case}_{reading}_{crit}"
            srch = Search(sc, a.out / "runs" / tag, a.np, lambda m: print(m, flush=True))
            est = theory_estimates(sc)
            start = next((est[k] for k in ("enstad", "jenike", "mclean") if est[k] and math.isfinite(est[k])), 0.2)
            lo = hi = None
            for n in ns:
                print(f"convergence: case {case} ({reading}), criterion {crit}, n_arc {n}", flush=True)
                k0 = len(srch.runs)
                if lo is not None and hi is not None:
                    lo, hi = lo - a.margin, hi + a.margin
                    lo, hi = refine(srch, lo, hi, n, 0.002, 0.5 * (lo + hi))
                else:
                    lo, hi = srch.bracket(min(start, 0.9 * srch.max_width()), n)
                    if lo is not None and hi is not None:
                        lo, hi = srch.bisect(lo, hi, n, 0.002)
                runs = srch.runs[k0:]
                walls = [r.wall for r in runs]
                rows.append(dict(case=case, reading=reading, height=h, criterion=crit, n_arc=n,
                                 n_elements=replace(sc, n_arc=n, outlet_width=lo or hi or start).n_elements(),
                                 fem_no_flow=lo, fem_flow=hi, runs=len(runs), wall=sum(walls),
                                 wall_per_run=sum(walls) / max(len(walls), 1), wall_max=max(walls, default=0.0),
                                 cpu_per_run=sum(x.cpu for x in runs) / max(len(runs), 1),
                                 enstad=est["enstad"]))
                r = rows[-1]
                print(f"  -> {_cm(lo):.2f} .. {_cm(hi):.2f} cm, {len(runs)} runs, {r['wall']:.0f} s "
                      f"({r['wall_per_run']:.1f} s per run)", flush=True)
                _save_convergence(a.out, rows)
            st.results.append(dict(case=case, reading=reading, criterion=crit,
                                   runs=[x.as_dict() for x in srch.runs]))
    _save_convergence(a.out, rows)
    (a.out / "convergence.json").write_text(json.dumps(dict(rows=rows, searches=st.results), default=str))
    plt = _plt()
    fig, axs = plt.subplots(1, len(cases), figsize=(5 * len(cases), 4), squeeze=False)
    for ax, (case, reading, h) in zip(axs[0], cases):
        for crit, c in zip(crits, ("tab:blue", "tab:red")):
            rr = [r for r in rows if r["case"] == case and r["criterion"] == crit and r["fem_no_flow"]
                  and r["fem_flow"]]
            x = [r["n_arc"] for r in rr]
            ax.fill_between(x, [_cm(r["fem_no_flow"]) for r in rr], [_cm(r["fem_flow"]) for r in rr],
                            color=c, alpha=0.4)
            ax.plot(x, [0.5 * (_cm(r["fem_no_flow"]) + _cm(r["fem_flow"])) for r in rr], "o-", color=c, label=crit)
        ax.set_xscale("log")
        ax.set_xlabel("elements along the outlet arc")
        ax.set_ylabel("critical outlet width (cm)")
        ax.set_title(f"{case} ({reading}), H = {h:g} m")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out / "convergence.png", dpi=120)
    print(convergence_table(rows))
    return st


def _save_rows(out: Path, name: str, rows: list[dict], table) -> None:
    """OUT/NAME.csv (one row per dict) and OUT/NAME_table.txt (table(rows), markdown)."""
    with open(out / f"{name}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    (out / f"{name}_table.txt").write_text(table(rows) + "\n")


def _save_convergence(out: Path, rows: list[dict]) -> None:
    _save_rows(out, "convergence", rows, convergence_table)


def convergence_table(rows: list[dict]) -> str:
    """Markdown table: per case and mesh, the interval under each criterion and its cost."""
    lines = ["| case | n_arc | criterion | COW no flow .. flow (cm) | shift from the previous mesh (mm) | runs | wall (s) "
             "| wall per run (s) | CPU per run (s, all ranks) |",
             "|---|---|---|---|---|---|---|---|---|"]
    prev = {}
    for r in rows:
        key = (r["case"], r["criterion"])
        mid = (0.5 * (r["fem_no_flow"] + r["fem_flow"]) if r["fem_no_flow"] and r["fem_flow"] else None)
        shift = f"{(mid - prev[key]) * 1000:+.1f}" if mid is not None and prev.get(key) is not None else "—"
        prev[key] = mid
        lines.append(f"| {r['case']} ({r['reading']}, {r['height']:g} m) | {r['n_arc']} | {r['criterion']} | "
                     f"{_cm(r['fem_no_flow']):.2f} .. {_cm(r['fem_flow']):.2f} | {shift} | {r['runs']} | "
                     f"{r['wall']:.0f} | {r['wall_per_run']:.1f} | {float(r.get('cpu_per_run', 'nan')):.1f} |")
    return "\n".join(lines)

#: meshdiag: the variants of the mesh-dependence diagnosis (issue 21 point 1), each removing or
#: changing one candidate cause of the drift of the COW with the mesh (README "Mesh dependence:
#: diagnosis"); scene fields overridden on top of Case B. "assoc" sets ψ = φ of the case.
MESHDIAG_VARIANTS = {
    "baseline": {},
    "ms1": dict(mass_scaling_dt_factor=1.0),              # (c) no mass scaling in steps 1-2
    "assoc": dict(psi="phi"),                             # (b) associated flow, ψ = φ
    "psi10": dict(psi=10.0),                              # (b) half way: ψ = 10°
    "davis": dict(flow_rule="davis"),                     # (b) Davis's associated material of equal strength
    "davis-smooth": dict(flow_rule="davis", phi_w=0.0),   # (a) and (b): Davis's material, frictionless wall (no wall corner friction)
    "nobv": dict(bulk_viscosity=(0.0, 0.0)),              # bulk viscosity (∝ element size) off
    "hgstiff": dict(hourglass="stiffness"),               # (e) stiffness instead of viscous hourglass control
    "hg10": dict(hourglass_scale=10.0),                   # (e) viscous hourglass control x 10
    "hold": dict(hold=0.15, min_open_time=0.15),          # (f) ARREST windows 3 x longer
}


def mesh_sequence(srch: Search, ns: list[int], start: float, margin: float, tol: float, log=print) -> list[dict]:
    """The COW on each mesh of `ns` (coarsest first): bracket from `start` by factors of 1.3 and
    bisect on the first mesh; on each finer one refine the previous interval widened by `margin`.
    One dict per mesh: interval, runs on that mesh, their wall and CPU time."""
    rows, lo, hi = [], None, None
    for n in ns:
        k0 = len(srch.runs)
        if lo is not None and hi is not None:
            lo, hi = refine(srch, lo - margin, hi + margin, n, tol, 0.5 * (lo + hi))
        else:
            lo, hi = srch.bracket(min(start, 0.9 * srch.max_width()), n)
            if lo is not None and hi is not None:
                lo, hi = srch.bisect(lo, hi, n, tol)
        runs = srch.runs[k0:]
        rows.append(dict(n_arc=n, fem_no_flow=lo, fem_flow=hi, runs=len(runs), wall=sum(r.wall for r in runs),
                         cpu=sum(r.cpu for r in runs)))
        log(f"  -> n_arc {n}: {_cm(lo):.2f} .. {_cm(hi):.2f} cm, {len(runs)} runs, {rows[-1]['wall']:.0f} s")
    return rows


def study_meshdiag(a) -> Study:
    """Mesh-dependence diagnosis (issue 21 point 1): the COW of Case B (--cases B, c0 reading) or the
    polymer (--cases polymer, fc0 reading), 1 m unless --height, on the meshes of --n-arcs for each
    variant of --variants (MESHDIAG_VARIANTS), to --tol-mm. Writes meshdiag.csv,
    meshdiag_table.txt and meshdiag.json (every trial)."""
    st = Study("meshdiag", a.out, a.np)
    ns = [int(v) for v in a.n_arcs.split(",")]
    h = a.height or 1.0
    case = a.cases if a.cases in ("B", "polymer") else "B"
    reading = "fc0" if case == "polymer" else "c0"
    names = a.variants.split(",") if a.variants else list(MESHDIAG_VARIANTS)
    rows = []
    for name in names:
        over = dict(MESHDIAG_VARIANTS[name])
        sc = scene_from_case(case, reading, height=h, n_arc=ns[0], field_frames=0)
        if over.get("psi") == "phi":
            over["psi"] = sc.phi
        sc = replace(sc, **over)
        print(f"meshdiag: variant {name} {over}", flush=True)
        srch = Search(sc, a.out / "runs" / name, a.np, lambda m: print(m, flush=True))
        for r in mesh_sequence(srch, ns, a.start, a.margin, a.tol_mm * 1e-3):
            rows.append(dict(variant=name, case=case, overrides=json.dumps(over), height=h, **r))
        st.results.append(dict(variant=name, overrides=over, runs=[x.as_dict() for x in srch.runs]))
        _save_meshdiag(a.out, rows)
        (a.out / "meshdiag.json").write_text(json.dumps(dict(rows=rows, searches=st.results), default=str))
    print(meshdiag_table(rows))
    return st


def _save_meshdiag(out: Path, rows: list[dict]) -> None:
    _save_rows(out, "meshdiag", rows, meshdiag_table)


def meshdiag_table(rows: list[dict]) -> str:
    """Markdown table: per variant and mesh, the interval, the shift from the previous mesh, the cost."""
    lines = ["| variant | n_arc | COW no flow .. flow (cm) | shift from the previous mesh (mm) | runs | wall (s) |",
             "|---|---|---|---|---|---|"]
    prev = {}
    for r in rows:
        lo, hi = r["fem_no_flow"], r["fem_flow"]
        mid = 0.5 * (lo + hi) if lo and hi else None
        shift = f"{(mid - prev[r['variant']]) * 1000:+.1f}" if mid is not None and prev.get(r["variant"]) else "—"
        prev[r["variant"]] = mid
        lines.append(f"| {r['variant']} | {r['n_arc']} | {_cm(lo):.2f} .. {_cm(hi):.2f} | {shift} | {r['runs']} | "
                     f"{r['wall']:.0f} |")
    return "\n".join(lines)


STUDIES = dict(height=study_height, parametric=study_parametric, mesh=study_mesh, elastic=study_elastic,
               stress=study_stress, powders=study_powders, benchmark=study_benchmark, cost=study_cost,
               convergence=study_convergence, meshdiag=study_meshdiag)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="bulkflow-arching-study", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("study", choices=sorted(STUDIES))
    p.add_argument("--quick", action="store_true", help="coarser target mesh and looser tolerance")
    p.add_argument("--out", default=None, help="output directory (default out/arching/<study>)")
    p.add_argument("--np", type=int, default=2)
    p.add_argument("--height", type=float, default=None, help="override the study's material height (m)")
    p.add_argument("--width", type=float, default=None, help="stress: the outlet width (m)")
    p.add_argument("--bracket", default="", help="cost: lo,hi (m) to skip the coarse bracket")
    p.add_argument("--t-open", type=float, default=0.5, help="cost: the opening step without early stop (s)")
    p.add_argument("--n-arcs", default="16,30,60", help="convergence: the meshes, coarsest first")
    p.add_argument("--criteria", default="", help="convergence: FLOW criteria (default: physical,half-element)")
    p.add_argument("--cases", default="B,polymer", help="convergence: B and/or polymer; meshdiag: B (default) or polymer")
    p.add_argument("--margin", type=float, default=0.004,
                   help="convergence: the previous mesh's interval widened by this on both sides (m)")
    p.add_argument("--variants", default="", help="meshdiag: comma-separated variants (default: all)")
    p.add_argument("--tol-mm", type=float, default=4.0, help="meshdiag: interval width (mm)")
    p.add_argument("--start", type=float, default=0.37, help="meshdiag: first width tried on the first mesh (m)")
    p.add_argument("--quick-skip-enstad", action="store_true", help="height: skip the Enstad-arch variant")
    p.add_argument("--criterion", choices=CRITERIA, default=None,
                   help="FLOW criterion of the studies (default: the generator's, physical); convergence: --criteria")
    a = p.parse_args(argv)
    global CRITERION
    CRITERION = a.criterion
    a.out = Path(a.out or f"out/arching/{a.study}")
    a.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    STUDIES[a.study](a)
    print(f"{a.study}: done in {time.perf_counter() - t0:.0f} s; outputs in {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
