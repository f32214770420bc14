"""Janssen's stresses in a plane bin (two parallel vertical walls), docs/theory/hopper_theory.md §f.

    σ̄_v(z) = (ρ g b/(K μ_w)) [1 − exp(−K μ_w z/b)] + Q exp(−K μ_w z/b),  σ_w = K σ̄_v,  μ_w = tan φ_w

z: depth below the surface; b: HALF-width (area/perimeter = b per unit depth for two walls);
Q: surcharge on the surface; K: wall stress ratio σ_w/σ̄_v (assumed constant with depth — the
Janssen assumption — and uniform σ_v across the section). The circular bin is the same with
b → D/4. Deep asymptote: σ̄_v → ρ g b/(K μ_w), σ_w → ρ g b/μ_w (independent of K).
K choices (say which): Walker's active K (:func:`bulkflow.theory.walker.walker_K_bin`),
Jaky 1 − sin φ, Rankine (1 − sin φ)/(1 + sin φ).
"""
from __future__ import annotations

import math

import numpy as np

from .walker import walker_K_bin

__all__ = ["K_jaky", "K_rankine", "K_walker", "janssen_vertical", "janssen_wall",
           "janssen_asymptote"]

G_STANDARD = 9.81


def K_jaky(phi_deg: float) -> float:
    """Jaky's K0 = 1 − sin φ."""
    return 1.0 - math.sin(math.radians(phi_deg))


def K_rankine(phi_deg: float) -> float:
    """Rankine's active K = (1 − sin φ)/(1 + sin φ)."""
    s = math.sin(math.radians(phi_deg))
    return (1.0 - s) / (1.0 + s)


def K_walker(delta_deg: float, phi_w_deg: float) -> float:
    """Walker's active wall ratio for a wall at yield (vertical wall)."""
    return walker_K_bin(delta_deg, phi_w_deg, "active")


def janssen_vertical(z, rho, b, K, phi_w_deg, Q=0.0, g=G_STANDARD):
    """Mean vertical stress σ̄_v at depth z in a plane bin of half-width b."""
    z = np.asarray(z, dtype=float)
    mu = math.tan(math.radians(phi_w_deg))
    if mu == 0.0 or K == 0.0:
        return rho * g * z + Q          # frictionless walls: hydrostatic in σ_v
    e = np.exp(-K * mu * z / b)
    return rho * g * b / (K * mu) * (1.0 - e) + Q * e


def janssen_wall(z, rho, b, K, phi_w_deg, Q=0.0, g=G_STANDARD):
    """Wall normal stress σ_w = K σ̄_v."""
    return K * janssen_vertical(z, rho, b, K, phi_w_deg, Q, g)


def janssen_asymptote(rho, b, K, phi_w_deg, g=G_STANDARD):
    """(σ̄_v, σ_w) as z → ∞: (ρgb/(Kμ_w), ρgb/μ_w)."""
    mu = math.tan(math.radians(phi_w_deg))
    return rho * g * b / (K * mu), rho * g * b / mu
