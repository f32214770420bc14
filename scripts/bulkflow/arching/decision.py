"""Flow/no-flow decision of an arching run from its history CSV (never from the solver's stdout).

The opening step's `*STOP CONDITION` (docs/keywords.md) ends the run at FLOW or ARREST; the
history holds what the decision needs: `UMAX_<NSET>` (largest displacement since the opening
over the node set) and `ALLKE`. This module re-derives the outcome from those rows with the
same rules and the parameters written in the scene:

* FLOW      — UMAX exceeds DISPLACEMENT (3 % of the outlet width B under the default, mesh-objective
              criterion; half the outlet element length under `criterion="half-element"`, the
              thesis's "whatever sliding occurred is less than one half of the mesh element
              length"; scene.py writes it, README "The decision" says why);
* ARREST    — UMAX stays below the limit and, from MIN TIME on, either ALLKE ≤ KINETIC FRACTION
              × its peak in the step for HOLD, or UMAX grew by ≤ GROWTH × limit over HOLD; a run
              that ended before its step period with UMAX below the limit was stopped by the
              solver's ARREST rule (evaluated every 10 increments, finer than the history rows);
* UNDECIDED — neither, by the end of the step (slow creep), or neither by the time an element
              distortion ended the run after the opening (`ended_by`: the solver's message; the
              corner element at the wall folds in a creeping flow near the threshold on fine
              meshes, README "Distortion after the opening"): counted as flow by the search (the
              material is not at rest), and reported as such.
"""
from __future__ import annotations

import json
import re
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from bulkflow.post.run_output import read_history

FLOW, ARREST, UNDECIDED = "FLOW", "ARREST", "UNDECIDED"


@dataclass
class StopParams:
    nset: str
    displacement: float
    ke_fraction: float = 0.01
    hold: float = 0.0
    min_time: float = 0.0
    growth: float = 0.05
    step: int = 0                #: 1-based step number holding the condition
    period: float = 0.0


@dataclass
class Decision:
    outcome: str
    reason: str
    umax: float
    limit: float
    ke_peak: float
    ke_end: float
    t_end: float                 #: step time of the last row
    period: float
    stopped_early: bool
    window_growth: float

    def as_dict(self) -> dict:
        return asdict(self)

    def summary(self) -> str:
        return (f"{self.outcome}: {self.reason} (umax {self.umax:.3g} m vs limit {self.limit:.3g} m, "
                f"ALLKE end/peak {self.ke_end:.3g}/{self.ke_peak:.3g} J, t {self.t_end:.3g}/{self.period:.3g} s)")


_PARAM = re.compile(r"\s*([A-Z ]+?)\s*=\s*([^,]+)")


def read_stop_params(scene_path) -> StopParams:
    """The *STOP CONDITION of the scene and the period of its step."""
    step = 0
    params = None
    period = 0.0
    expect_dynamic_data = False
    for raw in Path(scene_path).read_text().splitlines():
        line = raw.strip()
        up = line.upper()
        if expect_dynamic_data:
            fields = [f.strip() for f in line.split(",")]
            cur_period = float(fields[1])
            expect_dynamic_data = False
            if params is not None and params.step == step:
                params.period = cur_period
            period = cur_period
            continue
        if up.startswith("*STEP"):
            step += 1
        elif up.startswith("*DYNAMIC"):
            expect_dynamic_data = True
        elif up.startswith("*STOP CONDITION"):
            kv = {m.group(1).strip(): m.group(2).strip() for m in _PARAM.finditer(line.split(",", 1)[1])}
            params = StopParams(nset=kv["NSET"].upper(), displacement=float(kv["DISPLACEMENT"]),
                                ke_fraction=float(kv.get("KINETIC FRACTION", 0.01)),
                                hold=float(kv.get("HOLD", 0.0)), min_time=float(kv.get("MIN TIME", 0.0)),
                                growth=float(kv.get("GROWTH", 0.05)), step=step, period=period)
    if params is None:
        raise ValueError(f"{scene_path}: no *STOP CONDITION")
    if params.hold <= 0:
        params.hold = 0.05 * params.period
    return params


def decide(history_path, params: StopParams, ended_by: str = "") -> Decision:
    """Outcome of the step of `params` from the history rows. `ended_by`: the solver's error when an
    element distortion ended the run in that step; then an early end is not the ARREST rule's."""
    h = read_history(history_path)
    col = f"UMAX_{params.nset}"
    if col not in h:
        raise ValueError(f"{history_path}: no column {col}")
    sel = h["step"] == params.step
    if not np.any(sel):
        raise ValueError(f"{history_path}: no rows of step {params.step} (the run did not reach it)")
    t = h["step_time"][sel]
    u = h[col][sel]
    ke = h["ALLKE"][sel]
    umax = float(np.max(u))
    t_end = float(t[-1])
    stopped_early = t_end < params.period * (1 - 1e-9)
    ke_peak = float(np.max(ke))
    growth = float(u[-1] - np.interp(t_end - params.hold, t, u)) if t_end - params.hold >= t[0] else float(u[-1])
    common = dict(umax=umax, limit=params.displacement, ke_peak=ke_peak, ke_end=float(ke[-1]), t_end=t_end,
                  period=params.period, stopped_early=stopped_early, window_growth=growth)
    if umax > params.displacement:
        return Decision(FLOW, "the largest displacement since the opening exceeds the limit", **common)
    # the kinetic-energy rule on the rows from MIN TIME on
    late = t >= params.min_time
    if np.any(late) and ke_peak > 0:
        quiet = ke <= params.ke_fraction * ke_peak
        since = None
        for ti, qi, li in zip(t, quiet, late):
            if not li:
                continue
            if qi:
                since = ti if since is None else since
                if ti - since >= params.hold:
                    return Decision(ARREST, "ALLKE below the fraction of its peak for the hold time", **common)
            else:
                since = None
    if t_end >= params.min_time + params.hold and growth <= params.growth * params.displacement:
        return Decision(ARREST, "the displacement stopped growing over the hold time", **common)
    if ended_by:
        return Decision(UNDECIDED, f"neither rule was met when the run ended ({ended_by})", **common)
    if stopped_early:
        return Decision(ARREST, "the solver's stop condition ended the run (ARREST rule between history rows)",
                        **common)
    return Decision(UNDECIDED, "neither rule was met by the end of the step", **common)


def main(argv=None) -> int:
    import argparse

    p = argparse.ArgumentParser(prog="bulkflow-arching-decide", description="flow/no-flow from a run's history")
    p.add_argument("scene")
    p.add_argument("history")
    p.add_argument("--json", action="store_true")
    a = p.parse_args(argv)
    d = decide(a.history, read_stop_params(a.scene))
    print(json.dumps(d.as_dict()) if a.json else d.summary())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
