"""Picture of a bulkflow run of a hopper scene: the deformed mesh of one frame of BASE.h5
coloured by vertical stress (or pressure, PEEQ, ...), the analytic rigid walls of the scene
drawn, and the history (energies, wall forces) beside it.

    bulkflow-hopper-plot out/default/wedge_hopper.h5 --scene inputs/demo/wedge_hopper.inp \
        -o out/default/wedge_hopper.png [--field sv|p|peeq|s11|s22|s12|umag] [--frame -1]
        [--no-mirror] [--magnify 1] [--history BASE_history.csv]

The half model (symmetry on x = 0) is mirrored to show the whole hopper, unless --no-mirror.
3D (C3D8R) results are shown on their back face (the smallest z). Stresses in kPa, compression
positive for sv (= −S22) and p (= −tr S / 3). Agg backend: no display needed.
"""
from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

from bulkflow.post.run_output import FieldFile, read_history, read_scene_facts, scene_weight  # noqa: E402

FIELDS = {
    "sv": ("vertical stress $\\sigma_v = -S_{22}$ (kPa)", lambda f: -f["S"][:, 1] / 1e3),
    "p": ("pressure $p = -\\mathrm{tr}\\,S/3$ (kPa)", lambda f: -f["S"][:, :3].sum(axis=1) / 3e3),
    "s11": ("$S_{11}$ (kPa)", lambda f: f["S"][:, 0] / 1e3),
    "s22": ("$S_{22}$ (kPa)", lambda f: f["S"][:, 1] / 1e3),
    "s12": ("$S_{12}$ (kPa)", lambda f: f["S"][:, 3] / 1e3),
    "peeq": ("PEEQ", lambda f: f["PEEQ"] if "PEEQ" in f else f["SDV1"]),
}


def _face_polygons(ff: FieldFile, x: np.ndarray):
    """Quads to draw (m, 4, 2) and the element index of each."""
    conn = ff.connectivity
    if conn.shape[1] == 4:
        return x[conn][:, :, :2], np.arange(len(conn))
    z = ff.x0[:, 2]
    back = np.all(np.isclose(z[conn[:, :4]], z.min()), axis=1)
    idx = np.nonzero(back)[0]
    return x[conn[idx, :4]][:, :, :2], idx


def plot_hopper(h5_path, scene_path=None, history_path=None, field="sv", frame=-1, mirror=True,
                magnify=1.0, title=None):
    """A matplotlib Figure; returns (fig, info dict)."""
    ff = FieldFile(h5_path)
    fr = ff.frame(frame)
    x = fr.coordinates
    if magnify != 1.0:
        x = ff.x0 + magnify * (fr.coordinates - ff.x0)
    polys, idx = _face_polygons(ff, x)
    if field == "umag":
        label = "displacement |U| (mm)"
        u = np.linalg.norm(fr.fields["U"], axis=1) * 1e3
        values = u[ff.connectivity[idx, :4]].mean(axis=1)
    else:
        label, fn = FIELDS[field]
        values = fn(fr.fields)[idx]
    facts = read_scene_facts(scene_path) if scene_path else None

    has_history = history_path is not None and Path(history_path).exists()
    fig = plt.figure(figsize=(12.5, 7.2) if has_history else (7.5, 7.2))
    if has_history:
        gs = fig.add_gridspec(2, 2, width_ratios=[1.35, 1], hspace=0.32, wspace=0.28)
        ax = fig.add_subplot(gs[:, 0])
    else:
        ax = fig.add_subplot(1, 1, 1)

    all_polys, all_values = [polys], [values]
    if mirror:
        mp = polys.copy()
        mp[:, :, 0] *= -1
        all_polys.append(mp[:, ::-1])
        all_values.append(values)
    pc = PolyCollection(np.concatenate(all_polys), array=np.concatenate(all_values), cmap="viridis",
                        edgecolors=(0, 0, 0, 0.25), linewidths=0.2)
    ax.add_collection(pc)
    cb = fig.colorbar(pc, ax=ax, shrink=0.8, pad=0.02)
    cb.set_label(label)

    xmin, xmax = polys[:, :, 0].min(), polys[:, :, 0].max()
    ymin, ymax = polys[:, :, 1].min(), polys[:, :, 1].max()
    if mirror:
        xmin = -xmax
    if facts:
        for name, segs in facts.walls.items():
            for k, s in enumerate(segs):
                pts = s.points()
                style = dict(color="crimson" if "PLATE" in name.upper() else "black", lw=2.2)
                ax.plot(pts[0], pts[1], **style, label=name if k == 0 else None)
                if mirror:
                    ax.plot(-pts[0], pts[1], **style)
        for name, pl in facts.planes.items():
            if len(pl) == 2:
                p, n = np.array(pl[0][:2]), np.array(pl[1][:2])
                t = np.array([n[1], -n[0]]) / max(np.linalg.norm(n), 1e-300)
                span = 1.2 * max(ymax - ymin, xmax - xmin)
                a, b = p - span * t, p + span * t
                ax.plot([a[0], b[0]], [a[1], b[1]], color="black", lw=2.2)
                if mirror:
                    ax.plot([-a[0], -b[0]], [a[1], b[1]], color="black", lw=2.2)
    ax.axvline(0.0, color="0.5", lw=0.6, ls="--")
    pad = 0.06 * (ymax - ymin)
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(min(0.0, ymin) - pad, ymax + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    head = title or (facts.heading if facts and facts.heading else Path(h5_path).stem)
    mag = f", displacements ×{magnify:g}" if magnify != 1.0 else ""
    ax.set_title(f"{textwrap.fill(head, 66)}\nt = {fr.total_time:.4g} s (increment {fr.increment}){mag}", fontsize=9)

    info = {"frame_time": fr.total_time, "field": field, "min": float(values.min()), "max": float(values.max())}
    if has_history:
        h = read_history(history_path)
        t = h["time"]
        ax1 = fig.add_subplot(gs[0, 1])
        for name in ("ALLKE", "ALLIE", "ALLVD", "ALLFD", "ALLWK", "ALLAE", "ETOTAL"):
            if name in h:
                ax1.plot(t, h[name], label=name, lw=1.2)
        ax1.set_xlabel("time (s)")
        ax1.set_ylabel("energy (J" + ("/m)" if ff.ndim == 2 else ")"))
        ax1.legend(fontsize=7, ncol=2)
        ax1.grid(alpha=0.3)
        ax1.set_title("energies", fontsize=9)
        ax2 = fig.add_subplot(gs[1, 1])
        weight = None
        if facts is not None and facts.gravity > 0:
            try:
                weight = scene_weight(facts, ff)
            except ValueError:
                weight = None
        total = np.zeros_like(t)
        for col in h:
            if col.startswith("WALLF2_"):
                fy = -h[col]          # the force ON the wall; the wall carries −F_y of the fill
                total += fy
                ax2.plot(t, fy / (weight or 1.0), label=f"wall {col[7:]}", lw=1.2)
        ax2.plot(t, total / (weight or 1.0), "k--", label="sum", lw=1.0)
        ax2.set_xlabel("time (s)")
        ax2.set_ylabel("vertical load on walls / fill weight" if weight else "vertical load on walls (N)")
        ax2.legend(fontsize=7)
        ax2.grid(alpha=0.3)
        ax2.set_title("wall loads" + (f" (fill weight {weight / 1e3:.4g} kN{'/m' if ff.ndim == 2 else ''})"
                                      if weight else ""), fontsize=9)
    ff.close()
    return fig, info


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="bulkflow-hopper-plot", description=__doc__.split("\n\n")[0])
    p.add_argument("h5", help="BASE.h5 of a run")
    p.add_argument("--scene", help="the scene .inp (walls, density, gravity)")
    p.add_argument("--history", help="BASE_history.csv (default: next to the .h5)")
    p.add_argument("-o", "--output", help="PNG to write (default: BASE.png)")
    p.add_argument("--field", choices=sorted(list(FIELDS) + ["umag"]), default="sv")
    p.add_argument("--frame", type=int, default=-1, help="frame index (default: the last)")
    p.add_argument("--no-mirror", action="store_true", help="show the half model only")
    p.add_argument("--magnify", type=float, default=1.0, help="displacement magnification")
    p.add_argument("--title")
    a = p.parse_args(argv)
    h5 = Path(a.h5)
    history = Path(a.history) if a.history else h5.with_name(h5.stem + "_history.csv")
    out = Path(a.output) if a.output else h5.with_suffix(".png")
    fig, info = plot_hopper(h5, a.scene, history, a.field, a.frame, not a.no_mirror, a.magnify, a.title)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=130, bbox_inches="tight")
    print(f"picture: {out} ({info['field']} from {info['min']:.4g} to {info['max']:.4g} at t = {info['frame_time']:.4g} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
