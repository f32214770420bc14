"""Jenike's critical outlet width for plane-flow (wedge) hoppers, thesis eqs. 6.3–6.4.

    σ̄₁ = ρ g B / sin 2β   (6.3)        B_crit = f_c sin 2β / (ρ g)   (6.4)

Thesis wording: β is "the angle between the major principal stress direction and the normal to
the wall" and "depends on φ_w and θ [Nedderman]"; f_c is the unconfined yield strength in the
vicinity of the outlet at the passive consolidation stress; the stresses from the material above
a thin layer near the outlet are neglected, so B does not depend on the fill height.

Eq. 6.3 is the θ → 0 limit of a thin circular arch of uniform vertical thickness
(:func:`thin_arch_stress_theta`, docs/theory/hopper_theory.md §c.2); it is *not* Jenike's H(θ) chart.

Which β (docs/theory/hopper_theory.md §c.2; the thesis never states which one it used):
  ``theta_plus_omega`` (default) β = θ + ω_p(δ_mod), the angle of σ₁ from the horizontal at the
      wall. It is the only reading that matches the thesis's verbal statements for Case B
      (φ_w = 0: "Jenike predicts flow at 60 cm and no flow at 30 cm"): 50.4 cm;
  ``omega`` β = ω_p(δ_mod), the literal "angle to the wall normal": Case B gives B = 0;
  ``phi_w`` β = φ_w; ``omega_cap`` β = min(ω_p, 45° − θ/2); ``theta_plus_omega_cap``
      β = min(θ + ω_p, 45°) (sin 2β ≤ 1 either way; 45° is its maximum).

Consolidation near the outlet (σ₁ = S ρ g B):
  :func:`S_first_term` — first radial term of Enstad's eq. 6.8 (σ₁ version), what the thesis used
  for Jenike and McLean (§6.5.3: "Instead of using the radial stress theory ... the first radial
  term of Eq. (6.8) was used"); :func:`radial_stress_field` — Jenike's radial stress field.

With a linear flow function the critical width has a closed form (docs/theory/hopper_theory.md §c.3):
B = H f_c0/(ρ g (1 − k S H)), H = sin 2β for eq. 6.4 and 1 + 0.005θ for McLean.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from . import enstad
from .mohr import k_ratio, wall_angle_passive_deg

__all__ = [
    "JENIKE_BETA_READINGS", "jenike_beta", "thin_arch_stress", "thin_arch_stress_theta",
    "H_from_beta", "critical_width", "critical_width_closed_form", "critical_width_general",
    "S_first_term", "RadialField", "radial_stress_field", "S_radial",
]

G_STANDARD = 9.81
JENIKE_BETA_READINGS = ("theta_plus_omega", "omega", "phi_w", "omega_cap", "theta_plus_omega_cap")


def jenike_beta(theta_deg: float, delta_deg: float, phi_w_deg: float,
                reading: str = "theta_plus_omega") -> float:
    """β (degrees) of eqs. 6.3–6.4 under one of :data:`JENIKE_BETA_READINGS` (module doc)."""
    omega = wall_angle_passive_deg(delta_deg, phi_w_deg)
    if reading == "theta_plus_omega":
        return theta_deg + omega
    if reading == "omega":
        return omega
    if reading == "phi_w":
        return phi_w_deg
    if reading == "omega_cap":
        return min(omega, 45.0 - 0.5 * theta_deg)
    if reading == "theta_plus_omega_cap":
        return min(theta_deg + omega, 45.0)
    raise ValueError(f"unknown Jenike beta reading {reading!r}; one of {JENIKE_BETA_READINGS}")


def H_from_beta(beta_deg: float) -> float:
    """sin 2β: the 'H' of eq. 6.4 written as B = H f_c/(ρg)."""
    return math.sin(math.radians(2.0 * beta_deg))


def thin_arch_stress(B: float, rho: float, beta_deg: float, g: float = G_STANDARD) -> float:
    """Eq. 6.3: σ̄₁ = ρ g B / sin 2β carried by a thin arch over an outlet of width B."""
    return rho * g * B / math.sin(math.radians(2.0 * beta_deg))


def thin_arch_stress_theta(B: float, rho: float, theta_deg: float, beta_deg: float,
                           g: float = G_STANDARD) -> float:
    """Thin circular arch keeping θ (docs/theory/hopper_theory.md §c.2, thin-layer limit of Enstad's ODE):
    σ̄₁ = ρ g (B/2)[α sin θ + sin β sin α]/(cos β sin³α), α = θ + β (radians in the first α).
    θ → 0 recovers eq. 6.3."""
    t, b = math.radians(theta_deg), math.radians(beta_deg)
    a = t + b
    return rho * g * 0.5 * B * (a * math.sin(t) + math.sin(b) * math.sin(a)) / (math.cos(b) * math.sin(a) ** 3)


def critical_width(fc: float, rho: float, beta_deg: float, g: float = G_STANDARD) -> float:
    """Eq. 6.4 for a given f_c: B = f_c sin 2β/(ρ g) (m)."""
    return fc * H_from_beta(beta_deg) / (rho * g)


def critical_width_closed_form(fc0: float, k: float, rho: float, H: float, S: float,
                               g: float = G_STANDARD) -> float:
    """B = H f_c0/(ρ g (1 − k S H)) for B = H f_c(σ₁)/(ρg), f_c = f_c0 + k σ₁, σ₁ = S ρ g B.
    inf when k S H ≥ 1 (the flow function never falls below the arch stress)."""
    den = 1.0 - k * S * H
    if den <= 0.0:
        return math.inf
    return H * fc0 / (rho * g * den)


def critical_width_general(flow_function, rho: float, H: float, sigma1_outlet, g: float = G_STANDARD,
                           B_max: float = 100.0) -> float:
    """Smallest B with ρ g B ≥ H f_c(σ₁(B)) (the flow/no-flow point), any flow function.

    sigma1_outlet: callable B -> consolidation σ₁ at the outlet (e.g. S ρ g B, or the full
    eq. 6.8 at r = B/(2 sin θ)). Found by scanning then brentq; inf if none below B_max.
    """
    def F(B):
        return rho * g * B - H * float(flow_function(sigma1_outlet(B)))

    if F(0.0) >= 0.0:
        return 0.0
    grid = np.concatenate([np.geomspace(1e-6, B_max, 600)])
    prev = 0.0
    for B in grid:
        if F(B) >= 0.0:
            return brentq(F, prev, B, xtol=1e-12, rtol=1e-12)
        prev = B
    return math.inf


def S_first_term(theta_deg: float, delta_deg: float, beta_deg: float, quantity: str = "sigma1") -> float:
    """S = σ₁/(ρ g B) at the outlet wall from the first radial term of eq. 6.8 at r = B/(2 sin θ):
    S = Y/((X − 1) 2 sin θ) with X, Y of Enstad's arcs at angle β (docs/theory/hopper_theory.md §c.4 route 2).
    inf for X ≤ 1 (first term meaningless: e.g. Case B)."""
    X = float(enstad.X_factor(delta_deg, theta_deg, beta_deg))
    if X <= 1.0:
        return math.inf
    Y = float(enstad.Y_factor(delta_deg, theta_deg, beta_deg, quantity))
    return Y / ((X - 1.0) * 2.0 * math.sin(math.radians(theta_deg)))


# ---- Jenike's radial stress field (passive) ---------------------------------------------------
@dataclass(frozen=True)
class RadialField:
    """Passive radial stress field p = ρ g r s(t), σ₁,₂ = p (1 ± sin δ); ψ(t) angle of σ₁ from
    the radial direction; t polar angle from the axis. s0 = s(0), s_wall = s(θ)."""

    geometry: str
    delta: float
    phi_w: float
    theta: float
    s0: float
    s_wall: float
    t: np.ndarray
    s: np.ndarray
    psi: np.ndarray

    @property
    def sigma1_wall_factor(self) -> float:
        """σ₁ at the wall / (ρ g r): s(θ)(1 + sin δ)."""
        return self.s_wall * (1.0 + math.sin(math.radians(self.delta)))


def _radial_rhs(geometry: str, S: float):
    conical = geometry == "conical"

    def rhs(t, y):
        s, psi = y
        c, s2 = math.cos(2 * psi), math.sin(2 * psi)
        if conical:
            ct = 1.0 / math.tan(t) if t > 1e-12 else 0.0
            r1 = -math.cos(t) - s * (1 + 4 * S * c - S) - S * s * s2 * ct
            r2 = math.sin(t) - 4 * s * S * s2 + s * S * (1 + c) * ct
        else:
            r1 = -math.cos(t) - s * (1 + 3 * S * c)
            r2 = math.sin(t) - 3 * s * S * s2
        # [S s2, 2 S s c; (1 − S c), 2 S s s2] [s'; ψ'] = [r1; r2]
        a11, a12, a21, a22 = S * s2, 2 * S * s * c, 1 - S * c, 2 * S * s * s2
        det = a11 * a22 - a12 * a21
        return [(r1 * a22 - a12 * r2) / det, (a11 * r2 - a21 * r1) / det]

    return rhs


def _shoot(geometry, S, s0, theta_rad, dense=False):
    # start slightly off the axis with the series ψ ≈ π/2 + ψ'(0) t
    if geometry == "conical":
        dpsi0 = (1 + s0 * (1 - 5 * S)) / (4 * S * s0)
    else:
        dpsi0 = (1 + s0 * (1 - 3 * S)) / (2 * S * s0)
    t0 = 1e-6
    y0 = [s0, math.pi / 2 + dpsi0 * t0]
    sol = solve_ivp(_radial_rhs(geometry, S), (t0, theta_rad), y0, rtol=1e-10, atol=1e-12,
                    method="DOP853", dense_output=dense)
    return sol


def radial_stress_field(delta_deg: float, phi_w_deg: float, theta_deg: float,
                        geometry: str = "plane", s0_range=(1e-3, 50.0)) -> RadialField:
    """Jenike's passive radial stress field by shooting on s(0) (docs/theory/hopper_theory.md §c.4 route 1).

    Equilibrium in polar coordinates with p = ρ g r s(t), σ₁,₂ = p(1 ± sin δ) (Coulomb material
    at yield with δ), symmetry ψ(0) = 90° and the wall condition ψ(θ) = 90° + ω_p. The conical
    (axisymmetric, Haar–von Kármán σ_hoop = σ₁) variant is ``geometry='conical'``.
    Raises ValueError when no s(0) in s0_range meets the wall condition (no radial field).
    """
    S = math.sin(math.radians(delta_deg))
    th = math.radians(theta_deg)
    target = math.pi / 2 + math.radians(wall_angle_passive_deg(delta_deg, phi_w_deg))

    def miss(s0):
        sol = _shoot(geometry, S, s0, th)
        if sol.status != 0 or not np.all(np.isfinite(sol.y)):
            return math.nan
        return sol.y[1, -1] - target

    grid = np.geomspace(*s0_range, 160)
    vals = [miss(s) for s in grid]
    root = None
    for i in range(len(grid) - 1):
        a, b = vals[i], vals[i + 1]
        if np.isfinite(a) and np.isfinite(b) and a * b <= 0.0:
            root = brentq(miss, grid[i], grid[i + 1], xtol=1e-13, rtol=1e-12)
            break
    if root is None:
        raise ValueError(f"no {geometry} radial stress field for delta={delta_deg}, "
                         f"phi_w={phi_w_deg}, theta={theta_deg}")
    sol = _shoot(geometry, S, root, th)
    return RadialField(geometry, delta_deg, phi_w_deg, theta_deg, root, float(sol.y[0, -1]),
                       sol.t, sol.y[0], sol.y[1])


def S_radial(theta_deg: float, delta_deg: float, phi_w_deg: float, geometry: str = "plane") -> float:
    """S_J = σ₁(outlet wall)/(ρ g B) = s(θ)(1 + sin δ)/(2 sin θ) from the radial field."""
    f = radial_stress_field(delta_deg, phi_w_deg, theta_deg, geometry)
    return f.sigma1_wall_factor / (2.0 * math.sin(math.radians(theta_deg)))
