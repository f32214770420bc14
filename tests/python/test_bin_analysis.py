"""Flat-bottomed bin reductions (scripts/bulkflow/mpm/bin_analysis.py) and the bin scene generator
on synthetic data with known answers: no solver runs."""
import math

import numpy as np
import pytest

from bulkflow.mpm import bin_analysis as BA
from bulkflow.mpm import bin_scene as BS


def _history(t_open=0.3, rate=5.0, t_change=4.2, rate_after=1.0, t_end=7.0, dt=0.01):
    """Discharged mass: 0 until opening, a steady rate, then a sudden drop at t_change after opening."""
    t = np.arange(0.0, t_end + 1e-9, dt)
    s = np.clip(t - t_open, 0.0, None)
    mass = np.where(s < t_change, rate * s, rate * t_change + rate_after * (s - t_change))
    return t, mass


def test_steady_time_is_the_window_end_before_the_jump():
    t, m = _history()
    t_ss, ends, rates = BA.steady_time(t, m, 0.3)
    # windows end at 1.0, 1.5, ...; the change at 4.2 s falls in the window ending at 4.5 s
    assert ends[0] == pytest.approx(1.0)
    assert t_ss == pytest.approx(4.0)
    assert rates[0] == pytest.approx(5.0)
    assert BA.steady_rate(t, m, 0.3, t_ss) == pytest.approx(5.0, rel=1e-9)


def test_steady_time_ignores_changes_below_ten_percent_and_reports_nan_without_a_jump():
    t, m = _history(rate_after=4.6)          # an 8 % drop is not a sudden change
    t_ss, _, _ = BA.steady_time(t, m, 0.3)
    assert math.isnan(t_ss)
    # without T_ss the MDR is the regression over the whole record after the skip
    assert 4.6 < BA.steady_rate(t, m, 0.3, t_ss) < 5.0
    # a 12 % drop is one (on a window boundary: split over two windows it is two 6 % steps,
    # not a sudden change, by the rule)
    t, m = _history(rate_after=4.4, t_change=4.0)
    assert BA.steady_time(t, m, 0.3)[0] == pytest.approx(4.0)
    t, m = _history(rate_after=4.4, t_change=4.2)
    assert math.isnan(BA.steady_time(t, m, 0.3)[0])


def test_plateau_rule_passes_a_rising_drift_and_a_recovered_dip_and_stops_at_the_plateau():
    # a rate that dips 15 % at 1.5 s after opening and recovers, rises 12 % at 2.5 s (a drift),
    # then the outflow stops at 4.0 s
    t = np.arange(0.0, 7.0 + 1e-9, 0.01)
    s = np.clip(t - 0.3, 0.0, None)
    rate = np.select([s < 1.5, s < 2.0, s < 2.5, s < 4.0], [5.0, 4.25, 5.0, 5.6], 0.2)
    m = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(s))])
    assert BA.steady_time(t, m, 0.3)[0] == pytest.approx(1.5)                  # either sign: the dip
    assert BA.steady_time(t, m, 0.3, plateau=True)[0] == pytest.approx(4.0)    # the plateau's onset
    t, m = _history(rate_after=5.6)                                            # rises only: no end
    assert math.isnan(BA.steady_time(t, m, 0.3, plateau=True)[0])
    t, m = _history()                                                          # a plain stop
    assert BA.steady_time(t, m, 0.3, plateau=True)[0] == pytest.approx(4.0)


def test_opening_time_from_step_columns():
    hist = dict(time=np.array([0.1, 0.2, 0.3, 0.35, 0.45]), step=np.array([1, 1, 1, 2, 2]),
                step_time=np.array([0.1, 0.2, 0.3, 0.05, 0.15]))
    assert BA.opening_time(hist) == pytest.approx(0.3)


def test_surface_profile_takes_the_highest_particle_above_the_floor():
    x = np.array([0.005, 0.006, 0.015, 0.025, 0.025, 0.005])
    y = np.array([0.10, 0.12, 0.20, -0.01, -0.02, 0.05])
    xs, ys = BA.surface_profile(x, y, 0.0, 0.03, 0.01)
    assert xs == pytest.approx([0.005, 0.015, 0.025])
    assert ys[:2] == pytest.approx([0.12, 0.20])
    assert math.isnan(ys[2])                 # only falling particles below the floor: bare


@pytest.mark.parametrize("power,expected", [(0.5, "convex"), (1.0, "linear"), (2.0, "concave")])
def test_surface_shape_of_power_profiles(power, expected):
    xs = np.linspace(0.0, 0.08, 17)
    ys = 0.05 + 0.06 * (xs / 0.08) ** power
    shape, bulge = BA.surface_shape(xs, ys)
    assert shape == expected
    if expected == "linear":
        assert abs(bulge) < 1e-12
    # a surface that has hardly moved is flat, whatever its wiggles
    assert BA.surface_shape(xs, 0.2 + 1e-4 * (xs / 0.08) ** power, min_rise=0.004)[0] == "flat"


def test_two_slopes_recovers_45_and_34_degrees():
    xs = np.linspace(0.0, 0.17, 35)
    xb = 0.09
    t45, t34 = math.tan(math.radians(45.0)), math.tan(math.radians(34.0))
    ys = np.where(xs < xb, 0.2 - t45 * xs, 0.2 - t45 * xb - t34 * (xs - xb))
    f = BA.two_slopes(xs, ys)
    assert f["angle_left"] == pytest.approx(45.0, abs=1e-6)
    assert f["angle_right"] == pytest.approx(34.0, abs=1e-6)
    assert abs(f["x_break"] - xb) <= 0.5 * (xs[1] - xs[0]) + 1e-12


def test_velocity_profile_is_mass_weighted_and_time_averaged():
    x = np.array([[0.001, 0.040], [0.002, 0.041], [0.011, 0.040], [0.001, 0.070]])
    m = np.array([1.0, 3.0, 1.0, 1.0])
    v1 = np.array([[0, -1.0], [0, -2.0], [0, -0.5], [0, -9.0]])
    v2 = np.array([[0, -3.0], [0, -4.0], [0, -1.5], [0, -9.0]])
    xs, vy = BA.velocity_profile([(x, v1, m), (x, v2, m)], 0.040, 0.004, 0.0, 0.02, 0.01)
    assert vy[0] == pytest.approx(0.5 * ((-1 - 6) / 4 + (-3 - 12) / 4))
    assert vy[1] == pytest.approx(-1.0)


def test_bin_scene_geometry_and_material():
    assert BS.phi_peak() == pytest.approx(46.0)
    assert BS.eps_cv() == pytest.approx(math.log(1800.0 / 1387.0))
    assert BS.eps_cv(1600.0) == pytest.approx(math.log(1600.0 / 1387.0))
    g = BS.bin_geometry("concentric", edge_cells=1)
    h = g["cell"]
    assert h == pytest.approx(0.0118 / 3)
    assert g["x_out1"] / h == pytest.approx(1.5)                 # the outlet edge mid-cell
    assert g["x_right"] / h == pytest.approx(round(g["x_right"] / h))
    e = BS.bin_geometry("eccentric", edge_cells=1)
    assert e["x_out1"] - e["x_out0"] == pytest.approx(0.0118)
    assert e["x_out1"] == pytest.approx(e["x_right"])            # the outlet against the right wall
    text = BS.bin_scene("eccentric", "DS", right_wall_friction=34.0, side_friction=0.025)
    assert "*MPM SIDE FRICTION, GAP=0.025, FRICTION=0.1227846" in text
    assert "0.6745085" in text                                    # tan 34 deg on the right wall
    assert "46., 15., 0., 34., 0., 0.26064" in text
    assert "*MOHR COULOMB\n34., 0." in BS.bin_scene("concentric", "NDNS")
