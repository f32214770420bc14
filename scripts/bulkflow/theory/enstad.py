"""Enstad's (1975) arching theory for plane-flow (wedge) hoppers, thesis §6.1 eqs. 6.2, 6.6–6.8.

Enstad's assumptions (thesis §6.1, Table 1.1): in the converging section the major principal
stress σ₁ acts along circular arcs with constant magnitude on each arc; every arc meets the walls
at the angle β to the wall normal and is centred on the hopper axis (not at the apex unless
β = 0). Vertical equilibrium of the slice between two arcs gives an ODE in the wall distance r
(measured from the apex along the wall).

* Consolidation (flowing, passive) state: σ₁ = K_δ σ₂ on the modified EYL with δ = δ_mod (eq. 6.2,
  offset p₀ neglected as in the thesis) gives eq. 6.8:
  σ(r) = ρgYr/(X − 1) + (σ_R − ρgYR/(X − 1)) (r/R)^X.
* Arching (incipient failure) state: σ̄₁ = K_φ σ̄₂ + f_c(r), f_c(r) = f_c0 + k σ₁,cons(r) (eq. 6.1),
  gives eq. 6.6  r dσ̄₂/dr − X_b σ̄₂ = −ρgY_b r + Z_b (r/R)^X + Z_0 with solution 6.7
  σ̄₂ = a (r/R)^X + b (r/R)^{X_b} + c (r/R) + d.
* Critical outlet: the first root r* of σ̄₂(r) = 0 on (0, R); B_crit = 2 r* sin θ (thesis: "an
  iterative procedure ... to find r_outlet such that the minor stress at the outlet is zero").

The coefficients X, Y, X_b, Y_b, Z_b, Z_0, a, b, c, d are not printed in the thesis; they are
re-derived for plane flow (m = 0) in docs/theory/hopper_theory.md §d.1–d.5 (the plane
form of Arnold & McLean's coefficients) and re-derived again for this module from the slice
balance (§d.2): r σ₂' = −σ₂ − ρgWr + [σ₁ cos β sin α − σ₂ sin β cos α]/sin θ, α = θ + β.

Which β (thesis: "depends on φ_w and θ"; "the arch gets the maximum lift from the walls"):
see :func:`enstad_beta`; default ``omega_cap`` = min(ω_p(δ_mod), 45° − θ/2) (docs/theory/hopper_theory.md §d.6).

Degenerate exponents (X = 1, X_b = 1, X = X_b) are handled by nudging the exponent by 1e-6
(the solution is continuous in them); the numerical integrator :func:`sigma2_bar_numeric` is the
independent check.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .mohr import k_ratio, wall_angle_passive_deg

__all__ = [
    "G_STANDARD", "enstad_beta", "arch_alpha_deg", "arch_radius", "arch_centre_height",
    "arch_centre", "arch_crown_height", "W_factor", "X_factor", "Y_factor", "lift_factor",
    "consolidation_stress", "consolidation_first_term", "ArchingSolution", "arching_solution",
    "critical_radius", "critical_width", "sigma2_bar_numeric",
]

G_STANDARD = 9.81   #: gravity used throughout (thesis; docs/theory/hopper_theory.md conventions)
_EPS_EXP = 1e-6


def _rad(a):
    return np.radians(a)


# ---- β ----------------------------------------------------------------------------------------
def enstad_beta(theta_deg: float, delta_deg: float, phi_w_deg: float, reading: str = "omega_cap"):
    """(β_arch, β_cons) in degrees for Enstad's arcs (docs/theory/hopper_theory.md §d.6).

    readings
      ``omega``      β = ω_p(δ) for both the arch and the consolidation field;
      ``omega_cap``  β = min(ω_p(δ), 45° − θ/2) for both (default). 45° − θ/2 is the β that
                     maximises the wall lift σ̄₁ cos β sin(θ + β) of an unconfined arch, Enstad's
                     "maximum lift" assumption quoted in thesis §6.5.3;
      ``phiw_cap``   arch β = min(φ_w, 45° − θ/2) (an unconfined arch has wall obliquity β, so
                     friction needs β ≤ φ_w); consolidation β as ``omega_cap``.
    φ_w = 0 gives β = 0 in every reading (arcs centred on the apex, as in the thesis FEM).
    """
    omega = wall_angle_passive_deg(delta_deg, phi_w_deg)
    cap = 45.0 - 0.5 * theta_deg
    if reading == "omega":
        return omega, omega
    if reading == "omega_cap":
        b = min(omega, cap)
        return b, b
    if reading == "phiw_cap":
        return min(phi_w_deg, cap), min(omega, cap)
    raise ValueError(f"unknown Enstad beta reading {reading!r} (omega, omega_cap, phiw_cap)")


# ---- arc geometry (docs/theory/hopper_theory.md §d.1) ----------------------------------------------------
def arch_alpha_deg(theta_deg, beta_deg):
    """α = θ + β: rise of the arc tangent above the horizontal at the wall; the arc subtends 2α."""
    return theta_deg + beta_deg


def arch_radius(r, theta_deg, beta_deg):
    """Radius of Enstad's arc through the wall points at wall distance r: r sin θ / sin(θ + β)."""
    return r * np.sin(_rad(theta_deg)) / np.sin(_rad(theta_deg + beta_deg))


def arch_centre_height(r, theta_deg, beta_deg):
    """Height of the arc centre above the apex (on the axis): r sin β / sin(θ + β).

    β = 0 puts the centre at the apex (the thesis FEM arch, §6.2); β > 0 lifts it.
    """
    return r * np.sin(_rad(beta_deg)) / np.sin(_rad(theta_deg + beta_deg))


def arch_centre(r, theta_deg, beta_deg):
    """(centre height above the apex, arc radius) of Enstad's arch for an outlet at wall distance r.

    For scene generators that place the outlet arc on Enstad's arch: the arc through the two wall
    points (±r sin θ, r cos θ) with σ₁ tangent to it at the angle β to the wall normal. With
    ``r = outlet_width / (2 sin θ)`` the arc's chord is the outlet. The arch bulges upward: its
    crown, where it crosses the axis, is at centre height + radius (:func:`arch_crown_height`).
    β = 0 gives (0, r): the arc centred on the apex used by the thesis FEM (§6.2).
    """
    return arch_centre_height(r, theta_deg, beta_deg), arch_radius(r, theta_deg, beta_deg)


def arch_crown_height(r, theta_deg, beta_deg):
    """Height above the apex where the arc crosses the axis: r (sin β + sin θ)/sin(θ + β)."""
    c, a = arch_centre(r, theta_deg, beta_deg)
    return c + a


def W_factor(theta_deg, beta_deg):
    """W(θ, β) = [α sin θ + sin β sin α]/sin²α (α = θ + β in radians in the first term).

    The area between the apex and the arc through the wall points at r is r² sin θ · W
    (docs/theory/hopper_theory.md §d.1); it enters the weight term of the slice balance.
    """
    a = _rad(theta_deg + beta_deg)
    t = _rad(theta_deg)
    b = _rad(beta_deg)
    return (a * np.sin(t) + np.sin(b) * np.sin(a)) / np.sin(a) ** 2


def X_factor(angle_deg, theta_deg, beta_deg):
    """X = [sin δ/(1 − sin δ)] · [sin(2β + θ)/sin θ + 1] (docs/theory/hopper_theory.md §d.3; thesis eq. 6.8).

    With δ = δ_mod this is eq. 6.8's exponent; with the internal friction angle φ it is X_b of
    eq. 6.6. Thesis §6.5.1: X ≈ 7 for Case A, X ≈ 1 for Case B.
    """
    s = np.sin(_rad(angle_deg))
    return s / (1.0 - s) * (np.sin(_rad(2.0 * beta_deg + theta_deg)) / np.sin(_rad(theta_deg)) + 1.0)


def Y_factor(delta_deg, theta_deg, beta_deg, quantity: str = "sigma1"):
    """Y of eq. 6.8 for the stress the equation is written in (docs/theory/hopper_theory.md §d.3 trap).

    ``sigma1``: Y = K_δ W (default; what the flow function f_c(σ₁) needs);
    ``mean``  : Y = W/(1 − sin δ) (Arnold & McLean's Y, σ = mean stress);
    ``sigma2``: Y = W.
    """
    w = W_factor(theta_deg, beta_deg)
    s = np.sin(_rad(delta_deg))
    if quantity == "sigma1":
        return (1.0 + s) / (1.0 - s) * w
    if quantity == "mean":
        return w / (1.0 - s)
    if quantity == "sigma2":
        return w
    raise ValueError(f"unknown quantity {quantity!r} (sigma1, mean, sigma2)")


def lift_factor(theta_deg, beta_deg):
    """G = cos β sin(θ + β)/sin θ: the wall-lift factor of σ̄₁ in the slice balance (§d.2/§d.4)."""
    return np.cos(_rad(beta_deg)) * np.sin(_rad(theta_deg + beta_deg)) / np.sin(_rad(theta_deg))


def _nudge(x, away_from=1.0):
    if abs(x - away_from) < _EPS_EXP:
        return away_from + (_EPS_EXP if x >= away_from else -_EPS_EXP)
    return x


# ---- consolidation stresses, eq. 6.8 ---------------------------------------------------------
def consolidation_stress(r, R, rho, theta_deg, delta_deg, beta_deg, quantity="sigma1",
                         sigma_R=0.0, g=G_STANDARD):
    """Eq. 6.8 (full, with the surface term): passive consolidation stress at wall distance r.

    σ(r) = ρgYr/(X − 1) + (σ_R − ρgYR/(X − 1)) (r/R)^X, X = X(δ, θ, β), Y per `quantity`.
    R: apex → free surface along the wall; σ_R: the same stress at R (0 for a free surface).
    X = 1 uses its limit ρgYr ln(R/r) + σ_R r/R. Assumes Enstad's arcs and δ = δ_mod.
    """
    r = np.asarray(r, dtype=float)
    X = float(X_factor(delta_deg, theta_deg, beta_deg))
    Y = float(Y_factor(delta_deg, theta_deg, beta_deg, quantity))
    if abs(X - 1.0) < 1e-9:
        with np.errstate(divide="ignore", invalid="ignore"):
            return rho * g * Y * r * np.log(R / r) + sigma_R * r / R
    return rho * g * Y * r / (X - 1.0) + (sigma_R - rho * g * Y * R / (X - 1.0)) * (r / R) ** X


def consolidation_first_term(r, rho, theta_deg, delta_deg, beta_deg, quantity="sigma1",
                             g=G_STANDARD):
    """First radial term of eq. 6.8, ρgYr/(X − 1): what the thesis used for the consolidation
    stress near the outlet for Jenike and McLean (§6.5.3). Only meaningful for X > 1 (returns
    inf for X ≤ 1: the surface term then dominates everywhere, e.g. Case B)."""
    X = float(X_factor(delta_deg, theta_deg, beta_deg))
    Y = float(Y_factor(delta_deg, theta_deg, beta_deg, quantity))
    if X <= 1.0:
        return np.full_like(np.asarray(r, dtype=float), np.inf)
    return rho * g * Y * np.asarray(r, dtype=float) / (X - 1.0)


# ---- arching state, eqs. 6.6 and 6.7 ----------------------------------------------------------
@dataclass(frozen=True)
class ArchingSolution:
    """σ̄₂(r) = a (r/R)^X + b (r/R)^{X_b} + c (r/R) + d (thesis eq. 6.7) and its ODE data (6.6)."""

    R: float
    X: float
    X_b: float
    Y: float        #: consolidation Y (σ₁ version), with β_cons
    W: float        #: arch W, with β_arch
    G: float        #: lift factor, with β_arch
    Y_b: float
    Z_b: float
    Z_0: float
    a: float
    b: float
    c: float
    d: float
    rho: float
    g: float
    beta_arch: float
    beta_cons: float

    def __call__(self, r):
        x = np.asarray(r, dtype=float) / self.R
        return self.a * x ** self.X + self.b * x ** self.X_b + self.c * x + self.d

    def derivative(self, r):
        """dσ̄₂/dr of eq. 6.7."""
        r = np.asarray(r, dtype=float)
        x = r / self.R
        return (self.a * self.X * x ** (self.X - 1) + self.b * self.X_b * x ** (self.X_b - 1)
                + self.c) / self.R

    def rhs(self, r):
        """Right-hand side of eq. 6.6: −ρgY_b r + Z_b (r/R)^X + Z_0."""
        r = np.asarray(r, dtype=float)
        return -self.rho * self.g * self.Y_b * r + self.Z_b * (r / self.R) ** self.X + self.Z_0


def arching_solution(theta_deg, phi_deg, delta_deg, beta_arch_deg, beta_cons_deg, k, fc0, rho, R,
                     sigma2_R=0.0, sigma1_cons_R=0.0, g=G_STANDARD) -> ArchingSolution:
    """Coefficients of eqs. 6.6/6.7 (docs/theory/hopper_theory.md §d.4, re-derived).

    X_b = X(φ, θ, β_arch); W, G with β_arch; X, Y (σ₁ version) of the consolidation field with
    δ and β_cons; Y_b = W − kGY/(X − 1); Z_b = kG(σ₁,R − ρgYR/(X − 1)); Z_0 = G f_c0;
    a = Z_b/(X − X_b); c = ρgY_bR/(X_b − 1); d = −Z_0/X_b; b = σ̄₂(R) − a − c − d.
    sigma2_R: σ̄₂ at the surface (0: free surface); sigma1_cons_R: consolidation σ₁ there.
    """
    X = _nudge(float(X_factor(delta_deg, theta_deg, beta_cons_deg)))
    X_b = _nudge(float(X_factor(phi_deg, theta_deg, beta_arch_deg)))
    X_b = _nudge(X_b, X) if k != 0.0 else X_b
    Y = float(Y_factor(delta_deg, theta_deg, beta_cons_deg, "sigma1"))
    W = float(W_factor(theta_deg, beta_arch_deg))
    G = float(lift_factor(theta_deg, beta_arch_deg))
    Y_b = W - k * G * Y / (X - 1.0)
    Z_b = k * G * (sigma1_cons_R - rho * g * Y * R / (X - 1.0))
    Z_0 = G * fc0
    a = Z_b / (X - X_b) if k != 0.0 else 0.0
    c = rho * g * Y_b * R / (X_b - 1.0)
    d = -Z_0 / X_b
    b = sigma2_R - a - c - d
    return ArchingSolution(R=R, X=X, X_b=X_b, Y=Y, W=W, G=G, Y_b=Y_b, Z_b=Z_b, Z_0=Z_0,
                           a=a, b=b, c=c, d=d, rho=rho, g=g,
                           beta_arch=beta_arch_deg, beta_cons=beta_cons_deg)


def critical_radius(sol, n_grid: int = 4000) -> float:
    """r*: the first root of σ̄₂(r) = 0 on (0, R) (docs/theory/hopper_theory.md §d.5).

    Outlets at wall distance r_o < r* arch (no flow). Returns inf if σ̄₂ < 0 on all of (0, R)
    (an arch is stable at any outlet below the surface), 0 if σ̄₂(0+) ≥ 0 (no cohesion).
    Grid scan (geometric near the apex + uniform) then brentq to 1e-12 R.
    """
    R = sol.R
    if sol.d >= 0.0:
        return 0.0
    r = np.unique(np.concatenate([R * np.geomspace(1e-9, 1.0, n_grid // 2),
                                  R * np.linspace(0.0, 1.0, n_grid // 2 + 1)[1:]]))
    # the surface r = R itself is excluded: there σ̄₂ = σ_R = 0 by the boundary condition, which
    # is not an arch failure (σ̄₂ reaching 0 only at R means stable at every outlet below)
    r = r[r < R * (1.0 - 1e-9)]
    s = sol(r)
    pos = np.nonzero(s >= 0.0)[0]
    if pos.size == 0:
        return math.inf
    i = pos[0]
    if i == 0:
        return float(r[0])
    if s[i] == 0.0:
        return float(r[i])
    return brentq(lambda x: float(sol(x)), r[i - 1], r[i], xtol=1e-12 * R, rtol=1e-14)


def critical_width(theta_deg, phi_deg, delta_deg, phi_w_deg, k, fc0, rho, R, beta="omega_cap",
                   g=G_STANDARD, sigma2_R=0.0) -> float:
    """Enstad's critical outlet width B = 2 r* sin θ (m) for a free surface at wall distance R.

    ``beta``: a reading for :func:`enstad_beta` or a number (degrees, used for arch and
    consolidation). Returns inf when no outlet below the surface flows.
    """
    if isinstance(beta, str):
        ba, bc = enstad_beta(theta_deg, delta_deg, phi_w_deg, beta)
    else:
        ba = bc = float(beta)
    sol = arching_solution(theta_deg, phi_deg, delta_deg, ba, bc, k, fc0, rho, R,
                           sigma2_R=sigma2_R, g=g)
    return 2.0 * critical_radius(sol) * math.sin(math.radians(theta_deg))


def sigma2_bar_numeric(r_eval, theta_deg, phi_deg, delta_deg, beta_arch_deg, beta_cons_deg,
                       flow_function, rho, R, sigma2_R=0.0, sigma1_cons_R=0.0, g=G_STANDARD,
                       consolidation=None):
    """σ̄₂(r) by integrating the slice balance numerically from r = R down (solve_ivp, RK45).

    r σ̄₂' = X_b σ̄₂ − ρgWr + G f_c(σ₁,cons(r)), the arching ODE before the linear flow function
    is substituted: any flow function f_c(σ₁) (e.g. the bilinear one of thesis Fig. 6.11) works.
    ``consolidation``: callable r -> σ₁,cons(r); default eq. 6.8 (σ₁ version, β_cons).
    Independent check of :func:`arching_solution` for linear flow functions.
    """
    X_b = float(X_factor(phi_deg, theta_deg, beta_arch_deg))
    W = float(W_factor(theta_deg, beta_arch_deg))
    G = float(lift_factor(theta_deg, beta_arch_deg))
    if consolidation is None:
        def consolidation(r):
            return consolidation_stress(r, R, rho, theta_deg, delta_deg, beta_cons_deg,
                                        "sigma1", sigma1_cons_R, g)

    def f(r, y):
        return [(X_b * y[0] - rho * g * W * r + G * float(flow_function(consolidation(r)))) / r]

    r_eval = np.atleast_1d(np.asarray(r_eval, dtype=float))
    order = np.argsort(-r_eval)
    sol = solve_ivp(f, (R, float(r_eval.min())), [sigma2_R], t_eval=r_eval[order],
                    rtol=1e-10, atol=1e-8, method="DOP853")
    out = np.empty_like(r_eval)
    out[order] = sol.y[0]
    return out
