"""Discharge figures of an MPM hopper run: mass discharge rate, T_ss, mass-flow index, free surface.

    bulkflow-mpm-discharge BASE [--theta 30 --outlet 0.25] [--plot out.png]

BASE is the run's output base (BASE_history.csv, BASE.h5). Figures (2D: per metre of depth of the
half model; double them for the full hopper):
- MDR: slope of a linear regression of the discharged mass (MASS_OUT) against time from
  `--skip` seconds after the outlet opens (start of step 2) up to T_ss (thesis), and the same up
  to the end of the run (steady runs with inflow);
- T_ss (thesis §5.5.2): instantaneous MDRs over windows of `--window` s from `--skip` s after
  opening; T_ss is the end of the last window before the first one that differs by more than 10 %
  from the mean of the windows before it (the whole run when none does);
- MFI = mean vertical particle velocity within one cell of the inclined wall / the same within one
  cell of the axis, over heights y0 + 2b .. y0 + 0.75 H of the last frame; mass flow if MFI > 0.3;
- free surface: the highest particle in bins of one cell along x (last frame), written to
  BASE_surface.csv;
- bulk density against time (every particle frame, BASE_density.csv; `--density-every k` prints
  every k-th row): the particles are sorted into zones -- `surface` (within 2 cells of the local
  free surface), `wall` (within 2 cells of the inclined wall), `axis` (within 2 cells of the
  symmetry plane), `outlet` (below y0 + 2b) and `bulk` (the rest) -- and each zone's density is
  sum(m)/sum(V) with the particle volumes V = det F V0 (what the material sees). Beside it, a
  control volume fixed in space in the bulk (y0 + 3b .. y0 + 2H/3, 2 cells off the axis and the
  wall): the particle mass in it over its area (`space`: how densely the particles fill the
  space, whatever their volumes say) and the particle volume in it over its area (`fill`: 1 when
  the particle volumes tile the space, > 1 when they overlap). Columns: t, opened (s after
  opening), rho_<zone>, V_<zone> (share of the total particle volume), rho_space, fill, mean
  det F of the bulk zone (= rho0 / rho_bulk), rho0.
"""
import argparse
import math
import sys

import numpy as np


def discharge_rate(hist, skip=0.5, window=0.2, tolerance=0.10):
    t = hist["time"]
    step = hist["step"]
    i2 = int(np.argmax(step >= 2))
    opened = t[i2] - hist["step_time"][i2] if np.any(step >= 2) else t[0]
    mass = hist["MASS_OUT"]
    t0 = opened + skip
    edges = np.arange(t0, t[-1] + 1e-12, window)
    rates = []
    for a, b in zip(edges[:-1], edges[1:]):
        rates.append((np.interp(b, t, mass) - np.interp(a, t, mass)) / (b - a))
    t_ss = t[-1]
    for i in range(1, len(rates)):
        ref = np.mean(rates[:i])
        if ref > 0 and abs(rates[i] / ref - 1) > tolerance:
            t_ss = edges[i]
            break
    m = (t >= t0) & (t <= t_ss)
    mdr = np.polyfit(t[m], mass[m], 1)[0] if m.sum() >= 2 else float("nan")
    return mdr, t_ss - opened, opened, np.array(rates), edges


def mean_discharge_rate(hist, skip=0.5):
    """Regression slope of MASS_OUT over the whole discharge from `skip` s after opening (for runs
    with inflow, whose discharge stays steady to the end; less sensitive to window noise)."""
    t = hist["time"]
    step = hist["step"]
    i2 = int(np.argmax(step >= 2))
    opened = t[i2] - hist["step_time"][i2] if np.any(step >= 2) else t[0]
    m = t >= opened + skip
    return np.polyfit(t[m], hist["MASS_OUT"][m], 1)[0] if m.sum() >= 2 else float("nan")


def mass_flow_index(h5path, theta=30.0, outlet=0.25, height=3.0):
    import h5py
    f = h5py.File(h5path, "r")
    h = float(f["grid"].attrs["h"][0])
    g = f["particles"][sorted(f["particles"].keys())[-1]]
    x, v = g["coordinates"][:], g["V"][:]
    t = math.radians(theta)
    y0 = 0.5 * outlet / math.tan(t)
    # distance to the wall line through the apex (0, 0) at theta from the vertical
    d_wall = x[:, 1] * math.sin(t) - x[:, 0] * math.cos(t)
    band = (x[:, 1] > y0 + 2 * outlet) & (x[:, 1] < y0 + 0.75 * height)
    wall = band & (d_wall < h)
    axis = band & (x[:, 0] < h)
    if wall.sum() == 0 or axis.sum() == 0:
        return float("nan"), 0, 0
    return v[wall, 1].mean() / v[axis, 1].mean(), wall.sum(), axis.sum()


def free_surface(h5path, frame=-1):
    import h5py
    f = h5py.File(h5path, "r")
    h = float(f["grid"].attrs["h"][0])
    g = f["particles"][sorted(f["particles"].keys())[frame]]
    x = g["coordinates"][:]
    bins = np.floor(x[:, 0] / h).astype(int)
    ub = np.unique(bins)
    return (ub + 0.5) * h, np.array([x[bins == b, 1].max() for b in ub])


ZONES = ("bulk", "surface", "wall", "axis", "outlet")


def _zones(x, h, theta, outlet):
    """Zone index (ZONES) of each particle."""
    t = math.radians(theta)
    y0 = 0.5 * outlet / math.tan(t)
    d_wall = x[:, 1] * math.sin(t) - x[:, 0] * math.cos(t)
    k = np.floor(x[:, 0] / h).astype(int)
    k -= k.min()
    top = np.full(k.max() + 1, -np.inf)
    np.maximum.at(top, k, x[:, 1])
    y_top = top[k]
    zone = np.zeros(len(x), dtype=int)
    zone[x[:, 0] < 2 * h] = 3
    zone[d_wall < 2 * h] = 2
    zone[x[:, 1] > y_top - 2 * h] = 1
    zone[x[:, 1] < y0 + 2 * outlet] = 4
    return zone


def _control_volume(h, theta, outlet, height):
    """The bulk control volume: y0 + 3b .. y0 + 2H/3 in height, from 2 cells off the axis to 2
    cells off the inclined wall (a trapezoid fixed in space, full while inflow keeps the level)."""
    t = math.radians(theta)
    y0 = 0.5 * outlet / math.tan(t)
    return y0 + 3 * outlet, y0 + 2 * height / 3, 2 * h, 2 * h / math.cos(t), math.tan(t)


def _in_control_volume(x, h, theta, outlet, height):
    ya, yb, xa, off, tn = _control_volume(h, theta, outlet, height)
    return ((x[:, 1] >= ya) & (x[:, 1] < yb) & (x[:, 0] >= xa)
            & (x[:, 0] < x[:, 1] * tn - off))


def _control_volume_area(h, theta, outlet, height):
    ya, yb, xa, off, tn = _control_volume(h, theta, outlet, height)
    return (yb - ya) * (0.5 * (ya + yb) * tn - off - xa)


def bulk_density(h5path, theta=30.0, outlet=0.25, height=3.0):
    """Rows (t, s after opening, rho per zone, volume share per zone, space density and fill of the
    control volume, bulk mean det F, rho0) of every particle frame (see the module text)."""
    import h5py
    f = h5py.File(h5path, "r")
    h = float(f["grid"].attrs["h"][0])
    rows = []
    for key in sorted(f["particles"].keys()):
        g = f["particles"][key]
        x, m, vol = g["coordinates"][:], g["mass"][:], g["volume"][:]
        if len(x) == 0:
            continue
        zone = _zones(x, h, theta, outlet)
        rho0 = float(np.median(m / vol)) if key == sorted(f["particles"].keys())[0] else rows[0][-1]
        rho = [m[zone == z].sum() / vol[zone == z].sum() if np.any(zone == z) else float("nan")
               for z in range(len(ZONES))]
        share = [vol[zone == z].sum() / vol.sum() for z in range(len(ZONES))]
        # the fixed control volume: mass in it over its area (space density) and the particles'
        # own volume in it over its area (fill: > 1 the particle volumes overlap, < 1 gaps)
        inside = _in_control_volume(x, h, theta, outlet, height)
        area = _control_volume_area(h, theta, outlet, height)
        rho_space = m[inside].sum() / area
        fill = vol[inside].sum() / area
        time = float(g.attrs["total_time"][0])
        step = int(g.attrs["step"][0])
        opened = float(g.attrs["step_time"][0]) if step >= 2 else float("nan")
        rows.append([time, opened, *rho, *share, rho_space, fill, rho0 / rho[0], rho0])
    return np.array(rows)


def print_density(rows, every=1):
    print("bulk density against time (zones: module text; rho = sum m / sum V, V = det F V0; "
          "space = particle mass per area of the fixed bulk control volume, fill = particle volume "
          "per area there):")
    print("   t [s]  opened   " + "  ".join(f"{z:>8s}" for z in ZONES) +
          "     space    fill   det F   V share bulk/surface/wall")
    for i, r in enumerate(rows):
        if i % every and i != len(rows) - 1:
            continue
        op = f"{r[1]:6.2f}" if r[1] == r[1] else "     -"
        print(f"  {r[0]:6.3f}  {op}   " + "  ".join(f"{v:8.1f}" for v in r[2:7]) +
              f"  {r[12]:8.1f}  {r[13]:6.4f}  {r[14]:6.4f}   {r[7]:.3f}/{r[8]:.3f}/{r[9]:.3f}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("base")
    p.add_argument("--theta", type=float, default=30.0)
    p.add_argument("--outlet", type=float, default=0.25)
    p.add_argument("--height", type=float, default=3.0)
    p.add_argument("--skip", type=float, default=0.5)
    p.add_argument("--window", type=float, default=0.2)
    p.add_argument("--plot")
    p.add_argument("--density-every", type=int, default=1, help="print every k-th density row")
    a = p.parse_args(argv)
    hist = np.genfromtxt(a.base + "_history.csv", delimiter=",", names=True)
    mdr, t_ss, opened, rates, edges = discharge_rate(hist, a.skip, a.window)
    print(f"outlet opened at t = {opened:.4f} s; mass out {hist['MASS_OUT'][-1]:.6g} kg, "
          f"in {hist['MASS_IN'][-1]:.6g} kg, max |mass balance error| {np.abs(hist['MASS_ERROR']).max():.3e} kg")
    print(f"MDR (half model, per m depth) = {mdr:.6g} kg/s/m; full hopper {2 * mdr:.6g} kg/s/m")
    print(f"T_ss = {t_ss:.4f} s after opening (windows of {a.window:g} s from {a.skip:g} s)")
    mean = mean_discharge_rate(hist, a.skip)
    print(f"mean MDR from {a.skip:g} s after opening to the end: {mean:.6g} kg/s/m (full hopper {2 * mean:.6g})")
    beverloo = 0.58 * 1600 * math.sqrt(9.81) * a.outlet ** 1.5
    print(f"  for scale: 2D Beverloo C rho sqrt(g) b^1.5 with C = 0.58, rho = 1600: {beverloo:.6g} kg/s/m (full)")
    try:
        mfi, nw, na = mass_flow_index(a.base + ".h5", a.theta, a.outlet, a.height)
        print(f"MFI = {mfi:.4f} ({nw} wall / {na} axis particles): {'mass flow' if mfi > 0.3 else 'funnel flow'}")
        xs, ys = free_surface(a.base + ".h5")
        np.savetxt(a.base + "_surface.csv", np.c_[xs, ys], delimiter=",", header="x,y_top", comments="")
        print(f"free surface: {a.base}_surface.csv ({len(xs)} bins, top {ys.min():.4f} .. {ys.max():.4f} m)")
        rows = bulk_density(a.base + ".h5", a.theta, a.outlet, a.height)
        header = ("t,opened," + ",".join(f"rho_{z}" for z in ZONES) + "," +
                  ",".join(f"V_{z}" for z in ZONES) + ",rho_space,fill,detF_bulk,rho0")
        np.savetxt(a.base + "_density.csv", rows, delimiter=",", header=header, comments="")
        print_density(rows, a.density_every)
        print(f"density table: {a.base}_density.csv")
    except (OSError, KeyError) as e:
        print(f"(no field file: {e})")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(10, 4))
        ax[0].plot(hist["time"], hist["MASS_OUT"], label="discharged")
        ax[0].plot(hist["time"], hist["MASS_IN"], label="inflow")
        ax[0].set_xlabel("t [s]")
        ax[0].set_ylabel("mass [kg/m]")
        ax[0].legend()
        if len(rates):
            ax[1].step(edges[1:], rates, where="pre")
        ax[1].axhline(mdr, ls="--", c="k")
        ax[1].set_xlabel("t [s]")
        ax[1].set_ylabel("MDR [kg/s/m]")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main())
