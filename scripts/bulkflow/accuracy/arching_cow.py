"""Family `arching-cow`: the critical outlet width of thesis Case B (1 m) against the mesh.

Each member is a whole bulkflow-cow search (bulkflow.arching.find_cow: coarse bracket on 10
elements along the outlet, then bisection on the member's mesh to 2 mm; --quick: 4 mm) with
n_arc elements along the outlet arc; h = 1/n_arc. The member's value is the middle of its
interval [largest width that arched, smallest that flowed]; its cost is the whole search (every
trial's wall and CPU time, element-steps). No closed form: the reference is Richardson-
extrapolated from the three finest meshes. The bisection tolerance bounds how well a member is
known (± tol/2), which the GCI does not include: differences between members below the tolerance
are noise, and then no order is observed.

bulkflow.arching's flow criterion may change (another branch): a `--criterion` option is passed
to find_cow (or set on the scene) only if this checkout's bulkflow.arching takes one.
"""
from __future__ import annotations

import dataclasses
import inspect
from types import SimpleNamespace

FAMILY = [10, 20, 30, 40]
QUICK = [10, 14, 20]
CRITERION = None          #: set by the command line (--criterion), passed through when supported


def members(quick: bool) -> list[dict]:
    tol = 0.004 if quick else 0.002
    return [{"n_arc": n, "h": 1.0 / n, "tol": tol, "elements": 0,
             "label": f"{n} elements along the outlet, bisection to {1000 * tol:g} mm"}
            for n in (QUICK if quick else FAMILY)]


def criterion_supported() -> str | None:
    """'find_cow' or 'scene' when this checkout's bulkflow.arching takes a flow criterion, else None."""
    from ..arching import cow, scene

    if "criterion" in inspect.signature(cow.find_cow).parameters:
        return "find_cow"
    if any(f.name == "criterion" for f in dataclasses.fields(scene.ArchingScene)):
        return "scene"
    return None


def run(member: dict, workdir, ranks: int, solver: str | None):
    """One member: a full search. Returns (timing, measure) like study.run_family expects."""
    import os

    from ..arching.cow import find_cow
    from ..arching.scene import scene_from_case

    if solver:
        os.environ["BULKFLOW_BIN"] = str(solver)
    sc = scene_from_case("B", "c0", height=1.0, n_arc=member["n_arc"])
    kwargs = {}
    if CRITERION is not None:
        where = criterion_supported()
        if where == "find_cow":
            kwargs["criterion"] = CRITERION
        elif where == "scene":
            sc = dataclasses.replace(sc, criterion=CRITERION)
        else:
            raise SystemExit("bulkflow-accuracy: --criterion given, but this checkout's bulkflow.arching "
                             "has no flow criterion option")
    res = find_cow(sc, workdir / f"n{member['n_arc']}", np=ranks, tol=member["tol"],
                   coarse_n_arc=10 if member["n_arc"] > 10 else 0, log=lambda m: None, **kwargs)
    lo, hi = res["interval"]
    if lo is None or hi is None:
        raise RuntimeError(f"arching-cow n_arc {member['n_arc']}: no bracket found ({res['interval']})")
    timing = SimpleNamespace(wall=res["wall"], cpu=sum(r["cpu"] for r in res["runs"]),
                             increments=sum(r["increments"] for r in res["runs"]), base=None)
    work = sum(r["element_steps"] for r in res["runs"])
    return timing, {"value": 0.5 * (lo + hi), "no_flow": lo, "flow": hi, "runs": res["n_runs"],
                    "work_override": work}


KIND = {
    "name": "arching-cow",
    "title": "critical outlet width, thesis Case B at 1 m (bulkflow-cow search), elements along the outlet",
    "parameter": "1/n_arc",
    "parameter_unit": "-",
    "quantity": "critical outlet width",
    "error_measure": "|B_crit(n) / B_Richardson − 1|, B_crit the middle of the search's interval",
    "reference": "richardson",
    "members": members,
    "run": run,
    "expected_order": "about 1: the flow limit is half the outlet element, so the interval drifts with h",
}
