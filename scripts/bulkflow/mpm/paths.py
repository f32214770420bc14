"""Path outputs of an MPM wedge-hopper run, like thesis Fig. 4.6.

    bulkflow-mpm-paths BASE [--theta 30 --outlet 0.25] [--frames N] [--plot out.png]

From the particle frames of BASE.h5 (the last N frames averaged, or one frame):
- across the outlet: vertical velocity V2 and bulk density of the particles within one cell of the
  outlet line y0 = (b/2)/tan(theta), in bins of half a cell along x from the axis to the wall
  -> BASE_outlet_path.csv (x, v_y, density, particles);
- along the inclined wall: wall normal stress sigma_n = -n.S.n (compression positive) and wall
  shear tau = t.S.n of the particles within one cell of the wall, in wall coordinates
  (s = distance along the wall from the outlet edge), bins of one cell
  -> BASE_wall_path.csv (s, y, sigma_n, tau, particles).
Bulk density of a bin = sum of particle masses / sum of particle volumes (per unit depth in 2D).
"""
import argparse
import math
import sys

import numpy as np


def frames(h5, n):
    keys = sorted(h5["particles"].keys())
    return [h5["particles"][k] for k in keys[-n:]]


def outlet_path(groups, h, theta, outlet):
    y0 = 0.5 * outlet / math.tan(math.radians(theta))
    edges = np.arange(0.0, 0.5 * outlet + 1e-12, 0.5 * h)
    acc = np.zeros((len(edges) - 1, 4))
    for g in groups:
        x, v, m, vol = g["coordinates"][:], g["V"][:], g["mass"][:], g["volume"][:]
        band = np.abs(x[:, 1] - y0) < h
        k = np.digitize(x[band, 0], edges) - 1
        ok = (k >= 0) & (k < len(edges) - 1)
        for j, vy, mj, vj in zip(k[ok], v[band, 1][ok], m[band][ok], vol[band][ok]):
            acc[j] += [vy * mj, mj, vj, 1]
    xc = 0.5 * (edges[1:] + edges[:-1])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.c_[xc, acc[:, 0] / acc[:, 1], acc[:, 1] / acc[:, 2], acc[:, 3] / len(groups)]


def wall_path(groups, h, theta, outlet):
    t = math.radians(theta)
    x0 = np.array([0.5 * outlet, 0.5 * outlet / math.tan(t)])      # outlet edge
    tang = np.array([math.sin(t), math.cos(t)])                       # up along the wall
    nrm = np.array([-math.cos(t), math.sin(t)])                       # into the material
    acc = {}
    for g in groups:
        x, s = g["coordinates"][:, :2], g["S"][:]
        rel = x - x0
        d = rel @ nrm
        sv = rel @ tang
        near = (d < h) & (d > -h) & (sv >= 0)
        for si, st in zip(sv[near], s[near]):
            sig = np.array([[st[0], st[3]], [st[3], st[1]]])
            k = int(si // h)
            a = acc.setdefault(k, np.zeros(3))
            a += [-(nrm @ sig @ nrm), tang @ sig @ nrm, 1]
    rows = []
    for k in sorted(acc):
        a = acc[k]
        sc = (k + 0.5) * h
        rows.append([sc, x0[1] + sc * tang[1], a[0] / a[2], a[1] / a[2], a[2] / len(groups)])
    return np.array(rows)


def main(argv=None):
    import h5py
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("base")
    p.add_argument("--theta", type=float, default=30.0)
    p.add_argument("--outlet", type=float, default=0.25)
    p.add_argument("--frames", type=int, default=3)
    p.add_argument("--plot")
    a = p.parse_args(argv)
    f = h5py.File(a.base + ".h5", "r")
    h = float(f["grid"].attrs["h"][0])
    groups = frames(f, a.frames)
    times = [float(g.attrs["total_time"][0]) for g in groups]
    op = outlet_path(groups, h, a.theta, a.outlet)
    wp = wall_path(groups, h, a.theta, a.outlet)
    np.savetxt(a.base + "_outlet_path.csv", op, delimiter=",", header="x,v_y,density,particles", comments="")
    np.savetxt(a.base + "_wall_path.csv", wp, delimiter=",", header="s,y,sigma_n,tau,particles", comments="")
    print(f"frames at t = {', '.join(f'{t:.3f}' for t in times)} s")
    print(f"outlet: mean v_y {np.nanmean(op[:, 1]):.4f} m/s, mean density {np.nanmean(op[:, 2]):.1f} kg/m3 "
          f"-> {a.base}_outlet_path.csv")
    if len(wp):
        k = int(np.argmax(wp[:, 2]))
        print(f"wall: peak sigma_n {wp[k, 2]:.1f} Pa at s = {wp[k, 0]:.3f} m (y = {wp[k, 1]:.3f} m), "
              f"tau/sigma_n there {wp[k, 3] / wp[k, 2]:.4f} -> {a.base}_wall_path.csv")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 3, figsize=(13, 4))
        ax[0].plot(op[:, 0], op[:, 1], "o-")
        ax[0].set_xlabel("x [m]")
        ax[0].set_ylabel("v_y at the outlet [m/s]")
        ax[1].plot(op[:, 0], op[:, 2], "o-")
        ax[1].set_xlabel("x [m]")
        ax[1].set_ylabel("bulk density at the outlet [kg/m3]")
        if len(wp):
            ax[2].plot(wp[:, 2], wp[:, 1], "o-")
        ax[2].set_xlabel("wall normal stress [Pa]")
        ax[2].set_ylabel("y [m]")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main())
