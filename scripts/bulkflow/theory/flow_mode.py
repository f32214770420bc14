"""Mass-flow / funnel-flow boundary (docs/theory/hopper_theory.md §h; thesis §4.5.7, Fig. 4.16).

What is implemented, and how far it can be trusted:

* CONICAL hoppers, closed form (Leung et al. 2019 eqs. 5–6 via public code; checked against the
  existence limit of the conical radial stress field to 0.2°, see :mod:`.jenike`):
  θ_c = 90° − ½ acos[(1 − sin δ)/(2 sin δ)] − ω_p,  ω_p = ½[φ_w + asin(sin φ_w/sin δ)].
* PLANE FLOW (wedge), the thesis's case: Jenike's plane-flow chart (thesis Fig. 4.16) could NOT be
  retrieved — no closed form, no digitised chart data. It is not the existence limit of the plane
  radial stress field (that field exists to far larger angles). We do NOT provide chart values.
  :func:`plane_boundary_rule_of_thumb` is only the textbook rule "wedge walls may be about 10°
  less steep than cone walls for the same δ and φ_w" (from memory, unverified) applied to the
  conical formula; its result carries ``approximate=True`` and a caveat string. Do not use it to
  judge simulations; use the mass flow index instead.
* Mass flow index (thesis §4.5.7, Ketterhagen et al. 2009): MFI = V̄_wall / V̄_centreline,
  MFI > 0.3 mass flow, < 0.3 funnel flow — the operational criterion for FEM/MPM results.
"""
from __future__ import annotations

import math

import numpy as np

from .mohr import wall_angle_passive_deg

__all__ = ["conical_mass_flow_limit", "plane_boundary_rule_of_thumb", "mass_flow_index",
           "classify_mfi", "MFI_THRESHOLD", "PLANE_CAVEAT"]

MFI_THRESHOLD = 0.3
PLANE_CAVEAT = ("Jenike's plane-flow mass-flow chart is not available to us (no closed form or "
                "digitised data); this is the conical limit plus a rule-of-thumb margin, not the chart")


def conical_mass_flow_limit(delta_deg: float, phi_w_deg: float) -> float:
    """Largest half-angle θ_c (deg) of a conical hopper for mass flow (closed form, module doc).
    Returns a negative number when no cone angle gives mass flow for these δ, φ_w (nan if
    φ_w exceeds δ, i.e. the wall is fully rough)."""
    s = math.sin(math.radians(delta_deg))
    if math.sin(math.radians(phi_w_deg)) > s:
        return math.nan
    arg = (1.0 - s) / (2.0 * s)
    if arg > 1.0:
        return math.nan
    return 90.0 - 0.5 * math.degrees(math.acos(arg)) - wall_angle_passive_deg(delta_deg, phi_w_deg)


def plane_boundary_rule_of_thumb(delta_deg: float, phi_w_deg: float, margin_deg: float = 10.0) -> dict:
    """APPROXIMATE plane-flow limit θ_c,plane ≈ θ_c,cone + margin (rule of thumb, see module doc).

    Returns {'theta_c_deg' (capped at 90°), 'approximate': True, 'method', 'caveat'}.
    """
    tc = conical_mass_flow_limit(delta_deg, phi_w_deg)
    plane = min(tc + margin_deg, 90.0) if math.isfinite(tc) else math.nan
    return {"theta_c_deg": plane,
            "approximate": True,
            "method": f"conical closed form + {margin_deg:g} deg rule of thumb",
            "caveat": PLANE_CAVEAT}


def mass_flow_index(v_wall, v_centreline) -> float:
    """MFI = mean |velocity| along the wall path / mean |velocity| along the centreline path."""
    vw = float(np.mean(np.abs(np.asarray(v_wall, dtype=float))))
    vc = float(np.mean(np.abs(np.asarray(v_centreline, dtype=float))))
    return vw / vc


def classify_mfi(mfi: float, threshold: float = MFI_THRESHOLD) -> str:
    """'mass' if MFI > threshold (0.3), else 'funnel'."""
    return "mass" if mfi > threshold else "funnel"
