"""Reductions of the MPM hopper studies b, e, f, h (scripts/bulkflow/mpm/study_*.py) on synthetic
data with known answers: no solver runs."""
import math

import numpy as np
import pytest
from scipy import stats

from bulkflow.mpm import study_flow_mode as FM
from bulkflow.mpm import study_mdr_time as MT
from bulkflow.mpm import study_parametric as PA
from bulkflow.mpm import study_rate_fit as RF


# --- power-law fit (study e) -------------------------------------------------------------------

def test_power_law_fit_exact_data_recovers_exponent_and_prefactor():
    b = np.array([0.15, 0.20, 0.25, 0.30, 0.35])
    f = RF.power_law_fit(b, 3.7 * b ** 1.5)
    assert f["exponent"] == pytest.approx(1.5, abs=1e-12)
    assert f["prefactor"] == pytest.approx(3.7, rel=1e-12)
    assert f["ci"] == pytest.approx(0.0, abs=1e-10)
    assert f["r2"] == pytest.approx(1.0)
    assert (f["n"], f["x_min"], f["x_max"]) == (5, pytest.approx(0.15), pytest.approx(0.35))


def test_power_law_fit_negative_exponent_in_tan_theta():
    tan = np.tan(np.radians([10.0, 15.0, 20.0, 25.0, 30.0, 35.0]))
    f = RF.power_law_fit(tan, 900.0 * tan ** -0.35)
    assert f["exponent"] == pytest.approx(-0.35, abs=1e-12)


def test_power_law_fit_interval_is_the_student_t_interval_of_the_slope():
    rng = np.random.default_rng(7)
    x = np.geomspace(0.1, 0.4, 8)
    y = 2.0 * x ** 1.5 * np.exp(rng.normal(0.0, 0.03, x.size))
    f = RF.power_law_fit(x, y)
    lr = stats.linregress(np.log(x), np.log(y))
    assert f["exponent"] == pytest.approx(lr.slope, rel=1e-12)
    assert f["ci"] == pytest.approx(stats.t.ppf(0.975, x.size - 2) * lr.stderr, rel=1e-10)
    assert f["lo"] < 1.5 < f["hi"]
    # the 95 % interval is wider than the 68 % one
    assert RF.power_law_fit(x, y, conf=0.68)["ci"] < f["ci"]


def test_power_law_fit_interval_covers_truth_about_95_percent_of_the_time():
    rng = np.random.default_rng(1)
    x = np.geomspace(0.15, 0.35, 5)
    hits = 0
    trials = 400
    for _ in range(trials):
        f = RF.power_law_fit(x, x ** 1.5 * np.exp(rng.normal(0.0, 0.05, x.size)))
        hits += f["lo"] <= 1.5 <= f["hi"]
    assert 0.91 < hits / trials < 0.99


def test_power_law_fit_two_points_and_bad_points():
    f = RF.power_law_fit([1.0, 2.0], [1.0, 4.0])
    assert f["exponent"] == pytest.approx(2.0) and math.isnan(f["ci"])
    g = RF.power_law_fit([0.0, 1.0, 2.0, 4.0], [5.0, 1.0, 4.0, 16.0])     # x = 0 dropped
    assert g["n"] == 3 and g["exponent"] == pytest.approx(2.0)


# --- MFI = 0.3 crossing (study f) --------------------------------------------------------------

def test_mfi_crossing_linear_interpolation():
    c = FM.mfi_crossings([30.0, 40.0, 50.0], [0.6, 0.45, 0.25])
    assert len(c) == 1
    assert c[0]["x"] == pytest.approx(47.5)
    assert (c[0]["lo"], c[0]["hi"], c[0]["direction"]) == (40.0, 50.0, "falls")


def test_mfi_crossing_unsorted_input_and_rising_and_none():
    c = FM.mfi_crossings([20.0, 5.0, 10.0], [0.5, 0.1, 0.2])      # sorted: 0.1, 0.2, 0.5
    assert len(c) == 1 and c[0]["x"] == pytest.approx(10.0 + 10.0 * 0.1 / 0.3)
    assert c[0]["direction"] == "rises"
    assert FM.mfi_crossings([1.0, 2.0, 3.0], [0.5, 0.4, 0.35]) == []


def test_mfi_crossing_point_at_level_counted_once():
    c = FM.mfi_crossings([1.0, 2.0, 3.0], [0.5, 0.3, 0.1])
    assert [q["x"] for q in c] == [pytest.approx(2.0)]


def test_next_value_extends_towards_the_level():
    # MFI above 0.3 and falling with x: one more step upwards
    assert FM.next_value([20.0, 30.0, 40.0], [0.6, 0.5, 0.4], (5.0, 60.0)) == pytest.approx(50.0)
    # above and rising with x: one step downwards
    assert FM.next_value([10.0, 15.0], [0.35, 0.5], (0.0, 25.0)) == pytest.approx(5.0)
    # limit reached, or already crossing: nothing
    assert FM.next_value([50.0, 60.0], [0.6, 0.5], (5.0, 60.0)) is None
    assert FM.next_value([20.0, 30.0], [0.6, 0.2], (5.0, 60.0)) is None


# --- trend fit (study b) -----------------------------------------------------------------------

def test_linear_trend_relative_slope_of_known_line():
    t = np.linspace(0.5, 3.0, 13)
    f = MT.linear_trend(t, 900.0 - 45.0 * t)
    assert f["slope"] == pytest.approx(-45.0)
    mid = 900.0 - 45.0 * t.mean()
    assert f["mid"] == pytest.approx(mid)
    assert f["rel_pct"] == pytest.approx(-100.0 * 45.0 / mid)
    assert f["slope_ci"] == pytest.approx(0.0, abs=1e-9)


def test_linear_trend_flat_noisy_data_interval_contains_zero_and_matches_linregress():
    rng = np.random.default_rng(3)
    t = np.linspace(0.5, 3.0, 13)
    y = 880.0 + rng.normal(0.0, 10.0, t.size)
    f = MT.linear_trend(t, y)
    lr = stats.linregress(t, y)
    assert f["slope"] == pytest.approx(lr.slope)
    assert f["slope_ci"] == pytest.approx(stats.t.ppf(0.975, t.size - 2) * lr.stderr)
    assert abs(f["slope"]) < f["slope_ci"]


def test_window_rates_of_a_constant_discharge():
    t = np.arange(0.0, 3.0001, 0.01)
    step = np.where(t < 1.0 - 1e-12, 1, 2)
    step_time = np.where(step == 1, t, t - 1.0)
    mass = np.where(t > 1.0, 400.0 * (t - 1.0), 0.0)        # half model 400 kg/s/m after opening
    hist = np.rec.fromarrays([t, step, step_time, mass], names="time,step,step_time,MASS_OUT")
    mids, rates, opened = MT.window_rates(hist, window=0.2)
    assert opened == pytest.approx(1.0)
    assert mids[0] == pytest.approx(0.1)
    assert np.allclose(rates, 800.0)                        # full hopper: twice the half model


# --- parametric reductions (study h) -----------------------------------------------------------

def test_peak_position_ignores_a_single_spike():
    s = np.arange(0.025, 2.0, 0.05)
    sig = 1e4 * np.exp(-((s - 1.2) / 0.4) ** 2)
    sig[3] = 3e4                                             # one noisy bin near the outlet
    wp = np.c_[s, 0.2 + s, sig, np.zeros_like(s), np.ones_like(s)]
    sp, yp, _ = PA.peak_position(wp, smooth=5)
    assert sp == pytest.approx(1.2, abs=0.051)
    assert PA.peak_position(wp, smooth=1)[0] == pytest.approx(s[3])


def test_end_to_end_verdicts():
    pct, verdict, mono = PA.end_to_end(np.array([600.0, 580.0, 550.0]), 600.0, 5.0, 5.0)
    assert pct == pytest.approx(-100.0 * 50.0 / 600.0) and verdict == "falls" and mono
    assert PA.end_to_end(np.array([600.0, 610.0, 606.0]), 600.0, 5.0, 5.0)[1] == "flat (within noise)"
    assert PA.end_to_end(np.array([600.0, 610.0, 630.0]), 600.0, 5.0, 5.0)[1] == "rises"


def test_eta_cv_mapping_uses_eq_4_1_and_the_table_value_for_pi_over_6():
    conv = PA.PARAMS["eta_cv"][3]
    assert conv(math.pi / 6) == 0.2
    assert conv(0.55) == pytest.approx(math.log(0.64 / 0.55))


def test_edge_offset_of_the_outlet_edge_in_cells():
    assert [RF.edge_offset(b, 0.05) for b in (0.15, 0.20, 0.25, 0.30, 0.45)] == \
        [pytest.approx(v) for v in (0.5, 0.0, 0.5, 0.0, 0.5)]
    assert RF.edge_offset(0.25, 0.035) == pytest.approx(0.125 / 0.035 - 3)
