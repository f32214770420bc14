"""Mohr-circle relations (eqs. 6.2, 6.9, the wall angle) and the flow functions (eq. 6.1, Fig. 6.11)."""
import math

import numpy as np
import pytest

from bulkflow.theory import BilinearFlowFunction, LinearFlowFunction, Material
from bulkflow.theory.mohr import (c_from_fc, delta_mod_deg, fc_from_c, k_ratio, sin_delta_mod,
                                  wall_angle_active_deg, wall_angle_passive_deg)


@pytest.mark.parametrize("phi", [10.0, 20.0, 28.6, 34.0, 40.0])
def test_fc_from_c_eq_6_9_and_back(phi):
    c = 350.0
    fc = fc_from_c(c, phi)
    assert fc == pytest.approx(2 * c * math.tan(math.radians(45 + phi / 2)))
    assert c_from_fc(fc, phi) == pytest.approx(c)
    # the uniaxial circle (0, fc) is tangent to τ = c + σ tan φ: distance centre-line = radius
    p, q = fc / 2, fc / 2
    t = math.radians(phi)
    assert (c + p * math.tan(t)) * math.cos(t) == pytest.approx(q)


def test_case_values_of_eq_6_9():
    assert fc_from_c(350, 40) == pytest.approx(1501.15, abs=0.01)
    assert fc_from_c(800, 20) == pytest.approx(2285.04, abs=0.01)
    assert fc_from_c(519, 34) == pytest.approx(1952.2, abs=0.1)
    assert fc_from_c(175, 28.6) == pytest.approx(589.5, abs=0.1)


def test_delta_mod_k_zero_is_phi_and_values():
    for phi in (15, 25, 40):
        assert delta_mod_deg(phi, 0.0) == pytest.approx(phi)
    assert delta_mod_deg(40, 0.2) == pytest.approx(44.72, abs=0.005)
    with pytest.raises(ValueError):
        sin_delta_mod(40, 1.5)


@pytest.mark.parametrize("phi,k,fc0", [(40, 0.2, 1500.0), (34, 0.62, 519.0), (28.6, 0.47, 589.0)])
def test_delta_mod_is_the_constant_angle_of_the_steady_flow_circles(phi, k, fc0):
    # circle (p, q) tangent to the IYL whose f_c = f_c0 + k σ₁ with σ₁ = p + q:
    # q = p sin φ + c cos φ, c cos φ = f_c (1 − sin φ)/2. docs/theory/hopper_theory.md §c.1: q = sin δ_mod (p + p₀)
    s = math.sin(math.radians(phi))
    sd = sin_delta_mod(phi, k)
    p0 = fc0 * (1 - s) / (2 * s + k * (1 - s))
    for p in (100.0, 1e3, 1e4, 1e5):
        # solve q = p s + (fc0 + k (p + q))(1 − s)/2 for q
        q = (p * s + (fc0 + k * p) * (1 - s) / 2) / (1 - k * (1 - s) / 2)
        assert q == pytest.approx(sd * (p + p0), rel=1e-12)


@pytest.mark.parametrize("delta,phi_w", [(35, 20), (44.7, 20), (53.7, 26), (20, 5), (43.25, 33.3)])
def test_wall_angles_satisfy_coulomb_wall_condition(delta, phi_w):
    for w in (wall_angle_passive_deg(delta, phi_w), wall_angle_active_deg(delta, phi_w)):
        lhs = math.sin(math.radians(phi_w))
        rhs = math.sin(math.radians(delta)) * math.sin(math.radians(2 * w - phi_w))
        assert lhs == pytest.approx(rhs, rel=1e-10)
    assert wall_angle_passive_deg(delta, 0.0) == 0.0
    assert wall_angle_active_deg(delta, 0.0) == 90.0


def test_k_ratio():
    assert k_ratio(30) == pytest.approx(3.0)


def test_linear_flow_function():
    ff = LinearFlowFunction(500.0, 0.4)
    assert ff(1000.0) == pytest.approx(900.0)
    s = ff.intersection_with_identity()
    assert ff(s) == pytest.approx(s)


@pytest.mark.parametrize("fc0,k", [(589.5, 0.47), (1501.0, 0.2), (519.0, 0.62)])
def test_bilinear_flow_function_fig_6_11(fc0, k):
    lin = LinearFlowFunction(fc0, k)
    bi = lin.bilinear()
    assert isinstance(bi, BilinearFlowFunction)
    assert bi(0.0) == pytest.approx(0.5 * fc0)                     # f_c0 halved
    sm = fc0 / (1 - k)
    assert bi.sigma_merge == pytest.approx(sm)
    assert bi(sm) == pytest.approx(sm) and lin(sm) == pytest.approx(sm)   # merges on f_c = σ₁
    hi = np.array([1.0001 * sm, 2 * sm, 10 * sm])
    assert np.allclose(bi(hi), lin(hi))
    lo = np.linspace(0, 0.999 * sm, 50)
    assert np.all(bi(lo) < lin(lo))
    # continuous and piecewise linear
    assert bi(sm * (1 - 1e-9)) == pytest.approx(bi(sm * (1 + 1e-9)), rel=1e-7)


def test_material_from_c0():
    m = Material.from_c0(800.0, rho=400.0, phi_deg=20.0, phi_w_deg=0.0, k=0.0)
    assert m.fc0 == pytest.approx(2285.04, abs=0.01)
    assert m.c0 == pytest.approx(800.0)
    assert m.delta_mod_deg == pytest.approx(20.0)
