"""Mass discharge rate correlations: Beverloo for a rectangular (slot) outlet and Rose–Tanaka.

Sources: thesis eqs. 1.4–1.7 (Beverloo et al. 1961; Nedderman 1992 for k = 1.5; Rose & Tanaka
1959) and thesis eq. 4.5 (ṁ ∝ b^{3/2} (tan θ)^{-0.35}).

    ṁ_B  = (4C/π) ρ_i A* √(g D_H*)                                   (1.4)
    A*   = (b − k d)(l − k d)                                          (1.5)
    D_H* = 2 (b − k d)(l − k d)/(b + l − 2 k d)   (hydraulic diameter 4A/P of the reduced outlet) (1.6)
    ṁ_RT = ṁ_B F,   F = (tan θ)^{-0.35}  (thesis form)                  (1.7)

Assumptions: cohesionless, free-flowing material; C is not given by the thesis (0.55–0.65 is the
usual range; default 0.58, docs/theory/hopper_theory.md §a). General Rose–Tanaka form
(Nedderman 1992 ch. 10, from memory): F = (tan θ tan φ_d)^{-0.35} for θ < 90° − φ_d, 1 otherwise,
φ_d = angle of the stagnant-zone boundary with the horizontal; the thesis form is φ_d = 45°.
The steep-wall limit (θ ≥ 90° − φ_d, flat-bottomed bin behaviour) gives F = 1.
"""
from __future__ import annotations

import math

__all__ = ["beverloo_rect", "beverloo_circular", "rose_tanaka_factor", "rose_tanaka_rect"]

G_STANDARD = 9.81
C_DEFAULT = 0.58
K_SPHERES = 1.5


def beverloo_rect(b: float, l: float, d: float, rho: float, C: float = C_DEFAULT,
                  k: float = K_SPHERES, g: float = G_STANDARD) -> float:
    """Beverloo's mass flow rate (kg/s) through a rectangular b × l outlet (eqs. 1.4–1.6).

    b, l: outlet width and length (m); d: particle diameter (m); rho: flowing bulk density.
    Returns 0 if the reduced width b − k d or length l − k d is not positive.
    Long slot (l ≫ b): → (4√2 C/π) ρ √g l (b − kd)^{3/2}; per unit length ∝ b^{3/2}.
    """
    bb = b - k * d
    ll = l - k * d
    if bb <= 0.0 or ll <= 0.0:
        return 0.0
    area = bb * ll
    dh = 2.0 * bb * ll / (bb + ll)
    return 4.0 * C / math.pi * rho * area * math.sqrt(g * dh)


def beverloo_circular(D: float, d: float, rho: float, C: float = C_DEFAULT, k: float = K_SPHERES,
                      g: float = G_STANDARD) -> float:
    """Beverloo for a circular outlet of diameter D: C ρ √g (D − k d)^{5/2} (for comparison)."""
    dd = D - k * d
    return C * rho * math.sqrt(g) * dd ** 2.5 if dd > 0.0 else 0.0


def rose_tanaka_factor(theta_deg: float, phi_d_deg: float = 45.0) -> float:
    """Rose–Tanaka factor F = (tan θ tan φ_d)^{-0.35} for θ < 90° − φ_d, else 1.

    The thesis eq. 1.7 is φ_d = 45° ((tan θ)^{-0.35}); it is capped at F = 1 for θ ≥ 90° − φ_d
    (the hopper no longer narrows the flow: flat-bottom behaviour). θ → 0 diverges (F → ∞):
    the correlation is not meant for near-vertical walls below some angle; callers decide.
    """
    if theta_deg >= 90.0 - phi_d_deg:
        return 1.0
    return (math.tan(math.radians(theta_deg)) * math.tan(math.radians(phi_d_deg))) ** -0.35


def rose_tanaka_rect(b: float, l: float, d: float, rho: float, theta_deg: float,
                     C: float = C_DEFAULT, k: float = K_SPHERES, phi_d_deg: float = 45.0,
                     g: float = G_STANDARD) -> float:
    """Rose–Tanaka mass flow rate (kg/s), eq. 1.7: ṁ_B · F(θ)."""
    return beverloo_rect(b, l, d, rho, C, k, g) * rose_tanaka_factor(theta_deg, phi_d_deg)
