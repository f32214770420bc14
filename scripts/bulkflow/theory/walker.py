"""Wall normal stresses in a wedge hopper: Walker's method of differential slices with Walker's
or Walters' distribution factor, for filling (active) and discharge (passive, with a switch),
and the passive wall stress on Enstad's arcs.

Sources (thesis §1.2.2, §4.5.4 "modified Walker's theory" [its ref. 18: Walters]; formulas
re-derived in docs/theory/hopper_theory.md §e, the slice balance as in Tardos 1999):

    y dσ̄_v/dy + σ̄_v = −ρ g y + σ_w + τ_w cot θ ... → (wedge, m = 0; cone m = 1)
    σ̄_v(y) = ρgy/(N − 1) [1 − (y/H_t)^{N−1}] + Q (y/H_t)^N,  σ_w = D σ̄_v, τ_w = σ_w tan φ_w
    N = (m + 1)[D (1 + tan φ_w cot θ) − 1]       (N = 1: σ̄_v = ρgy ln(H_t/y) + Q y/H_t)

y: height above the apex; H_t: height of the free surface (or of the transition, with surcharge
Q) above the apex. Walker's D takes σ̄_v equal to σ_v at the wall, the wall at yield (ω from
:mod:`.mohr`): D = (1 + sin δ cos 2ω)/(1 − sin δ cos 2(θ + ω)), ω = ω_a filling, ω_p discharge.

Walters' factor: only the bin (vertical wall) form is implemented, numerically, from its
assumptions (τ_xy linear from axis to wall, σ_xx uniform, yield with δ across the slice;
Walters 1973, not re-read): :func:`walters_D_bin`. Walters' closed form for HOPPERS was not
available (docs/theory/hopper_theory.md §e.3); the wedge functions here use Walker's D and say so, and
:func:`enstad_wall_stress` is the self-consistent passive alternative.
Cohesionless (δ = φ) unless the caller passes δ_mod.
"""
from __future__ import annotations

import math

import numpy as np

from .enstad import G_STANDARD, W_factor, X_factor
from .mohr import k_ratio, wall_angle_active_deg, wall_angle_passive_deg

__all__ = ["walker_D", "walker_K_bin", "walters_D_bin", "slice_exponent", "slice_mean_vertical",
           "wall_normal_stress", "wall_normal_stress_switch", "enstad_wall_stress"]


def walker_D(delta_deg, phi_w_deg, theta_deg, state="passive"):
    """Walker's distribution factor D = σ_w/σ̄_v for a wall at yield (docs/theory/hopper_theory.md §e.2).

    state "active" (filling, σ₁ about vertical) uses ω_a; "passive" (discharge) uses ω_p.
    θ = 0 reduces to Walker's bin K (:func:`walker_K_bin`).
    """
    if state == "passive":
        w = wall_angle_passive_deg(delta_deg, phi_w_deg)
    elif state == "active":
        w = wall_angle_active_deg(delta_deg, phi_w_deg)
    else:
        raise ValueError("state must be 'active' or 'passive'")
    s = math.sin(math.radians(delta_deg))
    return (1.0 + s * math.cos(math.radians(2 * w))) / (1.0 - s * math.cos(math.radians(2 * (theta_deg + w))))


def walker_K_bin(delta_deg, phi_w_deg, state="active"):
    """Walker/Nedderman bin ratio σ_w/σ_v for a vertical wall at yield (closed form):
    K = [1 + sin²δ ∓ 2√(sin²δ − tan²φ_w cos²δ)]/(4 tan²φ_w + cos²δ), − active, + passive."""
    s, c, t = (math.sin(math.radians(delta_deg)), math.cos(math.radians(delta_deg)),
               math.tan(math.radians(phi_w_deg)))
    root = math.sqrt(max(0.0, s * s - t * t * c * c))
    sign = -1.0 if state == "active" else 1.0
    return (1.0 + s * s + sign * 2.0 * root) / (4.0 * t * t + c * c)


def walters_D_bin(delta_deg, phi_w_deg, state="active", n=2001):
    """Walters' distribution factor for a plane bin, D_W = σ_w / mean(σ_yy), from his assumptions:
    σ_xx uniform across the half-width, τ_xy = (x/b) τ_w (linear from the axis), every point at
    yield on a Coulomb locus through the origin with angle δ; σ_yy(x) is the major (active) or
    minor (passive) normal stress of the yield circle through (σ_xx, τ_xy). The wall stress σ_w
    and τ_w = σ_w tan φ_w fix the wall point, whose circle must also satisfy Walker's wall K.
    Numerical (trapezoid over n points). Example δ = 35°, φ_w = 20°: 0.277 active, 2.845 passive
    (docs/theory/hopper_theory.md §e.3)."""
    S = math.sin(math.radians(delta_deg))
    K = walker_K_bin(delta_deg, phi_w_deg, state)     # σ_w/σ_yy at the wall
    # at the wall: σ_xx = σ_w = 1, τ_w = tan φ_w; σ_yy(wall) = 1/K
    mu = math.tan(math.radians(phi_w_deg))
    x = np.linspace(0.0, 1.0, n)
    tau = x * mu
    sxx = 1.0
    # (sxx − p)² + τ² = p² S²  →  p²(1 − S²) − 2 sxx p + sxx² + τ² = 0
    a = 1.0 - S * S
    disc = np.maximum(sxx * sxx - a * (sxx * sxx + tau * tau), 0.0)
    p = (sxx + (1.0 if state == "active" else -1.0) * np.sqrt(disc)) / a
    syy = 2.0 * p - sxx
    # consistency of the wall point with Walker's K (same yield circle)
    if abs(syy[-1] - 1.0 / K) > 1e-6 * (1.0 / K):
        raise RuntimeError("walters_D_bin: wall point inconsistent with Walker's K")
    mean = float(np.sum((syy[1:] + syy[:-1]) * 0.5 * np.diff(x)))
    return 1.0 / mean


def slice_exponent(D, phi_w_deg, theta_deg, geometry="wedge"):
    """N = (m + 1)[D (1 + tan φ_w cot θ) − 1], m = 0 wedge, 1 cone."""
    m = 0 if geometry == "wedge" else 1
    return (m + 1) * (D * (1.0 + math.tan(math.radians(phi_w_deg)) / math.tan(math.radians(theta_deg))) - 1.0)


def slice_mean_vertical(y, H_t, rho, N, Q=0.0, g=G_STANDARD):
    """σ̄_v(y) of the slice balance (module doc); y, H_t heights above the apex; Q surcharge."""
    y = np.asarray(y, dtype=float)
    x = y / H_t
    if abs(N - 1.0) < 1e-9:
        with np.errstate(divide="ignore", invalid="ignore"):
            return rho * g * y * np.log(H_t / y) + Q * x
    return rho * g * y / (N - 1.0) * (1.0 - x ** (N - 1.0)) + Q * x ** N


def wall_normal_stress(y, H_t, rho, delta_deg, phi_w_deg, theta_deg, state="passive", Q=0.0,
                       D=None, geometry="wedge", g=G_STANDARD):
    """Wall normal stress σ_w(y) = D σ̄_v(y) of a hopper filled to H_t above the apex.

    state "active": filling (ω_a); "passive": discharge, passive everywhere (ω_p).
    D: override the distribution factor (default Walker's :func:`walker_D`).
    """
    if D is None:
        D = walker_D(delta_deg, phi_w_deg, theta_deg, state)
    N = slice_exponent(D, phi_w_deg, theta_deg, geometry)
    return D * slice_mean_vertical(y, H_t, rho, N, Q, g)


def wall_normal_stress_switch(y, H_t, y_switch, rho, delta_deg, phi_w_deg, theta_deg, Q=0.0,
                              geometry="wedge", g=G_STANDARD):
    """Discharge with a switch (docs/theory/hopper_theory.md §e.2): active field above y_switch (from the
    surface H_t with surcharge Q), passive field below it, loaded by the active σ̄_v at the
    switch; σ_w jumps from D_a σ̄_v to D_p σ̄_v there (the peak seen in thesis Fig. 4.12/4.17)."""
    y = np.asarray(y, dtype=float)
    Da = walker_D(delta_deg, phi_w_deg, theta_deg, "active")
    Dp = walker_D(delta_deg, phi_w_deg, theta_deg, "passive")
    Na = slice_exponent(Da, phi_w_deg, theta_deg, geometry)
    Np = slice_exponent(Dp, phi_w_deg, theta_deg, geometry)
    sv_switch = float(slice_mean_vertical(y_switch, H_t, rho, Na, Q, g))
    above = Da * slice_mean_vertical(y, H_t, rho, Na, Q, g)
    below = Dp * slice_mean_vertical(y, y_switch, rho, Np, sv_switch, g)
    return np.where(y >= y_switch, above, below)


def enstad_wall_stress(r, R, rho, theta_deg, delta_deg, beta_deg, g=G_STANDARD):
    """Passive wall normal stress on Enstad's arcs (docs/theory/hopper_theory.md §e.4, free surface):
    σ_w(r) = σ₂(r)[K_δ cos²β + sin²β], σ₂(r) = ρgWr/(X − 1)[1 − (r/R)^{X−1}], r along the wall."""
    r = np.asarray(r, dtype=float)
    X = float(X_factor(delta_deg, theta_deg, beta_deg))
    W = float(W_factor(theta_deg, beta_deg))
    if abs(X - 1.0) < 1e-9:
        s2 = rho * g * W * r * np.log(R / r)
    else:
        s2 = rho * g * W * r / (X - 1.0) * (1.0 - (r / R) ** (X - 1.0))
    b = math.radians(beta_deg)
    return s2 * (k_ratio(delta_deg) * math.cos(b) ** 2 + math.sin(b) ** 2)
