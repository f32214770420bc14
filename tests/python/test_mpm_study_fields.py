"""Reductions of the MPM hopper studies c, d, g (study_walker, study_kinematic, study_mc_dp) on
synthetic particle frames with known answers: no solver runs."""
import math

import numpy as np
import pytest

from bulkflow.mpm import study_kinematic as K
from bulkflow.mpm import study_mc_dp as G
from bulkflow.mpm import study_walker as W
from bulkflow.theory.walker import wall_normal_stress


class Frame(dict):
    """Stand-in for an h5py particle frame group: arrays by name plus attrs."""

    def __init__(self, step=2, step_time=1.0, total_time=2.0, **arrays):
        super().__init__(**arrays)
        self.attrs = dict(step=np.array([step]), step_time=np.array([step_time]),
                          total_time=np.array([total_time]))


def wall_particles(theta, outlet, s, d):
    """Coordinates of points at distance s along the wall (from the outlet edge) and d from it
    (positive into the material)."""
    x0, tang, nrm = W.wall_geometry(theta, outlet)
    s, d = np.asarray(s, float), np.asarray(d, float)
    xy = x0 + s[:, None] * tang + d[:, None] * nrm
    return np.c_[xy, np.zeros(len(s))]


# --- wall stress profile -------------------------------------------------------------------

def test_wall_profile_recovers_a_known_traction_and_ignores_particles_outside_the_band():
    theta, outlet, h = 30.0, 0.25, 0.05
    t = math.radians(theta)
    n = np.array([-math.cos(t), math.sin(t)])
    tg = np.array([math.sin(t), math.cos(t)])
    s = np.repeat(np.arange(0.0, 1.0, 0.01) + 0.005, 4)
    d = np.tile([0.06, 0.07, 0.3, 0.02], 100)    # two inside the 1-2 cell band, one far, one in the wall cell
    # a uniform stress (tension positive): sigma_n = -n.S.n, tau = t.S.n
    sxx, syy, sxy = -20e3, -30e3, 4e3
    S = np.zeros((len(s), 6))
    S[:, 0], S[:, 1], S[:, 3] = sxx, syy, sxy
    # particles outside the band carry a wildly different stress: they must not enter
    S[(d > 0.2) | (d < 0.05), :2] = -1e6
    g = Frame(coordinates=wall_particles(theta, outlet, s, d), S=S)
    p = W.wall_stress_profile([g, g], h, theta, outlet, 0.1, band=(1.0, 2.0))
    sig = np.array([[sxx, sxy], [sxy, syy]])
    assert np.allclose(p["sigma_n"], -(n @ sig @ n))
    assert np.allclose(p["tau"], tg @ sig @ n)
    assert np.allclose(p["s"], np.arange(10) * 0.1 + 0.05)
    assert np.allclose(p["count"], 20.0)         # 10 s values x 2 band particles per bin, per frame
    # the y of a bin is the wall point's height above the apex
    assert np.allclose(p["y"], 0.5 * outlet / math.tan(t) + p["s"] * math.cos(t))


def test_wall_profile_bins_a_linear_stress_to_its_bin_means():
    theta, outlet, h = 30.0, 0.25, 0.05
    s = np.linspace(0.0005, 0.9995, 1000)
    S = np.zeros((1000, 6))
    S[:, 0] = S[:, 1] = -(1000.0 + 5000.0 * s)   # hydrostatic: sigma_n = p
    g = Frame(coordinates=wall_particles(theta, outlet, s, np.full(1000, 0.01)), S=S)
    p = W.wall_stress_profile([g], h, theta, outlet, 0.2)
    assert np.allclose(p["sigma_n"], 1000.0 + 5000.0 * p["s"], rtol=1e-3)


# --- RMS figures and masks -----------------------------------------------------------------

def test_rms_relative_and_normalised_known_values():
    t = np.array([1.0, 2.0, 4.0, 8.0])
    assert W.rms_relative(1.1 * t, t) == pytest.approx(0.1)
    m = t + np.array([1.0, -1.0, 1.0, -1.0])
    assert W.rms_relative(m, t) == pytest.approx(math.sqrt((1 + 0.25 + 1 / 16 + 1 / 64) / 4))
    assert W.rms_normalised(m, t) == pytest.approx(1.0 / math.sqrt((1 + 4 + 16 + 64) / 4))
    mask = np.array([False, True, True, False])
    assert W.rms_relative(m, t, mask) == pytest.approx(math.sqrt((0.25 + 1 / 16) / 2))
    assert W.rms_relative(t, t) == 0.0


def test_wall_masks_leave_out_the_corner_cell_and_the_top():
    h, bw, y0, y_top = 0.05, 0.1, 0.2165, 3.2165
    s = (np.arange(40) + 0.5) * bw
    y = y0 + s * math.cos(math.radians(30))
    inc, whole = W.wall_masks(s, y, h, y_top, 0.2, bw)
    # the first bin (0..0.1) holds the corner cell (s < h): out; the second (0.1..0.2) is in
    assert not inc[0] and inc[1]
    assert np.all(y[inc] <= y_top - 0.2 + 1e-9) and np.any((y > y_top - 0.2) & whole)
    assert np.array_equal(whole, y < y_top)
    assert not np.any(inc & ~whole)
    # with one-cell bins the second bin (h..2h) is the first included one
    s1 = (np.arange(10) + 0.5) * h
    inc1, _ = W.wall_masks(s1, y0 + s1, h, y_top, 0.2, h)
    assert not inc1[0] and inc1[1]


def test_walker_comparison_of_the_theory_with_itself_and_a_scaled_copy():
    y0, y_top = 0.2165, 3.2165
    s = (np.arange(35) + 0.5) * 0.1
    y = y0 + s * math.cos(math.radians(30))
    th = W.walker_curves(y, y_top, 1600.0, 20.0, 5.0, 30.0)
    assert np.allclose(th["passive"][y < y_top], wall_normal_stress(y[y < y_top], y_top, 1600.0, 20, 5, 30, "passive"))
    assert np.all(th["active"][y >= y_top] == 0.0)
    inc, whole = W.wall_masks(s, y, 0.05, y_top, 0.2, 0.1)
    assert W.rms_relative(th["passive"], th["passive"], inc) == 0.0
    assert W.rms_relative(0.8 * th["active"], th["active"], inc) == pytest.approx(0.2)
    assert W.rms_normalised(0.8 * th["active"], th["active"], whole) == pytest.approx(0.2)


def test_walker_wall_force_is_the_integral_of_the_curve():
    # the passive force by a 50x finer trapezoid than the function's own
    y0, y_top = 0.2165, 3.2165
    y = np.linspace(y0, y_top, 200001)
    w = wall_normal_stress(y, y_top, 1600.0, 20.0, 5.0, 30.0, "passive")
    ref = float(np.sum(0.5 * (w[1:] + w[:-1]) * np.diff(y))) / math.cos(math.radians(30))
    got = W.walker_wall_force(y0, y_top, 1600.0, 20.0, 5.0, 30.0, "passive")
    assert got == pytest.approx(ref, rel=1e-5)


def test_history_wall_force_skips_the_last_row_of_the_discharge():
    t = math.radians(30)
    n_out = np.array([math.cos(t), -math.sin(t)])      # outward wall normal
    fn = np.array([10.0, 11.0, 20.0, 20.0, 20.0, 500.0])
    step = np.array([1, 1, 2, 2, 2, 2])
    st = np.array([0.5, 1.0, 0.2, 0.7, 0.8, 1.0])
    hist = dict(WALLF1_WALL=fn * n_out[0], WALLF2_WALL=fn * n_out[1], step=step, step_time=st)
    assert W.history_wall_force(hist, 30.0, 1)[0] == pytest.approx(11.0)
    assert W.history_wall_force(hist, 30.0, 2, 0.6)[0] == pytest.approx(20.0)


def test_split_frames_takes_the_last_fill_frame_and_the_late_discharge_frames():
    fr = [Frame(1, 0.5, 0.5), Frame(1, 1.0, 1.0), Frame(2, 0.3, 1.3), Frame(2, 0.6, 1.6), Frame(2, 0.9, 1.9)]
    fill, dis = W.split_frames(fr, 0.6)
    assert fill == [fr[1]] and dis == fr[3:]


# --- kinematic model -----------------------------------------------------------------------

def test_fit_of_an_exact_gaussian_profile_gives_back_its_D():
    x = np.linspace(0.0, 0.7, 15)
    y, D, vc = 1.2, 0.15, 0.5
    f = K.fit_profile(x, vc * np.exp(-x * x / (4 * D * y)), y)
    assert f["D"] == pytest.approx(D, rel=1e-10)
    assert f["v_c"] == pytest.approx(vc, rel=1e-10)
    assert f["r2"] == pytest.approx(1.0)
    assert f["rms_over_vc"] == pytest.approx(0.0, abs=1e-12)


def test_fit_quality_drops_for_a_profile_that_is_not_gaussian():
    x = np.linspace(0.0, 0.7, 15)
    v = np.where(x < 0.4, 1.0, 0.3)            # plug with a step
    f = K.fit_profile(x, v, 1.0)
    assert f["r2"] < 0.95


def test_velocity_profile_of_synthetic_particles_recovers_D():
    rng = np.random.default_rng(1)
    theta, h, y, D, vc = 30.0, 0.05, 1.0, 0.12, 0.8
    xw = y * math.tan(math.radians(theta))
    frames = []
    for _ in range(4):
        n = 4000
        x = rng.uniform(0, xw, n)
        yy = rng.uniform(y - 0.2, y + 0.2, n)
        # each particle's velocity from the model at its own height: the band average is close
        v = -vc * np.exp(-x * x / (4 * D * yy))
        frames.append(Frame(coordinates=np.c_[x, yy, np.zeros(n)], V=np.c_[np.zeros(n), v, np.zeros(n)],
                            mass=np.ones(n)))
    p = K.velocity_profile(frames, y, h, theta, h)
    assert p["x"].max() < xw and len(p["x"]) == math.ceil(xw / h)
    assert np.all(p["count"] > 0)
    f = K.fit_profile(p["x"], p["v"], y)
    assert f["D"] == pytest.approx(D, rel=0.03)
    assert f["r2"] > 0.99


def test_wall_distance_and_grows():
    assert K.wall_distance(0.0, 1.0, 30.0) == pytest.approx(0.5)
    assert K.wall_distance(math.tan(math.radians(30)), 1.0, 30.0) == pytest.approx(0.0, abs=1e-12)
    assert K.grows([0.1, 0.2, 0.3])
    assert not K.grows([0.1, 0.3, 0.2])


# --- MC vs DP ------------------------------------------------------------------------------

def test_align_matches_common_bins():
    p = dict(s=np.array([0.05, 0.15, 0.25]), y=np.array([1.0, 2.0, 3.0]), sigma_n=np.array([1.0, 2.0, 3.0]))
    q = dict(s=np.array([0.15, 0.25, 0.35]), y=np.array([2.0, 3.0, 4.0]), sigma_n=np.array([20.0, 30.0, 40.0]))
    s, y, a, b = G.align(p, q, "sigma_n")
    assert np.allclose(s, [0.15, 0.25]) and np.allclose(a, [2.0, 3.0]) and np.allclose(b, [20.0, 30.0])


def test_yield_share():
    sdv = np.zeros((4, 8))
    sdv[:3, 4] = [1, 2, 0]
    assert G.yield_share([Frame(SDV=sdv)]) == pytest.approx(0.5)
