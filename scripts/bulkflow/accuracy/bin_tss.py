"""Family `bin-tss`: time to the end of steady discharge T_ss of a flat-bottomed bin (thesis ch. 5),
refined in the cell.

The bin. The thesis-size bin (outlet 11.8 mm in 172 mm × 200 mm) all but stops at 3 cells across
its outlet (docs/bins.md, "Results"): its T_ss values are the rule's answer to a trickle, and a
finer family of it costs hours per member. This family keeps the thesis's kind of bin (flat
bottom, NDNS sand of Table 5.3, 7° walls, no inflow, 0.5 s windows) and chooses its geometry so
that the discharge is steady for seconds and then ends within the run: the **eccentric** bin of
bulkflow.mpm.bin_scene with outlet b = 50 mm (the small CI bin's), 0.2 m wide, filled to 0.6 m.

- eccentric: next to the smooth (7°) right wall the sand slides out at every cell; the concentric
  half model locked in trials (3 cells across the outlet: the rate fell to nothing; 5 cells: to a
  third in 3 s, with most of the sand still in; docs/accuracy.md gives the numbers);
- tall: in lower, wider eccentric bins (0.2 × 0.3 m, 0.3 × 0.4 m) the rate fell from the opening
  on, with no steady part; with 0.6 m of fill in 0.2 m (216 kg/m) it holds within 10 % from
  window to window for 2.5 s at 5, 7 and 9 cells across (39–57 kg/s/m), then drops (at 3 cells
  across it never settles: that member has no T_ss, docs/accuracy.md);
- cells h = b/(2k + 1), k = 1 … 4 (`edge_cells`): the eccentric outlet is 2k + 1 cells wide with
  its inner edge on a node line for every k, so the members differ in h only, not in where the
  edge falls in a cell (mixing edge offsets makes a series jump: hopper-mdr);
- E = Table 5.3's 8 MPa: lowering it to 1 MPa, as docs/bins.md did for cost, is not neutral here
  (0.3 × 0.4 m eccentric bin, 3 cells across: 75 kg/m out in 3 s with 1 MPa, 51 kg/m with 8 MPa).
  --quick does lower it, in a smaller bin (0.15 m × 0.5 m) and a 3 s discharge, to exercise the
  command in about a minute; its numbers are not the full family's answer.

The quantity is the rule of docs/bins.md (bulkflow.mpm.bin_analysis.steady_time, thesis §5.5.2):
0.5 s windows from 0.5 s after opening, T_ss the end of the last window before the first change
of more than 10 %. A member's value is T_ss only when the rule found a steady regime and its end
within the run; otherwise the member has no value and says why (`tss_status`):

- "not reached": no jump before the run ended (the run is too short for this member);
- "no steady regime": the jump is between the first two windows, so the rate never held within
  10 % over two windows: the rule's answer (its smallest possible, 1.0 s) would be the end of a
  steady discharge that was not observed. The rule's raw answer stays in `tss_rule`.

A member without a value has no error; the summary extrapolates only when the three finest
members all have one (bulkflow.accuracy.study). Also reported: the MDR up to T_ss (`mdr`, the
regression of the discharged mass from 0.5 s after opening to T_ss, kg/s per metre of depth;
none without T_ss) and the discharged fraction at the end of the run. T_ss is a multiple of the
0.5 s window by definition: members closer than that are not distinguished, which the GCI does
not include (as a bisection tolerance in arching-cow).
"""
from __future__ import annotations

import math

import numpy as np

from ..mpm.bin_analysis import T_SS_INTERVAL, opening_time, steady_rate, steady_time
from ..mpm.bin_scene import bin_cell, bin_scene
from .runs import particles_from_log

OUTLET = 0.05                #: m
EDGE_CELLS = [1, 2, 3, 4]
QUICK_EDGE_CELLS = [1, 2, 3]
FULL = dict(width=0.20, fill=0.60, young=8.0e6, discharge_time=5.0)
QUICK = dict(width=0.15, fill=0.50, young=1.0e6, discharge_time=3.0)
# bulkflow-accuracy --pic-time: *MPM CONTROLS, PIC TIME in every member (0: the scene's FLIP=0.99)
PIC_TIME = 0.0
# bulkflow-accuracy --open-edge: the floor holds the particles, not the nodes, at the outlet's edge
OPEN_EDGE = False
STATUS_REACHED, STATUS_NOT_REACHED, STATUS_NO_STEADY = "reached", "not reached", "no steady regime"


def members(quick: bool) -> list[dict]:
    """One member per k: cell b/(2k + 1), 2 × 2 particles per cell, uGIMP."""
    rows = []
    for k in (QUICK_EDGE_CELLS if quick else EDGE_CELLS):
        h = bin_cell(OUTLET, k)
        rows.append({"edge_cells": k, "cell": h, "h": h, "quick_case": quick, "elements": 0,
                     "label": f"cell {1000 * h:.2f} mm ({2 * k + 1} across the outlet), 2×2 PPC"})
    return rows


def scene(member: dict) -> str:
    """The eccentric bin of the module text at the member's cell (0.3 s fill, then the discharge)."""
    kw = QUICK if member["quick_case"] else FULL
    # one particle frame per second is enough: the measure reads the history (MASS_OUT every 0.01 s)
    return bin_scene(case="eccentric", sand="NDNS", edge_cells=member["edge_cells"], ppc=2, outlet=OUTLET,
                     width=kw["width"], fill=kw["fill"], young=kw["young"], fill_time=0.3, ramp=0.2,
                     discharge_time=kw["discharge_time"], field_dt=1.0, history_dt=0.01, pic_time=PIC_TIME,
                     open_edge=OPEN_EDGE)


def classify(t, mass, t_open, interval: float = T_SS_INTERVAL) -> dict:
    """T_ss of a discharged-mass record M(t) (whole bin, kg/m) and what it means: dict with
    `t_ss` (s after opening, None unless a steady regime ended within the record), `tss_rule` (the
    rule's raw answer, None without a jump), `tss_status`, `steady_windows` (windows before the
    jump, or all windows when there is none) and `mdr` (kg/s/m up to T_ss, None without it)."""
    t_rule, ends, rates = steady_time(t, mass, t_open, interval=interval, skip=interval)
    if not math.isfinite(t_rule):
        status, n_steady = STATUS_NOT_REACHED, len(rates)
    else:
        n_steady = int(np.argmin(np.abs(ends - t_rule))) + 1     # windows up to and with T_ss
        status = STATUS_REACHED if n_steady >= 2 else STATUS_NO_STEADY
    t_ss = t_rule if status == STATUS_REACHED else None
    mdr = steady_rate(t, mass, t_open, t_ss, skip=interval) if t_ss is not None else None
    return {"t_ss": t_ss, "tss_rule": t_rule if math.isfinite(t_rule) else None, "tss_status": status,
            "steady_windows": n_steady, "mdr": mdr}


def measure(base, member: dict) -> dict:
    """T_ss and the MDR up to it from the run's history (the eccentric bin is a full model: no
    factor 2). value None when T_ss is not measured (see `classify`)."""
    hist = np.genfromtxt(f"{base}_history.csv", delimiter=",", names=True)
    c = classify(hist["time"], hist["MASS_OUT"], opening_time(hist))
    return {"value": c["t_ss"], "tss_status": c["tss_status"], "tss_rule": c["tss_rule"],
            "steady_windows": c["steady_windows"], "mdr": c["mdr"],
            "discharged": float(hist["MASS_OUT"][-1] / hist["MASS"][0]),
            "particles": particles_from_log(base)}


KIND = {
    "name": "bin-tss",
    "title": "MPM eccentric flat-bottomed bin (thesis ch. 5, outlet 50 mm, NDNS), T_ss, cell h = b/(2k+1)",
    "parameter": "cell h",
    "parameter_unit": "m",
    "quantity": "T_ss",
    "error_measure": "|T_ss,h / T_ss,Richardson − 1|, T_ss the end of steady discharge after opening "
                     "(0.5 s windows, first change > 10 %), s",
    "reference": "richardson",
    "also": {"mdr": "MDR up to T_ss, kg/s/m (whole bin)"},
    "members": members,
    "scene": scene,
    "measure": measure,
    "expected_order": "none known: T_ss moves in steps of the 0.5 s window, so an order shows only if it "
                      "changes by whole windows between members; the MDR up to T_ss about 1-1.5 (hopper-mdr 1.3)",
}
