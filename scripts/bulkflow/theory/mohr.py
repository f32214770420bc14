"""Mohr-circle relations shared by the hopper theories.

Conventions (all modules of :mod:`bulkflow.theory`): compression positive, angles in degrees
at the public interface, θ is the hopper half-angle from the vertical, stresses in Pa.

Sources
-------
* Thesis (Pardikar) eq. 6.2 (Enstad's modified effective angle δ_mod) and eq. 6.9
  (unconfined yield strength from the cohesion of the incipient yield locus).
* The wall angle ω from Coulomb wall friction on a Mohr circle of angle δ:
  sin φ_w = sin δ sin(2ω − φ_w) (Nedderman 1992 ch. 4; re-derived in
  docs/theory/hopper_theory.md §c.2).
"""
from __future__ import annotations

import math

__all__ = [
    "fc_from_c", "c_from_fc", "sin_delta_mod", "delta_mod_deg", "k_ratio",
    "wall_angle_passive_deg", "wall_angle_active_deg",
]


def _rad(a: float) -> float:
    return math.radians(a)


def fc_from_c(c: float, phi_deg: float) -> float:
    """Unconfined yield strength f_c of a Mohr-Coulomb yield locus with cohesion c, angle φ.

    Thesis eq. 6.9: f_c = 2 c cos φ / (1 − sin φ) = 2 c tan(45° + φ/2).
    (The uniaxial Mohr circle through the origin tangent to τ = c + σ tan φ.)
    """
    s = math.sin(_rad(phi_deg))
    return 2.0 * c * math.cos(_rad(phi_deg)) / (1.0 - s)


def c_from_fc(fc: float, phi_deg: float) -> float:
    """Inverse of :func:`fc_from_c`: c = f_c (1 − sin φ) / (2 cos φ)."""
    s = math.sin(_rad(phi_deg))
    return fc * (1.0 - s) / (2.0 * math.cos(_rad(phi_deg)))


def sin_delta_mod(phi_deg: float, k: float) -> float:
    """sin δ_mod of Enstad's modified effective yield locus, thesis eq. 6.2.

    sin δ_mod = [2 sin φ + k (1 − sin φ)] / [2 − k (1 − sin φ)].

    Assumptions: constant φ and a linear flow function f_c = f_c0 + k σ₁ (eq. 6.1). The modified
    EYL is the line of constant slope sin δ_mod tangent to the steady-flow Mohr circles, offset
    from the origin by p₀ = f_c0 (1 − sin φ)/(2 sin φ + k (1 − sin φ)) along the σ axis
    (docs/theory/hopper_theory.md §c.1; the offset is neglected in the theories, as in the thesis).
    k = 0 gives δ_mod = φ. Raises ValueError when sin δ_mod ≥ 1 (k too large for φ).
    """
    s = math.sin(_rad(phi_deg))
    val = (2.0 * s + k * (1.0 - s)) / (2.0 - k * (1.0 - s))
    if not (0.0 < val < 1.0):
        raise ValueError(f"sin(delta_mod) = {val:.4g} outside (0, 1) for phi = {phi_deg} deg, k = {k}")
    return val


def delta_mod_deg(phi_deg: float, k: float) -> float:
    """δ_mod in degrees (thesis eq. 6.2); see :func:`sin_delta_mod`."""
    return math.degrees(math.asin(sin_delta_mod(phi_deg, k)))


def k_ratio(angle_deg: float) -> float:
    """K = (1 + sin a)/(1 − sin a): σ₁/σ₂ on a yield locus through the origin with angle a."""
    s = math.sin(_rad(angle_deg))
    return (1.0 + s) / (1.0 - s)


def _asin_ratio(phi_w_deg: float, delta_deg: float) -> float:
    ratio = math.sin(_rad(phi_w_deg)) / math.sin(_rad(delta_deg))
    # sin φ_w > sin δ: the wall is "fully rough", shear happens inside the material.
    return math.degrees(math.asin(min(1.0, ratio)))


def wall_angle_passive_deg(delta_deg: float, phi_w_deg: float) -> float:
    """ω_p: angle between σ₁ and the wall normal in the passive (discharge) state.

    ω_p = ½ [φ_w + asin(sin φ_w / sin δ)]  (docs/theory/hopper_theory.md §c.2, Nedderman 1992 ch. 4).
    σ₁ at the right-hand wall is tilted upward from the inward wall normal by ω_p, so it makes
    the angle θ + ω_p with the horizontal. φ_w = 0 gives 0 (σ₁ normal to a smooth wall).
    If sin φ_w > sin δ the asin is capped at 90° (fully rough wall).
    """
    return 0.5 * (phi_w_deg + _asin_ratio(phi_w_deg, delta_deg))


def wall_angle_active_deg(delta_deg: float, phi_w_deg: float) -> float:
    """ω_a: the same angle in the active (filling) state, σ₁ roughly vertical.

    ω_a = ½ [φ_w + 180° − asin(sin φ_w / sin δ)]  (docs/theory/hopper_theory.md §c.2). φ_w = 0 gives 90°.
    """
    return 0.5 * (phi_w_deg + 180.0 - _asin_ratio(phi_w_deg, delta_deg))
