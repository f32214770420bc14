"""Enstad's theory (bulkflow.theory.enstad): coefficients, eqs. 6.6-6.8, arch geometry and the
reference numbers of docs/theory/hopper_theory.md §d.8 and §i.5."""
import math

import numpy as np
import pytest

from bulkflow.theory import enstad as E
from bulkflow.theory.cases import case
from bulkflow.theory.flow_function import LinearFlowFunction
from bulkflow.theory.model import critical_width_estimates
from bulkflow.theory.mohr import delta_mod_deg, wall_angle_passive_deg


def _params(key):
    c = case(key)
    m = c.material()
    d = delta_mod_deg(m.phi_deg, m.k)
    ba, bc = E.enstad_beta(c.theta_deg, d, m.phi_w_deg, "omega_cap")
    return c, m, d, ba, bc


def test_X_is_about_7_for_case_A_and_1_for_case_B():
    # thesis §6.5.1: "X ≈ 7 for Case A and X ≈ 1 for Case B"; docs/theory/hopper_theory.md: 7.04 and 1.04
    for key, ref in (("A", 7.04), ("B", 1.04)):
        c, m, d, ba, bc = _params(key)
        assert E.X_factor(d, c.theta_deg, bc) == pytest.approx(ref, abs=0.005)


@pytest.mark.parametrize("key", ["A", "B", "polymer", "sic"])
def test_arching_solution_satisfies_ode_6_6_and_boundary_condition(key):
    c, m, d, ba, bc = _params(key)
    R = 1.7
    sol = E.arching_solution(c.theta_deg, m.phi_deg, d, ba, bc, m.k, m.fc0, m.rho, R, sigma2_R=123.0)
    assert sol(R) == pytest.approx(123.0, abs=1e-9 * max(1.0, abs(sol.c)))
    r = np.linspace(0.05, R - 0.05, 40)
    h = 1e-5
    dsdr = (sol(r + h) - sol(r - h)) / (2 * h)               # finite differences, not sol.derivative
    lhs = r * dsdr - sol.X_b * sol(r)
    scale = np.max(np.abs(sol.rhs(r)))
    assert np.max(np.abs(lhs - sol.rhs(r))) < 1e-6 * scale


@pytest.mark.parametrize("key", ["A", "polymer", "sic"])
def test_closed_form_matches_numerical_integration_of_the_slice_balance(key):
    # sigma2_bar_numeric integrates r s' = X_b s − ρgWr + G f_c(σ₁,cons(r)) with solve_ivp:
    # an independent route to eq. 6.7 (the linear flow function substituted by hand there).
    c, m, d, ba, bc = _params(key)
    R = 2.0
    sol = E.arching_solution(c.theta_deg, m.phi_deg, d, ba, bc, m.k, m.fc0, m.rho, R)
    r = np.linspace(0.1, R, 25)
    num = E.sigma2_bar_numeric(r, c.theta_deg, m.phi_deg, d, ba, bc, LinearFlowFunction(m.fc0, m.k),
                               m.rho, R)
    assert np.allclose(num, sol(r), rtol=1e-6, atol=1e-6 * np.max(np.abs(sol(r))))


def test_consolidation_stress_6_8_solves_its_ode_and_free_surface():
    c, m, d, ba, bc = _params("A")
    R = 2.0
    X = E.X_factor(d, c.theta_deg, bc)
    Y = E.Y_factor(d, c.theta_deg, bc, "sigma1")
    r = np.linspace(0.1, 1.9, 30)
    h = 1e-6
    f = lambda x: E.consolidation_stress(x, R, m.rho, c.theta_deg, d, bc)
    lhs = r * (f(r + h) - f(r - h)) / (2 * h) - X * f(r)
    assert np.allclose(lhs, -m.rho * 9.81 * Y * r, rtol=1e-6)
    assert f(np.array([R]))[0] == pytest.approx(0.0, abs=1e-9)
    # the X -> 1 limit is continuous (Case B has X = 1.04)
    near = E.consolidation_stress(0.5, R, 400, 30, 20, 0.0)
    lim = 400 * 9.81 * float(E.Y_factor(20, 30, 0.0)) * 0.5 * math.log(R / 0.5)
    assert near == pytest.approx(lim, rel=0.1)


def test_Y_readings_differ_by_1_plus_sin_delta():
    s = math.sin(math.radians(44.0))
    assert E.Y_factor(44, 30, 20, "sigma1") / E.Y_factor(44, 30, 20, "mean") == pytest.approx(1 + s)
    assert E.Y_factor(44, 30, 20, "mean") / E.Y_factor(44, 30, 20, "sigma2") == pytest.approx(1 / (1 - s))


@pytest.mark.parametrize("theta,beta", [(30, 0), (30, 24.5), (14.5, 29.5), (16, 37), (45, 10)])
def test_arch_geometry(theta, beta):
    r = 0.8
    yc, rad = E.arch_centre(r, theta, beta)
    t = math.radians(theta)
    P = np.array([r * math.sin(t), r * math.cos(t)])          # right wall point
    assert math.hypot(P[0], P[1] - yc) == pytest.approx(rad, rel=1e-12)
    # σ₁ tangent to the arc makes the angle β with the inward wall normal
    v = P - np.array([0.0, yc])
    tangent = np.array([-v[1], v[0]]) / np.linalg.norm(v)
    normal = np.array([-math.cos(t), math.sin(t)])
    assert math.degrees(math.acos(abs(tangent @ normal))) == pytest.approx(beta, abs=1e-9)
    assert E.arch_crown_height(r, theta, beta) == pytest.approx(yc + rad)
    # area between the apex and the arc = r² sin θ W (shoelace on a fine polygon)
    a = math.radians(theta + beta)
    ang = np.linspace(math.pi / 2 - a, math.pi / 2 + a, 20001)   # right wall point to left one
    arc = np.column_stack([rad * np.cos(ang), yc + rad * np.sin(ang)])
    poly = np.vstack([[0.0, 0.0], arc])
    x, y = poly[:, 0], poly[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    assert area == pytest.approx(r * r * math.sin(t) * E.W_factor(theta, beta), rel=1e-6)


def test_beta_zero_centres_the_arch_on_the_apex():
    yc, rad = E.arch_centre(0.3, 30.0, 0.0)
    assert yc == pytest.approx(0.0) and rad == pytest.approx(0.3)


def test_enstad_beta_readings():
    # Case A: ω_p(δ_mod) = 24.54° < 45 − θ/2 = 30°, so the cap does nothing
    assert E.enstad_beta(30, 44.72, 20, "omega_cap")[0] == pytest.approx(24.54, abs=0.01)
    # SiC: ω_p = 43.28° is capped at 45 − 16/2 = 37°
    d = delta_mod_deg(28.6, 0.47)
    assert E.enstad_beta(16, d, 33.3, "omega")[0] == pytest.approx(43.28, abs=0.01)
    assert E.enstad_beta(16, d, 33.3, "omega_cap") == (37.0, 37.0)
    assert E.enstad_beta(16, d, 33.3, "phiw_cap") == (33.3, 37.0)
    for reading in ("omega", "omega_cap", "phiw_cap"):
        assert E.enstad_beta(30, 20, 0.0, reading) == (0.0, 0.0)


# docs/theory/hopper_theory.md §i.5 (eq. 6.9, δ_mod, first radial term, Enstad β = min(ω, 45° − θ/2)), cm
I5 = {"A": [48.6, 51.3, 52.0, 52.2, 52.3, 52.3, 52.3], "B": [53.6, 37.9, 31.2, 24.8, 21.7, 19.7, 18.4]}
I5_H = [0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0]


@pytest.mark.parametrize("key", ["A", "B"])
def test_enstad_widths_table_i5(key):
    c = case(key)
    got = [100 * critical_width_estimates(c.hopper(H), c.material())["enstad"] for H in I5_H]
    assert np.allclose(got, I5[key], atol=0.051), got


def test_case_B_enstad_falls_below_30_cm_at_about_1_06_m():
    c = case("B")
    from scipy.optimize import brentq
    H = brentq(lambda H: critical_width_estimates(c.hopper(H), c.material())["enstad"] - 0.30, 0.6, 2.0)
    assert H == pytest.approx(1.06, abs=0.01)


def test_critical_radius_is_the_first_zero_of_sigma2():
    c, m, d, ba, bc = _params("A")
    R = 2.0 / math.cos(math.radians(30))
    sol = E.arching_solution(c.theta_deg, m.phi_deg, d, ba, bc, m.k, m.fc0, m.rho, R)
    rs = E.critical_radius(sol)
    assert abs(sol(rs)) < 1e-6 * m.fc0
    r = np.linspace(1e-4, rs * 0.999, 500)
    assert np.all(sol(r) < 0)


def test_no_flow_when_the_arch_is_stable_everywhere():
    # polymer, reading c0, H = 0.5 m: stable at every outlet below the surface (docs/theory/hopper_theory.md §i.2)
    c = case("polymer")
    est = critical_width_estimates(c.hopper(0.5), c.material("c0"))
    assert math.isinf(est["enstad"])
