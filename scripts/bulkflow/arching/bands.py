"""The plastic and displacement fields after the opening on two or more meshes at one outlet
width (issue 21 point 1, README "Mesh dependence: diagnosis"): does the plastic strain of the
opening localise into a band one element wide, and where does the motion start?

    python -m bulkflow.arching.bands --case B --height 1 --outlet-width 0.36 --n-arcs 30,60 --t-open 0.3

Each mesh runs the scene with the opening step in full (`*STOP CONDITION` at u_max > B/2, no
ARREST) and field frames every `t_open / --frames`; from the `.h5` (docs/output_format.md) it
prints, per frame of the opening step: u_max since the opening and where (radius / r_out,
angle / θ); the plastic strain of the opening ΔPEEQ = SDV1 − SDV1(opening), its maximum and the
element (row from the outlet, column from the axis); the width of its zone along each ray
(elements with ΔPEEQ above half the ray's maximum, in elements and in units of r_out, the median
over the rays that yield); the share of ∫ΔPEEQ dA in the outlet's first row and in the wall
column; the smallest area holding half of ∫ΔPEEQ dA (A50, over r_out²: it halves with each
refinement if the plastic strain sits in bands of a fixed number of elements); the return
regions (SDV5) of the elements with ΔPEEQ above 1 % of its maximum (elastic, MC plane, edges,
apex = tension); from the history the hourglass energy ALLAE over ALLIE. `--json` writes every
number; `--png` draws ΔPEEQ at two frames of each mesh.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from .runner import run_scene
from .scene import add_scene_arguments, scene_from_args


def _quad_area(xy: np.ndarray, conn: np.ndarray) -> np.ndarray:
    p = xy[conn]                                                     # (m, 4, 2)
    x, y = p[..., 0], p[..., 1]
    return 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1))


def band_widths(dpeeq: np.ndarray, mrad: int, n_arc: int) -> np.ndarray:
    """Per ray (column of the polar mesh) with plastic strain: the number of elements along the
    ray whose ΔPEEQ is above half the ray's maximum (nan where the ray has none)."""
    g = dpeeq.reshape(mrad, n_arc)
    mx = g.max(axis=0)
    w = np.full(n_arc, np.nan)
    ok = mx > 0
    w[ok] = np.sum(g[:, ok] > 0.5 * mx[ok], axis=0)
    return w


def analyse(scene, base: str, history: str | None = None) -> list[dict]:
    """Per frame of the opening step: the numbers the module docstring lists."""
    import h5py

    mrad, n = scene.n_radial(), scene.n_arc
    out = []
    with h5py.File(f"{base}.h5", "r") as f:
        x0 = f["mesh/coordinates"][:, :2]
        conn = f["mesh/connectivity"][...]
        frames = [f["frames"][k] for k in sorted(f["frames"])]
        last = max(int(fr.attrs["step"]) for fr in frames)
        opening = [fr for fr in frames if int(fr.attrs["step"]) == last]
        ref = opening[0]
        u0, p0 = ref["U"][...], ref["SDV1"][...]
        area = _quad_area(x0, conn)
        r_el = np.hypot(*x0[conn].mean(axis=1).T)
        # element radial size along each ray ~ r dθ (rows are nearly square)
        h_el = r_el * scene.th / n
        for fr in opening[1:]:
            du = np.linalg.norm(fr["U"][...] - u0, axis=1)
            i = int(np.argmax(du))
            r, a = math.hypot(*x0[i]), math.atan2(x0[i, 0], x0[i, 1])
            dp = np.maximum(fr["SDV1"][...] - p0, 0.0)
            w = band_widths(dp, mrad, n)
            wl = np.full(n, np.nan)
            g = dp.reshape(mrad, n)
            hh = h_el.reshape(mrad, n)
            mx = g.max(axis=0)
            ok = mx > 0
            for j in np.flatnonzero(ok):
                wl[j] = np.sum(hh[g[:, j] > 0.5 * mx[j], j]) / scene.r_out
            tot = float(np.sum(dp * area))
            # the smallest area that holds half of ∫ΔPEEQ dA: ∝ the element size for bands of fixed
            # element count, independent of the mesh for a diffuse (resolved) plastic zone
            order = np.argsort(dp)[::-1]
            cum = np.cumsum((dp * area)[order])
            k50 = int(np.searchsorted(cum, 0.5 * tot)) + 1 if tot > 0 else 0
            a50 = float(np.sum(area[order[:k50]]))
            rows = dp.reshape(mrad, n) * area.reshape(mrad, n)
            yld = fr["SDV5"][...].astype(int)
            active = yld[dp > 0.01 * dp.max()] if dp.max() > 0 else yld[:0]
            out.append(dict(
                step_time=float(fr.attrs["step_time"]), umax=float(du[i]), umax_r=r / scene.r_out,
                umax_angle=a / scene.th, dpeeq_max=float(dp.max()),
                dpeeq_max_row=int(np.argmax(dp) // n), dpeeq_max_col=int(np.argmax(dp) % n),
                band_elements=float(np.nanmedian(w)) if np.any(ok) else float("nan"),
                band_r_out=float(np.nanmedian(wl)) if np.any(ok) else float("nan"),
                share_outlet_row=float(rows[0].sum() / tot) if tot > 0 else float("nan"),
                share_wall_column=float(rows[:, -1].sum() / tot) if tot > 0 else float("nan"),
                area50_r_out2=a50 / scene.r_out ** 2, area50_elements=k50,
                yielding=int(np.sum(dp > 0.01 * dp.max())) if dp.max() > 0 else 0,
                region_counts={int(k): int(np.sum(active == k)) for k in range(6)}))
    if history:
        import csv
        with open(history) as fh:
            rows = list(csv.DictReader(fh))
        if rows and "ALLAE" in rows[0]:
            last = rows[-1]
            for o in out:
                o["allae_over_allie_end"] = float(last["ALLAE"]) / max(float(last["ALLIE"]), 1e-30)
    return out


def plot(runs: list[tuple], path) -> None:
    """ΔPEEQ of the opening at the second and the last frame of each run: runs = [(scene, base), ...]."""
    import h5py
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    fig, axs = plt.subplots(2, len(runs), figsize=(4.5 * len(runs), 8), squeeze=False)
    for k, (scene, base) in enumerate(runs):
        with h5py.File(f"{base}.h5", "r") as f:
            x0 = f["mesh/coordinates"][:, :2]
            conn = f["mesh/connectivity"][...]
            frames = [f["frames"][n] for n in sorted(f["frames"])]
            last = max(int(fr.attrs["step"]) for fr in frames)
            opening = [fr for fr in frames if int(fr.attrs["step"]) == last]
            p0 = opening[0]["SDV1"][...]
            for j, fr in enumerate([opening[min(2, len(opening) - 1)], opening[-1]]):
                dp = fr["SDV1"][...] - p0
                ax = axs[j, k]
                pc = PolyCollection(x0[conn], array=dp, cmap="viridis", edgecolors="none")
                ax.add_collection(pc)
                ax.set_aspect("equal")
                r = scene.r_out
                ax.set_xlim(0.0, 1.4 * r)
                ax.set_ylim(0.8 * r * math.cos(scene.th), 2.5 * r)
                fig.colorbar(pc, ax=ax, shrink=0.8)
                ax.set_title(f"n_arc {scene.n_arc}, B {scene.outlet_width * 100:.1f} cm, psi {scene.psi:g}"
                             f"{' (Davis)' if scene.flow_rule == 'davis' else ''}\nt = {fr.attrs['step_time']:.2f} s after opening: "
                             f"dPEEQ (max {dp.max():.3g})", fontsize=8)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m bulkflow.arching.bands", description=__doc__.split("\n\n")[0])
    p.add_argument("--outlet-width", type=float, required=True, help="B (m)")
    p.add_argument("--n-arcs", default="30,60", help="the meshes")
    p.add_argument("--frames", type=int, default=6, help="field frames per step")
    p.add_argument("--np", type=int, default=1)
    p.add_argument("--workdir", default="out/arching/bands")
    p.add_argument("--json", default="", help="write every number to this file")
    p.add_argument("--png", default="", help="draw ΔPEEQ of the opening to this file")
    add_scene_arguments(p)
    p.set_defaults(t_open=0.3)
    a = p.parse_args(argv)
    res, runs = {}, []
    for n in (int(v) for v in a.n_arcs.split(",")):
        a.n_arc = n
        # the opening step in full: FLOW far away, both ARREST rules off (the runner needs the condition)
        s = replace(scene_from_args(a, a.outlet_width), criterion="physical", flow_width_fraction=0.5,
                    ke_fraction=1e-12, growth=0.0, field_frames=a.frames)
        rec = run_scene(s, a.workdir, np=a.np, log=print, name=f"bands_B{a.outlet_width * 1000:.2f}mm_n{n}")
        fr = analyse(s, rec.base, f"{rec.base}_history.csv")
        runs.append((s, rec.base))
        res[n] = dict(n_elements=s.n_elements(), element_length=s.element_length(), wall=rec.wall, frames=fr)
        print(f"n_arc {n} ({s.n_elements()} el, outlet element {s.element_length() * 1e3:.1f} mm), {rec.wall:.0f} s wall")
        print("  t (s)  umax (mm) at r/r_out, angle/θ   ΔPEEQ max (row,col)  band: elements, /r_out  "
              "share row0, wall col  yielding  regions 0..5 (4 apex=tension)  ALLAE/ALLIE  A50/r_out^2 (elements)")
        for o in fr:
            rc = o["region_counts"]
            print(f"  {o['step_time']:.3f}  {o['umax'] * 1e3:8.3f} at {o['umax_r']:.3f}, {o['umax_angle']:.2f}   "
                  f"{o['dpeeq_max']:.2e} ({o['dpeeq_max_row']},{o['dpeeq_max_col']})   "
                  f"{o['band_elements']:.1f}, {o['band_r_out']:.3f}   "
                  f"{o['share_outlet_row']:.2f}, {o['share_wall_column']:.2f}   {o['yielding']:6d}   "
                  f"{[rc[k] for k in range(6)]}   {o.get('allae_over_allie_end', float('nan')):.3f}   "
                  f"{o['area50_r_out2']:.4f} ({o['area50_elements']})")
    if a.png:
        plot(runs, a.png)
    if a.json:
        Path(a.json).parent.mkdir(parents=True, exist_ok=True)
        Path(a.json).write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
