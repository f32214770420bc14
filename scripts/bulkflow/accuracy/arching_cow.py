"""Family `arching-cow`: the critical outlet width of a cohesive powder against the mesh.

Each member is a whole bulkflow-cow search (bulkflow.arching.find_cow: coarse bracket on 10
elements along the outlet, then bisection on the member's mesh to 2 mm; --quick: 4 mm) with
n_arc elements along the outlet arc; h = 1/n_arc. The member's value is the middle of its
interval [largest width that arched, smallest that flowed]; its cost is the whole search (every
trial's wall and CPU time, element-steps). No closed form: the reference is Richardson-
extrapolated from the three finest meshes. The bisection tolerance bounds how well a member is
known (± tol/2), which the GCI does not include: differences between members below the tolerance
are noise, and then no order is observed.

The material is thesis Case B at 1 m (default) or the Eckhoff & Leversen polymer powder (fc0
reading, 1 m), with the thesis's non-associated flow rule (ψ = 0) or Davis's associated material
of equal strength (`flow_rule="davis"`); the flow criterion is bulkflow.arching's (3 % of the
outlet width, or the thesis's half an outlet element). Why ψ = 0 drifts with the mesh and Davis's
material does not: scripts/bulkflow/arching/README.md, "Mesh dependence: diagnosis".
"""
from __future__ import annotations

import dataclasses
from types import SimpleNamespace

FAMILY = [10, 20, 30, 40]
QUICK = [10, 14, 20]
#: set by the command line: the members (--n-arcs), the flow criterion (--criterion), the flow
#: rule (--flow-rule) and the material (--cow-case)
N_ARCS: list[int] | None = None
CRITERION: str | None = None
FLOW_RULE = "nonassociated"
CASE = "B"
CASES = {"B": ("B", "c0"), "polymer": ("polymer", "fc0")}
CRITERIA = ("physical", "half-element")
FLOW_RULES = ("nonassociated", "davis")


def members(quick: bool) -> list[dict]:
    tol = 0.004 if quick else 0.002
    return [{"n_arc": n, "h": 1.0 / n, "tol": tol, "elements": 0,
             "label": f"{n} elements along the outlet, bisection to {1000 * tol:g} mm"}
            for n in (N_ARCS or (QUICK if quick else FAMILY))]


def member_scene(n_arc: int):
    """The ArchingScene of a member with n_arc elements along the outlet (CASE, FLOW_RULE, CRITERION)."""
    from ..arching.scene import scene_from_case

    case, reading = CASES[CASE]
    sc = scene_from_case(case, reading, height=1.0, n_arc=n_arc, flow_rule=FLOW_RULE)
    if CRITERION is not None:
        sc = dataclasses.replace(sc, criterion=CRITERION)
    return sc


def run(member: dict, workdir, ranks: int, solver: str | None):
    """One member: a full search. Returns (timing, measure) like study.run_family expects."""
    import os

    from ..arching.cow import find_cow

    if solver:
        os.environ["BULKFLOW_BIN"] = str(solver)
    sc = member_scene(member["n_arc"])
    res = find_cow(sc, workdir / f"n{member['n_arc']}", np=ranks, tol=member["tol"],
                   coarse_n_arc=10 if member["n_arc"] > 10 else 0, log=lambda m: None)
    lo, hi = res["interval"]
    if lo is None or hi is None:
        raise RuntimeError(f"arching-cow n_arc {member['n_arc']}: no bracket found ({res['interval']})")
    timing = SimpleNamespace(wall=res["wall"], cpu=sum(r["cpu"] for r in res["runs"]),
                             increments=sum(r["increments"] for r in res["runs"]), base=None)
    work = sum(r["element_steps"] for r in res["runs"])
    return timing, {"value": 0.5 * (lo + hi), "no_flow": lo, "flow": hi, "runs": res["n_runs"],
                    "work_override": work}


def title() -> str:
    """The family's title for the current CASE, FLOW_RULE and CRITERION."""
    what = "thesis Case B at 1 m" if CASE == "B" else "Eckhoff & Leversen polymer (fc0 reading) at 1 m"
    rule = "Davis's associated material" if FLOW_RULE == "davis" else "ψ = 0 (the thesis's flow rule)"
    crit = "half an outlet element" if CRITERION == "half-element" else "3 % of the outlet width"
    return (f"critical outlet width, {what}, {rule}, flow at {crit} (bulkflow-cow search), "
            "elements along the outlet")


def expected_order() -> str:
    if FLOW_RULE == "davis":
        return "none needed: Davis's associated material has a unique collapse load, the interval stops moving"
    return "about 0.5 (measured): a non-associated material localises in mesh-set bands and drifts"


KIND = {
    "name": "arching-cow",
    "title": title(),
    "parameter": "1/n_arc",
    "parameter_unit": "-",
    "quantity": "critical outlet width",
    "error_measure": "|B_crit(n) / B_Richardson − 1|, B_crit the middle of the search's interval",
    "reference": "richardson",
    "members": members,
    "run": run,
    "expected_order": expected_order(),
}
