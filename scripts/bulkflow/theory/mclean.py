"""McLean's correlation for the critical outlet width of a plane-flow (wedge) hopper.

Source: thesis eq. 1.8 = eq. 6.5 (McLean, based on Jenike's work):

    B_crit = f_c (1 + 0.005 θ) / (ρ g),   θ in degrees from the vertical.

f_c is the unconfined yield strength at the consolidation stress near the outlet and ρ the bulk
density at the outlet. It is Jenike's form B = H(θ) f_c/(ρg) with H(θ) = 1 + θ/200
(docs/theory/hopper_theory.md §b, §c.3). The thesis notes it has been shown to be over-conservative.
How f_c is found (which consolidation stress) is the same question as for Jenike;
:func:`critical_width_linear` uses σ₁ = S ρ g B (S from :mod:`bulkflow.theory.jenike`).
"""
from __future__ import annotations

import math

from .jenike import critical_width_closed_form

__all__ = ["mclean_H", "critical_width", "critical_width_linear"]

G_STANDARD = 9.81


def mclean_H(theta_deg: float) -> float:
    """H(θ) = 1 + 0.005 θ[deg] of McLean's correlation (eq. 6.5)."""
    return 1.0 + 0.005 * theta_deg


def critical_width(fc: float, rho: float, theta_deg: float, g: float = G_STANDARD) -> float:
    """Eq. 6.5 for a given f_c (Pa): B = f_c (1 + 0.005 θ)/(ρ g) in metres."""
    return fc * mclean_H(theta_deg) / (rho * g)


def critical_width_linear(fc0: float, k: float, rho: float, theta_deg: float, S: float,
                          g: float = G_STANDARD) -> float:
    """Eq. 6.5 with the linear flow function f_c = f_c0 + k σ₁ and σ₁ = S ρ g B at the outlet:
    B = H f_c0 / (ρ g (1 − k S H)), H = 1 + 0.005 θ; inf when k S H ≥ 1 (no arch-free width)."""
    return critical_width_closed_form(fc0, k, rho, mclean_H(theta_deg), S, g)
