"""Family `incline`: the MPM block sliding down a 30° frictional wall, refined in the cell size.

The scene of inputs/mpm/incline_slide_2d.inp (elastic block 0.4 × 0.2 m, E 20 MPa, ν 0.3,
ρ 1000 kg/m³, uGIMP, 2 × 2 particles per cell, FLIP 0.99, CFL 0.3, a wall at 30° that is not
aligned with the grid, μ = 0.2) with CELL = h. Exact: a = g (sin α − μ cos α) = 3.20587 m/s².
Measured: the least-squares slope of the centre-of-mass velocity along the slope against time
from 0.1 s (as tests/mpm/check_mpm.py), error |a_h/a − 1|.

(The element version, inputs/verification/incline_slide_2d.inp, is not refined: from 3 × 3
elements up a sliding elastic block on a rigid line chatters — frictional flutter — so its
family has no meaningful fine members; see inputs/verification/README.md.)
"""
from __future__ import annotations

import math
import re

import numpy as np

from .runs import REPO, particles_from_log

ALPHA, MU, G = math.radians(30.0), 0.2, 9.81
EXACT = G * (math.sin(ALPHA) - MU * math.cos(ALPHA))
BLOCK_AREA = 0.4 * 0.2
PPC = 2
FAMILY = [0.1, 0.05, 0.025, 0.0125]
QUICK = [0.1, 0.05, 0.025]


def members(quick: bool) -> list[dict]:
    return [{"cell": h, "h": h, "elements": round(BLOCK_AREA / (h / PPC) ** 2),
             "label": f"cell {1000 * h:g} mm, {PPC}×{PPC} PPC, uGIMP"} for h in (QUICK if quick else FAMILY)]


def scene(member: dict) -> str:
    text = (REPO / "inputs" / "mpm" / "incline_slide_2d.inp").read_text()
    text, n = re.subn(r"(\*MPM GRID, CELL=)[0-9.eE+-]+", lambda m: f"{m.group(1)}{member['cell']!r}", text)
    if n != 1:
        raise RuntimeError("inputs/mpm/incline_slide_2d.inp: expected one *MPM GRID, CELL= line")
    return text


def measure(base, member: dict) -> dict:
    from ..post.run_output import read_history

    hist = read_history(f"{base}_history.csv")
    t = hist["time"]
    vs = hist["VCM1"] * math.cos(ALPHA) - hist["VCM2"] * math.sin(ALPHA)
    m = t >= 0.1
    acc = float(np.polyfit(t[m], vs[m], 1)[0])
    return {"value": acc, "error": abs(acc / EXACT - 1), "particles": particles_from_log(base)}


KIND = {
    "name": "incline",
    "title": "MPM block sliding on a 30° wall, μ 0.2 (uGIMP, 2×2 PPC), cell size h",
    "parameter": "cell h",
    "parameter_unit": "m",
    "quantity": "slide acceleration",
    "error_measure": "|a_h / (g (sin α − μ cos α)) − 1|, a_h the slope of the centre-of-mass velocity from 0.1 s",
    "reference": "exact",
    "exact_value": EXACT,
    "members": members,
    "scene": scene,
    "measure": measure,
    "expected_order": "none a priori: a rigid-body quantity, the error comes from the wall's grid-node "
                      "contact and the block's elastic vibration, not from a smooth field",
}
