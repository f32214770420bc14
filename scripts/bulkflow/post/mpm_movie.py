"""Animation of a 2D MPM run: the particles of every frame of BASE.h5 coloured by their speed |v|,
the scene's walls drawn (a wall that a later step deletes, the outlet, solid while it is closed and
dashed once open), the outflow level dotted.

    bulkflow-mpm-movie BASE --scene SCENE.inp -o out.gif [--fps 10] [--no-mirror] [--vmax V] [--linear]

GIF through matplotlib's PillowWriter (Pillow comes with matplotlib); a name ending in .mp4 uses
ffmpeg, which must be installed. A half model (a vertical symmetry wall) is mirrored about its
axis to show the whole hopper, unless --no-mirror. The colour scale runs from 0 to --vmax (default:
the 99.5th percentile of |v| over all frames, so a few fast particles below the outlet do not wash
out the rest), logarithmic over three decades below it (--linear: from 0). Frames: /particles/NNNNNN of BASE.h5 (coordinates, V, volume; attributes step,
total_time; src/mpm/README.md "Outputs").
"""
from __future__ import annotations

import argparse
import sys

import matplotlib

matplotlib.use("Agg")
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import animation, colors  # noqa: E402

from bulkflow.post.mpm_scene import read_mpm_scene  # noqa: E402
from bulkflow.post.run_output import read_scene_facts  # noqa: E402

# The log colour scale spans vmax/1000 .. vmax: the slow creep along the walls (mass flow) and the
# stagnant zones (funnel flow) stay apart, where a linear scale shows only the fast core.
LOG_DECADES_SHOWN = 1000.0


def particle_frames(h5_path):
    """[(step, total_time, xy (n, 2), speed (n,), side (n,))] of every particle frame, in order;
    side = sqrt of the particle's current volume (area per unit depth)."""
    out = []
    with h5py.File(h5_path, "r") as f:
        for key in sorted(f["particles"].keys()):
            g = f["particles"][key]
            x, v = g["coordinates"][:], g["V"][:]
            out.append((int(g.attrs["step"][0]), float(g.attrs["total_time"][0]), x[:, :2],
                        np.linalg.norm(v[:, :2], axis=1), np.sqrt(g["volume"][:])))
    return out


def _mirror(xy, axis_x):
    if axis_x is None:
        return xy
    m = xy.copy()
    m[:, 0] = 2 * axis_x - m[:, 0]
    return np.vstack([xy, m])


def _clip(p, axis_x):
    """The part of segment p (2, 2) on the model's side of the axis x = axis_x (x >= axis_x)."""
    if axis_x is None or (p[:, 0] >= axis_x).all() or (p[:, 0] < axis_x).all():
        return p
    a, b = p if p[0, 0] < axis_x else p[::-1]
    s = (axis_x - a[0]) / (b[0] - a[0])
    return np.array([[axis_x, a[1] + s * (b[1] - a[1])], b])


def _segments(scene, facts, step, axis_x):
    """(points (2, k), style) of every wall to draw in `step`, mirrored about the axis."""
    out = []
    for w in scene.walls:
        if w.kind == "SYMMETRY":
            continue
        pts = _clip(np.array([w.p0, w.p1], dtype=float), axis_x).T
        if w.last_step is not None:          # the closable outlet
            style = dict(c="k", lw=2.5) if w.active(step) else dict(c="crimson", lw=2, ls="--")
        elif w.active(step):
            style = dict(c="k", lw=2.5)
        else:
            continue
        out.append((pts, style))
    for segs in facts.walls.values():         # rigid-surface walls (SEGMENTS): lines and arcs
        for s in segs:
            out.append((s.points(), dict(c="k", lw=2.5)))
    if axis_x is not None:
        out += [(np.array([2 * axis_x - p[0], p[1]]), st) for p, st in out]
    return out


def make_movie(base, scene_path, output, fps=10, mirror=True, vmax=None, dpi=80, title=None, linear=False):
    """Write the animation; returns dict(frames, vmax, particles (last frame), output)."""
    frames = particle_frames(f"{base}.h5")
    if not frames:
        raise SystemExit(f"{base}.h5: no particle frames")
    scene = read_mpm_scene(scene_path)
    facts = read_scene_facts(scene_path)
    axis_x = scene.symmetry_x() if mirror else None
    if vmax is None:
        vmax = float(np.percentile(np.concatenate([f[3] for f in frames]), 99.5)) or 1.0
    # the view: every wall and every particle position of the run
    pts = np.vstack([_mirror(f[2], axis_x) for f in frames] +
                    [p.T for p, _ in _segments(scene, facts, frames[0][0], axis_x)])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    if scene.outflow is not None:
        lo[1] = min(lo[1], scene.outflow)
    pad = 0.04 * (hi - lo).max()
    lo, hi = lo - pad, hi + pad
    height = 7.0
    width = max(3.0, height * (hi[0] - lo[0]) / (hi[1] - lo[1]) + 1.6)
    fig, ax = plt.subplots(figsize=(width, height), dpi=dpi)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    copies = 2 if axis_x is not None else 1
    norm = (colors.Normalize(0.0, vmax) if linear else
            colors.LogNorm(vmax / LOG_DECADES_SHOWN, vmax, clip=True))
    sc = ax.scatter(*_mirror(frames[0][2], axis_x).T, c=np.tile(frames[0][3], copies), s=1.0,
                    cmap="viridis", norm=norm, marker="s", linewidths=0)
    fig.colorbar(sc, ax=ax, shrink=0.7, label="particle speed |v| [m/s]")
    fig.suptitle(title or facts.heading, fontsize=9)
    fig.tight_layout()
    # markers: squares of the particle's own area (in points, once the layout is final), a little
    # more so that rounding to pixels leaves no gaps where the particles tile the space
    pt_per_m = 1.15 * (ax.transData.transform([1.0, 0.0])[0] - ax.transData.transform([0.0, 0.0])[0]) * 72.0 / dpi
    lines = []
    if scene.outflow is not None:
        ax.axhline(scene.outflow, c="0.5", lw=0.8, ls=":")
        ax.annotate("outflow level", (hi[0], scene.outflow), xytext=(-4, 3), textcoords="offset points",
                    ha="right", fontsize=8, color="0.4")
    label = ax.text(0.02, 0.98, "", transform=ax.transAxes, va="top", fontsize=10)

    def draw(i):
        step, t, xy, speed, side = frames[i]
        sc.set_offsets(_mirror(xy, axis_x))
        sc.set_array(np.tile(speed, copies))
        sc.set_sizes(np.tile((side * pt_per_m) ** 2, copies))
        for ln in lines:
            ln.remove()
        lines.clear()
        for p, style in _segments(scene, facts, step, axis_x):
            lines.extend(ax.plot(p[0], p[1], **style))
        outlet = ""
        if scene.outlets():
            opened = any(not w.active(step) for w in scene.outlets())
            outlet = " (outlet open)" if opened else " (outlet closed)"
        label.set_text(f"t = {t:4.2f} s, step {scene.step_name(step)}{outlet}")
        return [sc, label, *lines]

    anim = animation.FuncAnimation(fig, draw, frames=len(frames), blit=False)
    if str(output).endswith(".mp4"):
        writer = animation.FFMpegWriter(fps=fps)
    else:
        writer = animation.PillowWriter(fps=fps)
    anim.save(str(output), writer=writer, dpi=dpi)
    plt.close(fig)
    return dict(frames=len(frames), vmax=vmax, particles=len(frames[-1][2]), output=str(output))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("base", help="output base of the run (BASE.h5)")
    p.add_argument("--scene", required=True, help="the scene the run was made from (walls, outflow)")
    p.add_argument("-o", "--output", required=True, help="BASE.gif (or .mp4 with ffmpeg)")
    p.add_argument("--fps", type=float, default=10.0)
    p.add_argument("--dpi", type=int, default=80)
    p.add_argument("--vmax", type=float, help="top of the colour scale [m/s]")
    p.add_argument("--no-mirror", action="store_true", help="draw the half model only")
    p.add_argument("--linear", action="store_true", help="linear colour scale from 0 (default: log, 3 decades)")
    a = p.parse_args(argv)
    r = make_movie(a.base, a.scene, a.output, a.fps, not a.no_mirror, a.vmax, a.dpi, linear=a.linear)
    print(f"  animation: {r['output']} ({r['frames']} frames, |v| colour scale 0..{r['vmax']:.2f} m/s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
