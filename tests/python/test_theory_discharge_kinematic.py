"""Beverloo / Rose-Tanaka (thesis eqs. 1.4-1.7, 4.5) and the kinematic model (eqs. 1.2, 1.3)."""
import math

import numpy as np
import pytest

from bulkflow.theory import beverloo as B
from bulkflow.theory import kinematic as K


def test_beverloo_b_to_the_1_5_for_long_slots():
    l = 1e4   # l >> b
    m1 = B.beverloo_rect(0.1, l, 0.0, 1600.0)
    m2 = B.beverloo_rect(0.2, l, 0.0, 1600.0)
    assert m2 / m1 == pytest.approx(2 ** 1.5, rel=1e-4)
    # with particles, the scaling holds in the reduced width b − k d
    d = 0.002
    m1 = B.beverloo_rect(0.1, l, d, 1600.0)
    m2 = B.beverloo_rect(0.1 + (0.1 - 1.5 * d), l, d, 1600.0)
    assert m2 / m1 == pytest.approx(2 ** 1.5, rel=1e-3)


def test_beverloo_long_slot_closed_form_and_empty_annulus():
    l, b, d, rho, C = 1e5, 0.1, 0.001, 1500.0, 0.58
    got = B.beverloo_rect(b, l, d, rho, C) / l
    bb = b - 1.5 * d
    assert got == pytest.approx(4 * math.sqrt(2) * C / math.pi * rho * math.sqrt(9.81) * bb ** 1.5, rel=1e-4)
    assert B.beverloo_rect(0.0029, 1.0, 0.002, rho) == 0.0      # b < k d: nothing flows


def test_beverloo_square_uses_hydraulic_diameter():
    b, rho, C = 0.2, 1000.0, 0.6
    assert B.beverloo_rect(b, b, 0.0, rho, C) == pytest.approx(4 * C / math.pi * rho * b * b * math.sqrt(9.81 * b))


def test_rose_tanaka_factor():
    assert B.rose_tanaka_factor(30.0) == pytest.approx(math.tan(math.radians(30)) ** -0.35)
    # = 1 once the walls are at or beyond the stagnant-zone boundary (θ ≥ 90° − φ_d = 45°)
    for t in (45.0, 60.0, 80.0):
        assert B.rose_tanaka_factor(t) == 1.0
    assert B.rose_tanaka_factor(45.0 - 1e-9) == pytest.approx(1.0, abs=1e-8)   # continuous
    assert B.rose_tanaka_factor(20.0) > B.rose_tanaka_factor(30.0) > 1.0
    # thesis eq. 4.5: ṁ ∝ b^{3/2} (tan θ)^{-0.35}
    r = B.rose_tanaka_rect(0.2, 1e4, 0.0, 1600, 20.0) / B.rose_tanaka_rect(0.1, 1e4, 0.0, 1600, 30.0)
    assert r == pytest.approx(2 ** 1.5 * (math.tan(math.radians(20)) / math.tan(math.radians(30))) ** -0.35, rel=1e-4)


def test_kinematic_model_conserves_flux():
    Q, D = 0.01, 0.003
    x = np.linspace(-2.0, 2.0, 40001)
    for y in (0.05, 0.2, 0.5, 1.0):
        assert K.flux(x, K.point_sink_velocity(x, y, Q, D)) == pytest.approx(Q, rel=1e-6)


def test_kinematic_model_solves_the_diffusion_equation():
    Q, D = 0.01, 0.003
    x = np.linspace(-0.1, 0.1, 21)
    y, h = 0.3, 1e-4
    v = lambda xx, yy: K.point_sink_velocity(xx, yy, Q, D)
    dvdy = (v(x, y + h) - v(x, y - h)) / (2 * h)
    d2 = (v(x + h, y) - 2 * v(x, y) + v(x - h, y)) / h ** 2
    # y is the height above the sink here; eq. 1.2's minus sign is y measured downward
    assert np.allclose(dvdy, D * d2, rtol=1e-4, atol=1e-8)


def test_eq_1_3_centreline_and_fit():
    x = np.linspace(-0.08, 0.08, 33)
    v = K.kinematic_velocity(x, 0.4, 0.2, 0.0025)
    assert v[16] == pytest.approx(0.2)
    D, vc = K.fit_diffusion_length(x, v, 0.4)
    assert D == pytest.approx(0.0025, rel=1e-9) and vc == pytest.approx(0.2, rel=1e-9)
    with pytest.raises(ValueError):
        K.fit_diffusion_length(x, np.ones_like(x) + x ** 2, 0.4)
