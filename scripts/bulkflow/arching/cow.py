"""bulkflow-cow: the critical outlet width (COW) of a cohesive material in a wedge hopper by FEM,
bracketed from the theory estimates and bisected to a tolerance (thesis §6.2-6.5, issue 4).

Each trial writes an arching scene (bulkflow.arching.scene) for an outlet width B, runs it with
mpirun and decides flow/no-flow from its history (bulkflow.arching.decision). The search:

1. start at Enstad's estimate (bulkflow.theory.critical_width_estimates; Jenike/McLean if Enstad
   has none), or the middle of --bracket;
2. bracket on a coarse mesh (--coarse-n-arc elements along the outlet): step by a factor 1.3 away
   from the start until the outcome changes, then bisect to --coarse-tol;
3. on the target mesh (--n-arc): check both ends of the coarse bracket (widen by its width while
   they do not bracket), then bisect to --tol (default 2 mm on B).

The result is the interval [largest width that arched, smallest width that flowed]; the table
puts it beside the theories, like thesis Table 6.3, with the cost (runs, wall time). `--json`
prints everything machine-readable; `--plot` draws the trials.

    bulkflow-cow --case B --height 2                    # Case B, 2 m above the apex
    bulkflow-cow --case polymer --reading fc0 --json
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

from bulkflow.theory import Hopper, Material, critical_width_estimates

from .runner import RunRecord, run_scene
from .scene import ArchingScene, add_scene_arguments, scene_from_args


def theory_estimates(scene: ArchingScene) -> dict:
    """McLean/Jenike/Enstad widths (m) for the scene's material and hopper (default readings)."""
    m = Material(rho=scene.density, phi_deg=scene.phi, phi_w_deg=scene.phi_w, k=scene.k, fc0=scene.fc0,
                 E=scene.young, nu=scene.poisson, flow="bilinear" if scene.flow == "bilinear" else "linear")
    h = Hopper(theta_deg=scene.theta, height=scene.height)
    est = critical_width_estimates(h, m)
    return {k: float(est[k]) for k in ("mclean", "jenike", "enstad")} | {"assumptions": est.get("assumptions", {})}


def _finite(x) -> bool:
    return x is not None and math.isfinite(x) and x > 0


class Search:
    """Trial bookkeeping: every run, and the tightest bracket seen per mesh."""

    def __init__(self, scene: ArchingScene, workdir, np: int, log):
        self.scene, self.workdir, self.np, self.log = scene, Path(workdir), np, log
        self.runs: list[RunRecord] = []
        self.known: dict[tuple, bool] = {}     # (width rounded to 1 µm, n_arc) -> flows

    def max_width(self) -> float:
        # the outlet crown (r_out on the axis) must stay below the top surface: r_out <= 0.85 H
        return 2.0 * 0.85 * self.scene.height * math.sin(math.radians(self.scene.theta))

    def trial(self, width: float, n_arc: int) -> bool:
        key = (round(width, 6), n_arc)
        if key in self.known:
            return self.known[key]
        s = replace(self.scene, outlet_width=width, n_arc=n_arc, field_frames=0)
        rec = run_scene(s, self.workdir, np=self.np, log=self.log, keep=False)
        self.runs.append(rec)
        self.known[key] = rec.flows
        return rec.flows

    def bracket(self, start: float, n_arc: int, lo: float | None = None, hi: float | None = None,
                factor: float = 1.3, max_steps: int = 8):
        """Expand from `start` (or check lo/hi) until [arched, flowed] brackets the COW."""
        if lo is None and hi is None:
            if self.trial(start, n_arc):
                hi = start
            else:
                lo = start
        if lo is not None and hi is not None:
            if self.trial(lo, n_arc):
                hi, lo = lo, None
            elif not self.trial(hi, n_arc):
                lo, hi = hi, None
        steps = 0
        while lo is None and steps < max_steps:
            w = hi / factor
            if self.trial(w, n_arc):
                hi = w
            else:
                lo = w
            steps += 1
        while hi is None and steps < max_steps:
            w = min(lo * factor, self.max_width())
            if w <= lo * (1 + 1e-9):
                break
            if self.trial(w, n_arc):
                hi = w
            else:
                lo = w
            steps += 1
        return lo, hi

    def bisect(self, lo: float, hi: float, n_arc: int, tol: float):
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            if self.trial(mid, n_arc):
                hi = mid
            else:
                lo = mid
        return lo, hi


def refine(srch: Search, lo: float | None, hi: float | None, n_arc: int, tol: float, start: float):
    """On mesh `n_arc`: check the ends of a bracket [lo, hi] found elsewhere (a coarser mesh), widen
    while they do not bracket, then bisect to `tol`. Without a bracket, expand from `start`."""
    if lo is not None and hi is not None:
        width = hi - lo
        flo = srch.trial(lo, n_arc)
        while flo and lo - width > 0.005:
            hi, lo = lo, lo - width
            width *= 2
            flo = srch.trial(lo, n_arc)
        if not flo:
            fhi = srch.trial(hi, n_arc)
            while not fhi and hi + width < srch.max_width():
                lo, hi = hi, hi + width
                width *= 2
                fhi = srch.trial(hi, n_arc)
            if not fhi:
                hi = None
        else:
            lo = None
    else:
        lo, hi = srch.bracket(start, n_arc, lo, hi)
    if lo is not None and hi is not None:
        lo, hi = srch.bisect(lo, hi, n_arc, tol)
    return lo, hi


def find_cow(scene: ArchingScene, workdir, *, np: int = 2, tol: float = 0.002, coarse_n_arc: int = 12,
             coarse_tol: float | None = None, bracket: tuple | None = None, log=print) -> dict:
    """Run the search; returns a dict with the interval, the theories and every trial."""
    t0 = time.perf_counter()
    est = theory_estimates(scene)
    start = next((est[k] for k in ("enstad", "jenike", "mclean") if _finite(est[k])), 0.2)
    srch = Search(scene, workdir, np, log)
    start = min(start, 0.9 * srch.max_width())
    coarse_tol = coarse_tol or max(4 * tol, 0.01)
    lo = hi = None
    if bracket:
        lo, hi = bracket
        start = 0.5 * (lo + hi)
    phases = []
    if coarse_n_arc and coarse_n_arc < scene.n_arc:
        log(f"coarse bracket (n_arc {coarse_n_arc}) from {start * 100:.2f} cm")
        lo, hi = srch.bracket(start, coarse_n_arc, lo, hi)
        if lo is not None and hi is not None:
            lo, hi = srch.bisect(lo, hi, coarse_n_arc, coarse_tol)
        phases.append(dict(n_arc=coarse_n_arc, interval=[lo, hi]))
        if lo is not None and hi is not None:
            start = 0.5 * (lo + hi)
    log(f"target mesh (n_arc {scene.n_arc})")
    lo, hi = refine(srch, lo, hi, scene.n_arc, tol, start)
    phases.append(dict(n_arc=scene.n_arc, interval=[lo, hi]))
    wall = time.perf_counter() - t0
    return dict(scene={k: v for k, v in vars(scene).items() if k != "title"}, theory=est, tol=tol,
                interval=[lo, hi], phases=phases, runs=[r.as_dict() for r in srch.runs],
                n_runs=len(srch.runs), solver_wall=sum(r.wall for r in srch.runs), wall=wall)


def table(result: dict, title: str = "") -> str:
    """Thesis Table 6.3 layout: theories and the FEM interval (cm)."""
    th = result["theory"]
    lo, hi = result["interval"]
    s = result["scene"]

    def cm(x):
        return "  n/a" if x is None or not math.isfinite(x) else f"{x * 100:6.2f}"
    lines = [title or "critical outlet width",
             f"  theta {s['theta']:g} deg, H {s['height']:g} m above the apex, fc0 {s['fc0']:.5g} Pa, k {s['k']:g}, "
             f"phi {s['phi']:g}, phi_w {s['phi_w']:g}, {s['state']}, {s['arch']} arch, flow function {s['flow']}",
             f"  {'':22s} B_crit (cm)",
             f"  {'McLean':22s} {cm(th['mclean'])}",
             f"  {'Jenike':22s} {cm(th['jenike'])}",
             f"  {'Enstad':22s} {cm(th['enstad'])}",
             f"  {'FEM (no flow, flow)':22s} {cm(lo)} .. {cm(hi)}"
             + (f"   width {(hi - lo) * 1000:.2f} mm" if lo is not None and hi is not None else "   (not bracketed)"),
             f"  cost: {result['n_runs']} runs, solver {result['solver_wall']:.0f} s, total {result['wall']:.0f} s "
             f"(n_arc {s['n_arc']}, tol {result['tol'] * 1000:g} mm, FLOW criterion {s.get('criterion', 'half-element')})"]
    return "\n".join(lines)


def plot(result: dict, path, title: str = "") -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    runs = result["runs"]
    for i, r in enumerate(runs):
        ax.plot(i + 1, r["outlet_width"] * 100, "o" if r["flows"] else "s",
                color="tab:red" if r["flows"] else "tab:blue", ms=5 + (r["n_arc"] > 15) * 2)
    colours = {"mclean": "k", "jenike": "g", "enstad": "r"}
    for k, c in colours.items():
        v = result["theory"][k]
        if v is not None and math.isfinite(v):
            ax.axhline(v * 100, color=c, lw=1, ls="--", label=f"{k} {v * 100:.1f} cm")
    lo, hi = result["interval"]
    if lo is not None and hi is not None:
        ax.axhspan(lo * 100, hi * 100, color="0.8", label=f"FEM {lo * 100:.2f}-{hi * 100:.2f} cm")
    ax.plot([], [], "o", color="tab:red", label="flow")
    ax.plot([], [], "s", color="tab:blue", label="arch (no flow)")
    ax.set_xlabel("trial (small markers: coarse mesh)")
    ax.set_ylabel("outlet width B (cm)")
    ax.set_title(title or "critical outlet width search")
    ax.legend(fontsize=7)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="bulkflow-cow", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    add_scene_arguments(p)
    g = p.add_argument_group("search")
    g.add_argument("--tol", type=float, default=0.002, help="interval width on B (m)")
    g.add_argument("--coarse-n-arc", type=int, default=12, help="mesh while bracketing (0: target mesh only)")
    g.add_argument("--coarse-tol", type=float, default=None, help="bracket width on the coarse mesh (m)")
    g.add_argument("--bracket", type=str, default="", help="lo,hi (m) instead of the theory start")
    g.add_argument("--np", type=int, default=2, help="MPI ranks per run")
    g.add_argument("--workdir", default="out/cow", help="scenes, histories and logs")
    g.add_argument("--json", action="store_true", help="print the result as JSON (the log goes to stderr)")
    g.add_argument("--plot", default="", help="PNG of the trials")
    a = p.parse_args(argv)
    scene = scene_from_args(a, 0.1)
    log = (lambda m: print(m, file=sys.stderr, flush=True)) if a.json else (lambda m: print(m, flush=True))
    bracket = tuple(float(v) for v in a.bracket.split(",")) if a.bracket else None
    res = find_cow(scene, a.workdir, np=a.np, tol=a.tol, coarse_n_arc=a.coarse_n_arc, coarse_tol=a.coarse_tol,
                   bracket=bracket, log=log)
    title = f"critical outlet width, case {a.case or 'custom'}" + (f" (reading {a.reading})" if a.case else "")
    res["title"] = title
    if a.plot:
        plot(res, a.plot, title)
    if a.json:
        print(json.dumps(res, default=str))
    else:
        print(table(res, title))
    return 0


if __name__ == "__main__":
    sys.exit(main())
