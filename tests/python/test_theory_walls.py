"""Wall stresses: Walker's D and its bin limit, Walters' bin factor, the slice solution, the
discharge switch, Enstad-arc wall stresses and Janssen (docs/theory/hopper_theory.md §e, §f)."""
import math

import numpy as np
import pytest

from bulkflow.theory import janssen as J
from bulkflow.theory import walker as W
from bulkflow.theory.mohr import wall_angle_passive_deg


@pytest.mark.parametrize("delta,phi_w", [(35, 20), (20, 5), (45, 30), (30, 0.0)])
def test_walker_limit_theta_to_zero_is_the_bin_K(delta, phi_w):
    for state in ("active", "passive"):
        assert W.walker_D(delta, phi_w, 1e-9, state) == pytest.approx(W.walker_K_bin(delta, phi_w, state), rel=1e-9)


def test_walker_bin_K_values_and_smooth_wall():
    assert W.walker_K_bin(35, 20, "active") == pytest.approx(0.291, abs=0.0005)
    assert W.walker_K_bin(35, 20, "passive") == pytest.approx(1.923, abs=0.0005)
    # smooth wall: Rankine active/passive ratios
    s = math.sin(math.radians(30))
    assert W.walker_K_bin(30, 0.0, "active") == pytest.approx((1 - s) / (1 + s))
    assert W.walker_K_bin(30, 0.0, "passive") == pytest.approx((1 + s) / (1 - s))


def test_walters_bin_factor():
    assert W.walters_D_bin(35, 20, "active") == pytest.approx(0.277, abs=0.0005)
    assert W.walters_D_bin(35, 20, "passive") == pytest.approx(2.845, abs=0.0005)
    # smooth walls: no shear, uniform stress, Walters = Walker
    assert W.walters_D_bin(30, 0.0, "active") == pytest.approx(W.walker_K_bin(30, 0.0, "active"))


@pytest.mark.parametrize("state", ["active", "passive"])
def test_slice_solution_satisfies_the_slice_balance(state):
    rho, delta, phi_w, theta, Ht, Q = 1600.0, 20.0, 5.0, 30.0, 3.0, 2000.0
    D = W.walker_D(delta, phi_w, theta, state)
    N = W.slice_exponent(D, phi_w, theta)
    y = np.linspace(0.2, 2.8, 30)
    h = 1e-6
    sv = lambda x: W.slice_mean_vertical(x, Ht, rho, N, Q)
    lhs = y * (sv(y + h) - sv(y - h)) / (2 * h) + sv(y)
    sw = D * sv(y)
    rhs = -rho * 9.81 * y + sw + sw * math.tan(math.radians(phi_w)) / math.tan(math.radians(theta))
    assert np.allclose(lhs, rhs, rtol=1e-6, atol=1e-3)
    assert sv(np.array([Ht]))[0] == pytest.approx(Q)


def test_table_4_2_wall_stresses():
    # docs/theory/hopper_theory.md §e.4: θ = 30°, φ_w = 5°, φ = δ = 20°, ρ = 1600, surface 3 m above the apex
    y = np.array([0.5, 1.0, 2.0])
    walker = W.wall_normal_stress(y, 3.0, 1600.0, 20.0, 5.0, 30.0, "passive") / 1e3
    assert np.allclose(walker, [28.3, 30.1, 19.4], atol=0.05)
    c = math.cos(math.radians(30))
    beta = wall_angle_passive_deg(20.0, 5.0)
    arcs = W.enstad_wall_stress(y / c, 3.0 / c, 1600.0, 30.0, 20.0, beta) / 1e3
    assert np.allclose(arcs, [27.8, 37.7, 30.9], atol=0.05)


def test_discharge_switch_jumps_by_Dp_over_Da():
    args = (1600.0, 20.0, 5.0, 30.0)
    ys = 1.5
    below = W.wall_normal_stress_switch(np.array([ys - 1e-9]), 3.0, ys, *args)[0]
    above = W.wall_normal_stress_switch(np.array([ys]), 3.0, ys, *args)[0]
    ratio = W.walker_D(20, 5, 30, "passive") / W.walker_D(20, 5, 30, "active")
    assert below / above == pytest.approx(ratio, rel=1e-6)
    assert ratio > 1.5     # the discharge peak
    # switch at the surface = fully passive
    y = np.linspace(0.1, 2.9, 7)
    assert np.allclose(W.wall_normal_stress_switch(y, 3.0, 3.0, *args),
                       W.wall_normal_stress(y, 3.0, *args, state="passive"))


def test_janssen_asymptote_surface_and_ode():
    rho, b, phi_w, K = 1500.0, 0.4, 20.0, 0.4
    sv_inf, sw_inf = J.janssen_asymptote(rho, b, K, phi_w)
    assert J.janssen_vertical(200.0, rho, b, K, phi_w) == pytest.approx(sv_inf, rel=1e-9)
    assert J.janssen_wall(200.0, rho, b, K, phi_w) == pytest.approx(sw_inf, rel=1e-9)
    assert sw_inf == pytest.approx(rho * 9.81 * b / math.tan(math.radians(phi_w)))
    assert J.janssen_vertical(0.0, rho, b, K, phi_w, Q=700.0) == pytest.approx(700.0)
    # near the surface: hydrostatic
    assert J.janssen_vertical(1e-4, rho, b, K, phi_w) == pytest.approx(rho * 9.81 * 1e-4, rel=1e-3)
    # dσ/dz = ρg − K μ σ / b
    z = np.linspace(0.1, 3, 20)
    h = 1e-6
    sv = lambda x: J.janssen_vertical(x, rho, b, K, phi_w, Q=300.0)
    mu = math.tan(math.radians(phi_w))
    assert np.allclose((sv(z + h) - sv(z - h)) / (2 * h), rho * 9.81 - K * mu * sv(z) / b, rtol=1e-6)


def test_janssen_K_choices():
    assert J.K_jaky(30) == pytest.approx(0.5)
    assert J.K_rankine(30) == pytest.approx(1 / 3)
    assert J.K_walker(35, 20) == pytest.approx(0.291, abs=0.0005)
