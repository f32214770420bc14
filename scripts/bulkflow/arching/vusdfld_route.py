"""The thesis's own route to a flow-function cohesion (issue 17 point 4): Abaqus's built-in
Mohr–Coulomb with `*MOHR COULOMB, DEPENDENCIES=1` + `*MOHR COULOMB HARDENING, DEPENDENCIES=1`
(cohesion tabulated against field 1) and a VUSDFLD that writes field 1 = the major principal
consolidation stress σ1, frozen after filling (ours, in flow-function mode:
`*USER DEFINED FIELD, PROPERTIES=3` with `1, t_freeze, record`), against our MC VUMAT's internal
flow function (`*USER MATERIAL` props 8–12), on one ch. 6 arching case.

Route "vumat": the arching scene as `bulkflow-make-arching` writes it (cohesion c = fc(σ1)(1 −
sin φ)/(2 cos φ) inside the VUMAT, σ1 recorded in SDV4). Route "vusdfld": the same scene with the
material replaced by

    *MATERIAL, NAME=MC-POWDER
    *ELASTIC                              E, ν
    *MOHR COULOMB, DEPENDENCIES=1         φ, 0, , 0  (one row: constant angles)
    *MOHR COULOMB HARDENING, DEPENDENCIES=1
                                          c(σ1_i), 0, , σ1_i   (rows of the flow function)
    *DEPVAR                               9  (SDV 9: the VUSDFLD's record; 1-8 our VUMAT's in bulkflow)
    *USER DEFINED FIELD, PROPERTIES=3     1, t_freeze, 0

c(σ1_i) = fc(σ1_i)(1 − sin φ)/(2 cos φ) at the corners of the flow function (σ1 = 0, the bilinear
knee, and `TOP` Pa, far above any consolidation stress in a hopper), so linear interpolation in
the field reproduces the flow function exactly (to round-off) over the whole range. Both routes
freeze σ1 at `FREEZE_OFFSET` after the end of the sliding step: at exactly the step end the
answer to "is the last increment's time ≤ t_freeze" depends on the last bit of two differently
summed times (umat/README.md), and the offset, far below one increment, takes that away.

    python -m bulkflow.arching.vusdfld_route                   # both intervals, Case A, H = 1 m
    python -m bulkflow.arching.vusdfld_route --case B --height 2 --n-arc 30 --tol 0.002
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from dataclasses import dataclass

from .cow import find_cow
from .scene import ArchingScene, fmt, scene_from_case

#: σ1 of the last row of the cohesion table (Pa): consolidation stresses in the ch. 6 hoppers are a
#: few kPa (ρgH ≈ 8 kPa for Case A at 2 m), so the held end value is never reached.
TOP = 1.0e7
#: Freeze time after the end of the sliding step (s): far below an increment (~1e-5 s).
FREEZE_OFFSET = 1.0e-7
ROUTES = ("vumat", "vusdfld")


@dataclass
class RouteScene(ArchingScene):
    """An arching scene whose material follows one of the two routes."""

    route: str = "vumat"

    def freeze_time(self) -> float:
        return super().freeze_time() + FREEZE_OFFSET

    def cohesion_rows(self) -> list[tuple[float, float]]:
        """(σ1, c) at the corners of the flow function: exact under linear interpolation."""
        s = math.sin(math.radians(self.phi))
        factor = (1.0 - s) / (2.0 * math.cos(math.radians(self.phi)))
        if self.flow == "linear":
            points = [0.0, TOP]
            fc = [self.fc0 + self.k * p for p in points]
        elif self.flow == "bilinear":
            knee = self.fc0 / (1.0 - self.k)
            points = [0.0, knee, TOP]
            fc = [min(0.5 * self.fc0 + 0.5 * (1 + self.k) * p, self.fc0 + self.k * p) for p in points]
        else:
            points = [p for p, _ in self.table]
            fc = [f for _, f in self.table]
        return [(p, f * factor) for p, f in zip(points, fc)]

    def material_lines(self) -> list[str]:
        if self.route == "vumat":
            return super().material_lines()
        lines = ["*MATERIAL, NAME=MC-POWDER", "*DENSITY", fmt(self.density),
                 "*ELASTIC", f"{fmt(self.young)}, {fmt(self.poisson)}",
                 "*MOHR COULOMB, DEPENDENCIES=1", f"{fmt(self.phi)}, 0., , 0.",
                 "*MOHR COULOMB HARDENING, DEPENDENCIES=1"]
        lines += [f"{c:.17g}, 0., , {s1:.17g}" for s1, c in self.cohesion_rows()]
        lines += ["*DEPVAR", "9", "*USER DEFINED FIELD, PROPERTIES=3",
                  f"1., {self.freeze_time():.17g}, 0."]
        return lines


def route_scene(route: str, case: str = "A", reading: str = "c0", **overrides) -> RouteScene:
    base = scene_from_case(case, reading, **overrides)
    return RouteScene(**dataclasses.asdict(base), route=route)


def compare(case: str, reading: str, workdir, np: int, tol: float, coarse_n_arc: int, bracket=None,
            log=print, **overrides) -> dict:
    """The critical outlet width interval by both routes (the same search, trial for trial)."""
    out = {}
    for route in ROUTES:
        scene = route_scene(route, case, reading, **overrides)
        log(f"route {route}: {scene.n_elements()} elements, freeze time {scene.freeze_time():.9g} s")
        t0 = time.perf_counter()
        res = find_cow(scene, f"{workdir}/{route}", np=np, tol=tol, coarse_n_arc=coarse_n_arc,
                       bracket=bracket, log=log)
        res["wall"] = time.perf_counter() - t0
        out[route] = res
    return out


def table(result: dict) -> str:
    rows = [f"{'route':10s} {'no flow (cm)':>13s} {'flow (cm)':>10s} {'runs':>5s} {'wall (s)':>9s}"]
    for route, res in result.items():
        lo, hi = res["interval"]
        cm = (lambda x: "n/a" if x is None else f"{x * 100:.3f}")
        rows.append(f"{route:10s} {cm(lo):>13s} {cm(hi):>10s} {res['n_runs']:5d} {res['wall']:9.1f}")
    trials = {r: [(t["outlet_width"], t["n_arc"], t["outcome"]) for t in res["runs"]] for r, res in result.items()}
    same = trials["vumat"] == trials["vusdfld"]
    rows.append("identical interval: " + ("yes" if result["vumat"]["interval"] == result["vusdfld"]["interval"]
                                          else "NO") + f"; identical trials and outcomes: {'yes' if same else 'NO'}")
    return "\n".join(rows)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m bulkflow.arching.vusdfld_route", description=__doc__.split("\n\n")[0])
    p.add_argument("--case", default="A")
    p.add_argument("--reading", default="c0")
    p.add_argument("--height", type=float, default=1.0)
    p.add_argument("--n-arc", type=int, default=16)
    p.add_argument("--coarse-n-arc", type=int, default=12)
    p.add_argument("--tol", type=float, default=0.004)
    p.add_argument("--bracket", default="", help="lo,hi (m) instead of the theory start")
    p.add_argument("--np", type=int, default=2)
    p.add_argument("--workdir", default="out/vusdfld_route")
    p.add_argument("--json", default="", help="write both searches to this JSON file")
    a = p.parse_args(argv)
    bracket = tuple(float(v) for v in a.bracket.split(",")) if a.bracket else None
    res = compare(a.case, a.reading, a.workdir, a.np, a.tol, a.coarse_n_arc, bracket,
                  height=a.height, n_arc=a.n_arc)
    print(f"critical outlet width, case {a.case} (reading {a.reading}), H = {a.height:g} m, "
          f"{a.n_arc} elements along the outlet, tolerance {a.tol * 1000:g} mm")
    print(table(res))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(res, f, default=str)
    return 0 if res["vumat"]["interval"] == res["vusdfld"]["interval"] else 1


if __name__ == "__main__":
    sys.exit(main())
