"""Discharge figures of a flat-bottomed bin run (thesis ch. 5), as the thesis reports them.

    bulkflow-mpm-study bins ...        (study_bins.py runs the bins and calls these)

Pure functions on arrays (unit-tested on synthetic data, tests/python/test_bin_analysis.py) and
two readers of a run's particle frames. The definitions (docs/bins.md, "Outputs", says the same):

- MDR against time: the discharged mass M(t) (history MASS_OUT) differenced over windows.
- T_ss (thesis §5.5.2): instantaneous MDRs r_j = (M(t_j) - M(t_j - D)) / D at t_j = t_open + s + j D
  (D = 0.5 s, s = `skip` = D: the first window starts 0.5 s after opening, past the start-up);
  the first j >= 2 with |r_j / r_(j-1) - 1| > 10 % marks the sudden change; T_ss = t_(j-1) - t_open,
  the time just before it. No such jump before the run ends: T_ss is not reached (nan).
  `plateau`: only the fall that begins the plateau counts: r_j / r_(j-1) - 1 < -10 % and no later
  window regains 90 % of r_(j-1). The thesis's sudden change is the one "observed at the beginning
  of the plateau region" of M(t), where the outflow stops; a rate that drifts upwards by 10 %
  between two windows (the eccentric bins, docs/bins.md), or dips by 10 % and recovers (the DS
  bins), has not ended its discharge. A fall in the record's last window has no later window to
  confirm it and is taken. The bins study uses it; the accuracy families keep either sign.
- MDR: slope of the least-squares line through M(t) over t_open + skip .. t_open + T_ss.
- free surface: the highest particle centre above the bottom (y >= 0) in columns of width dx; an
  empty column is nan (floor bare). Shape of a profile: its chord from the lowest to the highest
  end of the sloping part, and the mean signed distance of the profile above the chord over the
  chord's rise; > +tol: convex (bulges up, like a heap), < -tol: concave (sags), else linear;
  flat when the rise is below `min_rise` (the study: 2 cells).
- two slopes (the eccentric bin): the two straight lines of least total squared error, split at
  the best breakpoint; their angles with the horizontal in degrees.
- velocity profile at height H: the mass-weighted mean vertical velocity of the particles within
  half a cell of y = H, in columns of width dx, averaged over the frames of a time window.
"""
import math

import numpy as np

T_SS_INTERVAL = 0.5      # s, the FEM's instantaneous-MDR interval (thesis §5.5.2)
T_SS_JUMP = 0.10         # the sudden change


def opening_time(hist):
    """Total time at which the discharge step starts (history columns time, step, step_time)."""
    t, step = np.asarray(hist["time"]), np.asarray(hist["step"])
    if not np.any(step >= 2):
        return float(t[0])
    i2 = int(np.argmax(step >= 2))
    return float(t[i2] - hist["step_time"][i2])


def window_rates(t, mass, t_open, interval=T_SS_INTERVAL, skip=T_SS_INTERVAL):
    """(window end times after opening, rates) of the discharged mass over windows of `interval`
    starting `skip` s after opening, up to the last time of the record."""
    t = np.asarray(t, dtype=float)
    mass = np.asarray(mass, dtype=float)
    n = int(math.floor((t[-1] - t_open - skip) / interval + 1e-9))
    if n < 1:
        return np.zeros(0), np.zeros(0)
    ends = skip + interval * np.arange(1, n + 1)
    m_end = np.interp(t_open + ends, t, mass)
    m_start = np.interp(t_open + ends - interval, t, mass)
    return ends, (m_end - m_start) / interval


def steady_time(t, mass, t_open, interval=T_SS_INTERVAL, skip=T_SS_INTERVAL, jump=T_SS_JUMP, plateau=False):
    """T_ss (s after opening) by the module's rule, and the window ends and rates it used.
    nan when no jump (with `plateau`: no fall that the rate does not recover from) occurs before
    the record ends."""
    ends, rates = window_rates(t, mass, t_open, interval, skip)
    for j in range(1, len(rates)):
        if rates[j - 1] <= 0:
            continue
        change = rates[j] / rates[j - 1] - 1.0
        if not plateau and abs(change) > jump:
            return float(ends[j - 1]), ends, rates
        if plateau and change < -jump and not np.any(rates[j + 1:] >= (1.0 - jump) * rates[j - 1]):
            return float(ends[j - 1]), ends, rates
    return float("nan"), ends, rates


def steady_rate(t, mass, t_open, t_ss, skip=T_SS_INTERVAL):
    """MDR: regression slope of the discharged mass over t_open + skip .. t_open + t_ss (to the end
    of the record when t_ss is nan)."""
    t = np.asarray(t, dtype=float)
    mass = np.asarray(mass, dtype=float)
    end = t_open + t_ss if math.isfinite(t_ss) else t[-1]
    m = (t >= t_open + skip - 1e-12) & (t <= end + 1e-12)
    return float(np.polyfit(t[m], mass[m], 1)[0]) if m.sum() >= 2 else float("nan")


def surface_profile(x, y, x_lo, x_hi, dx):
    """Free surface: (column centres, highest particle y >= 0 in each column; nan if none)."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    edges = np.arange(x_lo, x_hi + 0.5 * dx, dx)
    ncol = len(edges) - 1
    top = np.full(ncol, -np.inf)
    inside = (y >= 0.0) & (x >= x_lo) & (x < edges[-1])
    k = np.clip(((x[inside] - x_lo) / dx).astype(int), 0, ncol - 1)
    np.maximum.at(top, k, y[inside])
    top[~np.isfinite(top)] = np.nan
    return 0.5 * (edges[1:] + edges[:-1]), top


def surface_shape(xs, ys, tol=0.05, min_rise=0.0):
    """Shape of a one-sided profile: ('convex'|'linear'|'concave', bulge) where bulge is the mean
    distance of the profile above the chord between its ends, over the chord's rise; ('flat', nan)
    when the rise is not above `min_rise` (the surface has hardly moved)."""
    ok = np.isfinite(ys)
    xs, ys = np.asarray(xs)[ok], np.asarray(ys)[ok]
    if len(xs) < 3:
        return "undefined", float("nan")
    rise = abs(ys[-1] - ys[0])
    if rise <= max(min_rise, 0.0):
        return "flat", float("nan")
    chord = ys[0] + (ys[-1] - ys[0]) * (xs - xs[0]) / (xs[-1] - xs[0])
    bulge = float(np.mean(ys - chord) / rise)
    return ("convex" if bulge > tol else "concave" if bulge < -tol else "linear"), bulge


def line_fit(xs, ys):
    """(slope, intercept, sum of squared residuals) of the least-squares line."""
    a, b = np.polyfit(xs, ys, 1)
    r = ys - (a * xs + b)
    return float(a), float(b), float(np.sum(r * r))


def two_slopes(xs, ys, min_points=3):
    """Two straight segments of least total squared error: dict with the breakpoint x_break and
    the left and right slopes (dy/dx) and angles with the horizontal (deg)."""
    ok = np.isfinite(ys)
    xs, ys = np.asarray(xs, dtype=float)[ok], np.asarray(ys, dtype=float)[ok]
    best = None
    for i in range(min_points, len(xs) - min_points + 1):
        a1, _, s1 = line_fit(xs[:i], ys[:i])
        a2, _, s2 = line_fit(xs[i:], ys[i:])
        if best is None or s1 + s2 < best[0]:
            best = (s1 + s2, i, a1, a2)
    if best is None:
        return dict(x_break=float("nan"), slope_left=float("nan"), slope_right=float("nan"),
                    angle_left=float("nan"), angle_right=float("nan"))
    _, i, a1, a2 = best
    return dict(x_break=float(0.5 * (xs[i - 1] + xs[i])), slope_left=a1, slope_right=a2,
                angle_left=math.degrees(math.atan(abs(a1))), angle_right=math.degrees(math.atan(abs(a2))))


def velocity_profile(frames_xv, height, band, x_lo, x_hi, dx):
    """Time-averaged vertical velocity along y = height: frames_xv is a list of (x, v, m) arrays
    of particle coordinates (n, 2), velocities (n, 2), masses (n); particles with |y - height| <
    band/2 count. Returns (column centres, mean v_y over the frames of the mass-weighted column
    means; nan where no frame had a particle)."""
    edges = np.arange(x_lo, x_hi + 0.5 * dx, dx)
    ncol = len(edges) - 1
    total = np.zeros(ncol)
    count = np.zeros(ncol)
    for x, v, m in frames_xv:
        sel = (np.abs(x[:, 1] - height) < 0.5 * band) & (x[:, 0] >= x_lo) & (x[:, 0] < edges[-1])
        k = np.clip(((x[sel, 0] - x_lo) / dx).astype(int), 0, ncol - 1)
        mv = np.bincount(k, weights=m[sel] * v[sel, 1], minlength=ncol)
        mm = np.bincount(k, weights=m[sel], minlength=ncol)
        has = mm > 0
        total[has] += mv[has] / mm[has]
        count[has] += 1
    with np.errstate(invalid="ignore", divide="ignore"):
        return 0.5 * (edges[1:] + edges[:-1]), np.where(count > 0, total / np.maximum(count, 1), np.nan)


def read_frames(h5path, t_open):
    """[(time after opening, coordinates, V, mass)] of every particle frame from the opening on."""
    import h5py
    out = []
    with h5py.File(h5path, "r") as f:
        for key in sorted(f["particles"].keys()):
            g = f["particles"][key]
            t = float(g.attrs["total_time"][0]) - t_open
            if t < -1e-9:
                continue
            out.append((t, g["coordinates"][:], g["V"][:], g["mass"][:]))
    return out
