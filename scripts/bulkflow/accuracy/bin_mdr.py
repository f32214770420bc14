"""Family `bin-mdr`: the discharge rate of the thesis's flat-bottomed bin (ch. 5), refined in the
cell, with or without a regularisation (issue 21 point 2).

The bin. The eccentric bin of bulkflow.mpm.bin_scene at the thesis's size (outlet b = 11.8 mm
against the right wall, 172 mm wide, filled to 200 mm), NDNS sand of Table 5.3 (φ = φcv = 34°,
ψ = 0, ρ_i 1800, 7° walls), 1 particle per cell, uGIMP, 0.3 s fill and 2.5 s discharge, no
inflow. Why the eccentric bin: the concentric half model nearly blocks at these cells (docs/bins.md:
its rate is the noise of a trickle), the eccentric one discharges steadily from the opening.
Cells h = b/(2k + 1), k = 2, 3, 4 (`edge_cells`, 5, 7 and 9 cells across the outlet; --quick:
k = 1, 2, 3 and a 1 s discharge): the outlet is an odd number of cells wide with its inner edge on
a node line for every k, so the members differ in h only.

- E = 1 MPa (Table 5.3 has 8 MPa): with the blend as a rate (PIC TIME) the rate no longer depends
  on E (eccentric NDNS at b/7: 8.40 kg/s/m with 8 MPa, 8.37 with 1 MPa; docs/bins.md), and 1 MPa
  takes √8 times fewer increments.
- PIC TIME 0.01 s (`--pic-time`; 0 gives the scene's FLIP=0.99, whose damping per increment makes
  the finer members discharge slower for a reason that is not the physics: docs/bins.md, "The
  PIC/FLIP blend").
- `--inertial-friction φ2,I0,d,ρs`: the rate-dependent friction μ(I) (`*INERTIAL FRICTION`,
  docs/mu_of_i.md; for this sand φ2 55.2°, I0 0.279, d 0.71 mm, ρs 2650 there), the regularised
  family; without it the static Mohr–Coulomb sand.

The quantity is the bins study's MDR (bulkflow.mpm.bin_analysis, thesis §5.5.2): the regression
of the discharged mass from 0.5 s after opening to the end of steady discharge T_ss, or to the
run's end when the rate held within 10 % from window to window to the end (kg/s per metre of
depth; the eccentric bin is a full model). No closed form: the reference is Richardson-
extrapolated from the three members with the GCI as its uncertainty, when they converge
monotonically (bulkflow.accuracy.study). Also reported: T_ss (None: not reached in the run).
"""
from __future__ import annotations

import math

import numpy as np

from ..mpm.bin_analysis import opening_time, steady_rate, steady_time
from ..mpm.bin_scene import bin_cell, bin_scene
from .runs import particles_from_log

EDGE_CELLS = [2, 3, 4]
QUICK_EDGE_CELLS = [1, 2, 3]
FULL = dict(young=1.0e6, discharge_time=2.5)
QUICK = dict(young=1.0e6, discharge_time=1.0)
# bulkflow-accuracy --pic-time: *MPM CONTROLS, PIC TIME in every member (0: the scene's FLIP=0.99)
PIC_TIME = 0.01
# bulkflow-accuracy --inertial-friction: (φ2 [deg], I0, d [m], ρs [kg/m3]) or None (static MC)
INERTIAL_FRICTION: tuple[float, float, float, float] | None = None
# bulkflow-accuracy --open-edge: the floor holds the particles, not the nodes, at the outlet's edge
OPEN_EDGE = False


def members(quick: bool) -> list[dict]:
    """One member per k: cell b/(2k + 1), 1 particle per cell, uGIMP."""
    rows = []
    for k in (QUICK_EDGE_CELLS if quick else EDGE_CELLS):
        h = bin_cell(edge_cells=k)
        rows.append({"edge_cells": k, "cell": h, "h": h, "quick_case": quick, "elements": 0,
                     "regularisation": regularisation_label(),
                     "label": f"cell {1000 * h:.3f} mm ({2 * k + 1} across the outlet), 1 PPC"})
    return rows


def regularisation_label() -> str:
    if INERTIAL_FRICTION is None:
        return "none (static Mohr-Coulomb)"
    phi2, i0, d, rho_s = INERTIAL_FRICTION
    return f"mu(I): phi2 {phi2:g} deg, I0 {i0:g}, d {d:g} m, rho_s {rho_s:g} kg/m3"


def with_inertial_friction(text: str, block: tuple[float, float, float, float]) -> str:
    """The scene with `*INERTIAL FRICTION` (φ2, I0, d, ρs) in its *MOHR COULOMB material, after
    that material's *MOHR COULOMB HARDENING table (the keyword belongs to the material)."""
    key = "*MOHR COULOMB HARDENING\n"
    at = text.find(key)
    if at < 0 or text.find(key, at + 1) >= 0:
        raise ValueError("--inertial-friction needs exactly one *MOHR COULOMB material in the scene "
                         "(the NDNS sand; the DS sand is a *USER MATERIAL)")
    end = text.index("\n", at + len(key)) + 1           # the hardening table's one line
    phi2, i0, d, rho_s = block
    return text[:end] + f"*INERTIAL FRICTION\n{phi2:.9g}, {i0:.9g}, {d:.9g}, {rho_s:.9g}\n" + text[end:]


def scene(member: dict) -> str:
    """The eccentric thesis bin of the module text at the member's cell."""
    kw = QUICK if member["quick_case"] else FULL
    # the measure reads the history (MASS_OUT every 0.01 s); one particle frame per second
    text = bin_scene(case="eccentric", sand="NDNS", edge_cells=member["edge_cells"], ppc=1,
                     young=kw["young"], fill_time=0.3, ramp=0.2, discharge_time=kw["discharge_time"],
                     field_dt=1.0, history_dt=0.01, pic_time=PIC_TIME, open_edge=OPEN_EDGE)
    if INERTIAL_FRICTION is not None:
        text = with_inertial_friction(text, INERTIAL_FRICTION)
    return text


def discharge_rate(t, mass, t_open) -> dict:
    """The bins study's MDR of a discharged-mass record M(t) (kg/m): to T_ss when the rate
    changed by more than 10 % between 0.5 s windows within the record, else to its end."""
    t_ss, _, _ = steady_time(t, mass, t_open)
    reached = math.isfinite(t_ss)
    return {"mdr": float(steady_rate(t, mass, t_open, t_ss)), "t_ss": float(t_ss) if reached else None}


def measure(base, member: dict) -> dict:
    hist = np.genfromtxt(f"{base}_history.csv", delimiter=",", names=True)
    r = discharge_rate(hist["time"], hist["MASS_OUT"], opening_time(hist))
    return {"value": r["mdr"], "t_ss": r["t_ss"], "discharged": float(hist["MASS_OUT"][-1] / hist["MASS"][0]),
            "particles": particles_from_log(base)}


KIND = {
    "name": "bin-mdr",
    "title": "MPM eccentric flat-bottomed bin at the thesis's size (ch. 5, outlet 11.8 mm, NDNS), MDR, "
             "cell h = b/(2k+1)",
    "parameter": "cell h",
    "parameter_unit": "m",
    "quantity": "MDR",
    "error_measure": "|MDR_h / MDR_Richardson − 1|, MDR the bin's discharge rate (0.5 s after opening to "
                     "T_ss or the run's end), kg/s/m",
    "reference": "richardson",
    "members": members,
    "scene": scene,
    "measure": measure,
    "expected_order": "about 1 where the flow is resolved (hopper-mdr 1.3-1.45); lower while the outlet "
                      "is still a few cells wide (static, b/5-b/9: 0.55, docs/bins.md)",
}
