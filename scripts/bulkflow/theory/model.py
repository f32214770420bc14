"""High-level API: a material, a wedge hopper, and every critical-width estimate at once.

    from bulkflow.theory import Material, Hopper, critical_width_estimates
    m = Material(rho=400.0, phi_deg=20.0, phi_w_deg=0.0, k=0.0, fc0=2285.0)
    h = Hopper(theta_deg=30.0, height=2.0)
    est = critical_width_estimates(h, m)
    est["mclean"], est["jenike"], est["enstad"]          # outlet widths B (m), B = 2 r_out sin θ

These names are a stable interface (other code brackets its searches with them); new keys may be
added to the result, existing ones keep their meaning.

Geometry: `Hopper.height` is the vertical height of the horizontal free surface above the hopper
APEX (the virtual apex of the wedge), so R = H/cos θ along the wall (docs/theory/hopper_theory.md §d.3).
(The scene generator bulkflow.scenes.wedge_hopper measures its `height` above the outlet instead.)
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.optimize import brentq

from . import enstad, jenike, mclean
from .flow_function import BilinearFlowFunction, LinearFlowFunction
from .mohr import c_from_fc, delta_mod_deg, fc_from_c, wall_angle_passive_deg

__all__ = ["Material", "Hopper", "critical_width_estimates", "enstad_outlet_arch",
           "CONSOLIDATION_ROUTES", "DEFAULT_READINGS"]

G_STANDARD = 9.81
CONSOLIDATION_ROUTES = ("first_term", "full", "radial", "at_enstad")
DEFAULT_READINGS = {
    "jenike_beta": "theta_plus_omega",
    "enstad_beta": "omega_cap",
    "consolidation": "first_term",
}


@dataclass(frozen=True)
class Material:
    """A cohesive bulk solid (SI units, angles in degrees).

    rho: bulk density (kg/m³), used at the outlet and everywhere; phi_deg: internal friction
    angle φ (constant, thesis §6.1); phi_w_deg: wall friction angle; k: flow-function slope;
    fc0: unconfined yield strength at zero consolidation (Pa), f_c = f_c0 + k σ₁ (eq. 6.1);
    E, nu: elastic constants (not used by the theories; carried for scene generators);
    flow: "linear" (eq. 6.1) or "bilinear" (thesis Fig. 6.11: f_c0/2 at σ₁ = 0, merging with
    the linear function where it meets f_c = σ₁).
    """

    rho: float
    phi_deg: float
    phi_w_deg: float
    k: float
    fc0: float
    E: float = 10e6
    nu: float = 0.2
    flow: str = "linear"
    name: str = ""

    @classmethod
    def from_c0(cls, c0: float, *, rho: float, phi_deg: float, phi_w_deg: float, k: float,
                **kw) -> "Material":
        """Build from the cohesion c0 at zero consolidation, f_c0 = 2 c0 cos φ/(1 − sin φ) (eq. 6.9)."""
        return cls(rho=rho, phi_deg=phi_deg, phi_w_deg=phi_w_deg, k=k, fc0=fc_from_c(c0, phi_deg), **kw)

    @property
    def c0(self) -> float:
        """Cohesion at zero consolidation from f_c0 by inverting eq. 6.9."""
        return c_from_fc(self.fc0, self.phi_deg)

    @property
    def delta_mod_deg(self) -> float:
        """Enstad's modified effective angle of internal friction, eq. 6.2."""
        return delta_mod_deg(self.phi_deg, self.k)

    @property
    def flow_function(self):
        if self.flow == "linear":
            return LinearFlowFunction(self.fc0, self.k)
        if self.flow == "bilinear":
            return BilinearFlowFunction(self.fc0, self.k, 0.5)
        raise ValueError(f"unknown flow function {self.flow!r} (linear, bilinear)")

    def replace(self, **kw) -> "Material":
        d = asdict(self)
        d.update(kw)
        return Material(**d)


@dataclass(frozen=True)
class Hopper:
    """A plane-flow (wedge) hopper filled to a horizontal free surface.

    theta_deg: half-angle from the vertical; height: vertical height of the free surface above
    the APEX (m); outlet_width: B (m), optional (for flow questions and discharge rates);
    length: outlet length l (m) for Beverloo (None: per unit length of a long slot).
    """

    theta_deg: float
    height: float
    outlet_width: float | None = None
    length: float | None = None

    @classmethod
    def from_scene(cls, theta_deg: float, outlet_width: float, height_above_outlet: float,
                   length: float | None = None) -> "Hopper":
        """The hopper of a `bulkflow.scenes.wedge_hopper.WedgeHopper` scene: that generator
        measures its `height` from the outlet line y = B/(2 tan θ) to the free surface, so the
        surface is B/(2 tan θ) + height above the apex (for both its arc and flat bottoms)."""
        apex = 0.5 * outlet_width / math.tan(math.radians(theta_deg))
        return cls(theta_deg=theta_deg, height=apex + height_above_outlet,
                   outlet_width=outlet_width, length=length)

    @property
    def R(self) -> float:
        """Apex → free surface along the wall: H / cos θ."""
        return self.height / math.cos(math.radians(self.theta_deg))

    def outlet_radius(self, B: float | None = None) -> float:
        """Wall distance of the outlet edge, r_out = B/(2 sin θ)."""
        B = self.outlet_width if B is None else B
        return B / (2.0 * math.sin(math.radians(self.theta_deg)))

    def width_at(self, r: float) -> float:
        """Outlet width B = 2 r sin θ for an outlet edge at wall distance r."""
        return 2.0 * r * math.sin(math.radians(self.theta_deg))

    def __post_init__(self):
        # θ = 0 is a vertical channel: no apex, no radial field, r_out = B/(2 sin θ) infinite.
        # The wedge theories have no limit there, so say so instead of dividing by zero.
        if not 0.0 < self.theta_deg < 90.0:
            raise ValueError(f"hopper half-angle theta = {self.theta_deg} deg: the wedge theories need "
                             "0 < theta < 90 (theta = 0 is a vertical channel without an apex)")
        if not self.height > 0.0:
            raise ValueError(f"hopper height = {self.height} m: must be > 0 (above the apex)")

    def replace(self, **kw) -> "Hopper":
        d = asdict(self)
        d.update(kw)
        return Hopper(**d)


def _enstad_width_numeric(h: Hopper, m: Material, ba: float, bc: float, delta: float, g: float):
    """Enstad with a non-linear flow function: numerical ODE (eq. 6.6 before substitution)."""
    R = h.R
    r = R * np.linspace(1e-4, 1.0, 2001)[:-1]     # the surface (σ̄₂ = 0 by the BC) excluded
    s2 = enstad.sigma2_bar_numeric(r, h.theta_deg, m.phi_deg, delta, ba, bc, m.flow_function,
                                   m.rho, R, g=g)
    pos = np.nonzero(s2 >= 0.0)[0]
    if pos.size == 0:
        return math.inf, math.nan
    i = pos[0]
    if i == 0:
        return 0.0, 0.0
    # linear interpolation on a fine grid (2000 intervals)
    rs = r[i - 1] - s2[i - 1] * (r[i] - r[i - 1]) / (s2[i] - s2[i - 1])
    return float(h.width_at(rs)), float(rs)


def critical_width_estimates(hopper: Hopper, material: Material, *,
                             jenike_beta: str = DEFAULT_READINGS["jenike_beta"],
                             enstad_beta: str = DEFAULT_READINGS["enstad_beta"],
                             consolidation: str = DEFAULT_READINGS["consolidation"],
                             g: float = G_STANDARD) -> dict:
    """McLean, Jenike and Enstad critical outlet widths (m) with the readings used.

    Result keys (widths in metres, inf = no flow at any outlet / no arch-free width):
      'mclean', 'jenike', 'enstad'   B_crit = 2 r_out sin θ; the outlet flows if B > B_crit;
      'assumptions'                  the readings (dict, strings);
      'delta_mod_deg', 'omega_p_deg', 'beta_jenike_deg', 'beta_enstad_arch_deg',
      'beta_enstad_cons_deg', 'X', 'X_b', 'Y', 'W', 'S' (σ₁/(ρgB) at the outlet for
      Jenike/McLean, nan when not a constant), 'H_mclean', 'H_jenike' (= sin 2β),
      'fc0', 'fc_mclean', 'fc_jenike' (f_c at their widths), 'sigma1_outlet_mclean',
      'sigma1_outlet_jenike', 'r_star' (Enstad), 'sigma1_cons_enstad' and 'fc_enstad'
      (consolidation σ₁ and f_c at Enstad's critical arch), 'R', 'jenike_by_beta' (Jenike under
      every β reading), 'notes' (list of warnings), and if the hopper has an outlet width: 'outlet_width' and 'flows'
      ({theory: outlet_width > B_crit}).

    Readings (docs/theory/hopper_theory.md §c.2, §c.4, §d.6; defaults in :data:`DEFAULT_READINGS`):
      jenike_beta   see :data:`bulkflow.theory.jenike.JENIKE_BETA_READINGS` (default θ + ω_p,
                    the one that matches the thesis's Case B statements);
      enstad_beta   omega | omega_cap (default) | phiw_cap;
      consolidation consolidation σ₁ near the outlet for Jenike and McLean:
                    first_term  first radial term of eq. 6.8 at r_out (the thesis's choice,
                                §6.5.3; Enstad β_cons); when X ≤ 1 and k > 0 it is meaningless
                                and 'full' is used instead (recorded in the assumptions);
                    full        eq. 6.8 with its free-surface term at r_out (height dependent);
                    radial      Jenike's plane radial stress field;
                    at_enstad   one f_c, taken at Enstad's critical arch, shared by both.
    Everywhere: δ = δ_mod (eq. 6.2), passive consolidation, ρ constant, g = 9.81, free surface.
    """
    m, h = material, hopper
    if consolidation not in CONSOLIDATION_ROUTES:
        raise ValueError(f"unknown consolidation route {consolidation!r}; one of {CONSOLIDATION_ROUTES}")
    theta = h.theta_deg
    delta = m.delta_mod_deg
    omega = wall_angle_passive_deg(delta, m.phi_w_deg)
    bj = jenike.jenike_beta(theta, delta, m.phi_w_deg, jenike_beta)
    ba, bc = enstad.enstad_beta(theta, delta, m.phi_w_deg, enstad_beta)
    R = h.R
    ff = m.flow_function
    sin_t = math.sin(math.radians(theta))
    assumptions = {
        "delta": "delta_mod (thesis eq. 6.2) for the consolidation field and the Jenike/Enstad beta",
        "jenike_beta": jenike_beta,
        "enstad_beta": enstad_beta,
        "consolidation": consolidation,
        "consolidation_state": "passive (flowing), Enstad arcs, sigma1 version of eq. 6.8, free surface",
        "flow_function": m.flow,
        "height": "vertical height of the free surface above the hopper apex; R = H/cos(theta)",
        "g": f"{g} m/s^2, rho constant",
    }

    # ---- Enstad -------------------------------------------------------------------------
    sol = enstad.arching_solution(theta, m.phi_deg, delta, ba, bc, m.k, m.fc0, m.rho, R, g=g)
    if m.flow == "linear":
        r_star = enstad.critical_radius(sol)
        B_enstad = h.width_at(r_star)
    else:
        B_enstad, r_star = _enstad_width_numeric(h, m, ba, bc, delta, g)
    if np.isfinite(r_star) and r_star > 0:
        s1_enstad = float(enstad.consolidation_stress(r_star, R, m.rho, theta, delta, bc, "sigma1", 0.0, g))
        fc_enstad = float(ff(s1_enstad))
    else:
        s1_enstad = fc_enstad = math.nan

    # ---- consolidation near the outlet for Jenike and McLean ------------------------------
    route = consolidation
    S = math.nan
    notes = []
    if route == "first_term":
        S = jenike.S_first_term(theta, delta, bc)
        if not math.isfinite(S):
            if m.k != 0.0:
                route = "full"
                assumptions["consolidation"] = "full (first_term requested but X <= 1 makes it meaningless)"
            else:
                assumptions["consolidation"] = "first_term (irrelevant: k = 0 and X <= 1)"
        elif float(enstad.X_factor(delta, theta, bc)) < 1.5:
            notes.append(f"X = {float(enstad.X_factor(delta, theta, bc)):.3g} is close to 1: the first radial "
                         "term of eq. 6.8 overstates the consolidation stress (the free-surface term "
                         "dominates)" + ("; irrelevant here since k = 0" if m.k == 0.0 else ""))
    elif route == "radial":
        try:
            S = jenike.S_radial(theta, delta, m.phi_w_deg, "plane")
        except ValueError:
            S = math.nan
            assumptions["consolidation"] = "radial (no plane radial field found: results nan)"

    def sigma1_of_B(B):
        if route == "full":
            r = min(B / (2.0 * sin_t), R)
            return float(enstad.consolidation_stress(r, R, m.rho, theta, delta, bc, "sigma1", 0.0, g))
        if not math.isfinite(S):
            return 0.0 if m.k == 0.0 else math.inf
        return S * m.rho * g * B

    H_m = mclean.mclean_H(theta)
    H_j = jenike.H_from_beta(bj)

    def width(H):
        if route == "at_enstad":
            return H * fc_enstad / (m.rho * g)
        if m.flow == "linear" and route != "full" and (math.isfinite(S) or m.k == 0.0):
            return jenike.critical_width_closed_form(m.fc0, m.k, m.rho, H, S if math.isfinite(S) else 0.0, g)
        return jenike.critical_width_general(ff, m.rho, H, sigma1_of_B, g)

    def checked_width(H, label):
        # A thin arch needs sin 2β ≥ 0: β = θ + ω_p > 90° (a wall rougher than the material,
        # φ_w near or above δ, on a steep hopper) leaves eq. 6.4 without an arch; its width
        # would come out negative, which is no width at all.
        if H < 0.0:
            notes.append(f"{label}: sin 2beta = {H:.3g} < 0 (beta > 90 deg, wall friction {m.phi_w_deg} deg "
                         f"against delta {delta:.3g} deg): no thin arch, width nan")
            return math.nan
        return width(H)

    B_mclean = width(H_m)
    B_jenike = checked_width(H_j, "jenike")
    by_beta = {}
    for reading in jenike.JENIKE_BETA_READINGS:
        H_r = jenike.H_from_beta(jenike.jenike_beta(theta, delta, m.phi_w_deg, reading))
        by_beta[reading] = width(H_r) if H_r >= 0.0 else math.nan

    def s1_at(B):
        if not math.isfinite(B):
            return math.nan
        if route == "at_enstad":
            return s1_enstad
        return sigma1_of_B(B)

    X = float(enstad.X_factor(delta, theta, bc))
    out = {
        "mclean": B_mclean,
        "jenike": B_jenike,
        "enstad": B_enstad,
        "assumptions": assumptions,
        "delta_mod_deg": delta,
        "omega_p_deg": omega,
        "beta_jenike_deg": bj,
        "beta_enstad_arch_deg": ba,
        "beta_enstad_cons_deg": bc,
        "X": X,
        "X_b": float(enstad.X_factor(m.phi_deg, theta, ba)),
        "Y": float(enstad.Y_factor(delta, theta, bc, "sigma1")),
        "W": float(enstad.W_factor(theta, ba)),
        "S": S if route in ("first_term", "radial") else math.nan,
        "H_mclean": H_m,
        "H_jenike": H_j,
        "fc0": m.fc0,
        "c0": m.c0,
        "sigma1_outlet_mclean": s1_at(B_mclean),
        "sigma1_outlet_jenike": s1_at(B_jenike),
        "fc_mclean": float(ff(s1_at(B_mclean))) if math.isfinite(B_mclean) else math.nan,
        "fc_jenike": float(ff(s1_at(B_jenike))) if math.isfinite(B_jenike) else math.nan,
        "r_star": r_star,
        "sigma1_cons_enstad": s1_enstad,
        "fc_enstad": fc_enstad,
        "R": R,
        "height": h.height,
        "theta_deg": theta,
        "jenike_by_beta": by_beta,
        "notes": notes,
    }
    if h.outlet_width is not None:
        out["outlet_width"] = h.outlet_width
        out["flows"] = {key: bool(h.outlet_width > out[key]) for key in ("mclean", "jenike", "enstad")}
    return out


def enstad_outlet_arch(hopper: Hopper, material: Material, outlet_width: float | None = None,
                       enstad_beta: str = DEFAULT_READINGS["enstad_beta"]) -> dict:
    """Enstad's arch over an outlet, for scene generators that put the outlet arc on it.

    Returns {'beta_deg', 'r_wall' (wall distance of the outlet edges), 'centre_height' (of the arc
    centre above the apex, on the axis), 'radius', 'crown_height' (above the apex)}; β is the
    arch β of :func:`bulkflow.theory.enstad.enstad_beta` with δ = δ_mod. β = 0 (smooth walls)
    gives the apex-centred arc of the thesis FEM.
    """
    B = hopper.outlet_width if outlet_width is None else outlet_width
    if B is None:
        raise ValueError("enstad_outlet_arch: no outlet width")
    ba, _ = enstad.enstad_beta(hopper.theta_deg, material.delta_mod_deg, material.phi_w_deg, enstad_beta)
    r = hopper.outlet_radius(B)
    c, a = enstad.arch_centre(r, hopper.theta_deg, ba)
    return {"beta_deg": ba, "r_wall": r, "centre_height": float(c), "radius": float(a),
            "crown_height": float(c + a)}
