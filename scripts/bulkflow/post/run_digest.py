"""Three-line digest of a bulkflow run from its files (history CSV, HDF5 frames, the scene):

1. quasi-static check: final ALLKE/ALLIE (and the kinetic energy recomputed from the last
   frame's velocities with lumped masses ρV₀/nen, as a cross-check of ALLKE);
2. walls: normal force per unit depth on each straight analytic wall, the vertical load of every
   wall against the weight of the fill, and their sum / weight (1 at rest);
3. energy balance: |ETOTAL| against max(ALLIE, ALLWK, ALLKE).

    bulkflow-run-digest out/default/wedge_hopper --scene inputs/demo/wedge_hopper.inp

Wall forces in the history (WALLF<i>_<wall>) are the forces ON the walls. The values printed are
medians over the history rows of the last 10 % of the run, robust to a single odd row (the last
row, after a shortened last increment, has been seen off by up to a factor 2); the last row's sum
is shown too.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from bulkflow.post.run_output import FieldFile, element_areas, hex_volumes, read_history, read_scene_facts, scene_weight


def frame_kinetic_energy(ff: FieldFile, facts) -> float | None:
    """½ Σ m v² of the last frame, lumped masses ρV₀/nen (one-material scenes)."""
    fr = ff.frame(-1, names={"V"})
    if "V" not in fr.fields or not facts.densities:
        return None
    rho = next(iter(facts.densities.values()))
    conn = ff.connectivity
    if conn.shape[1] == 8:
        vol = hex_volumes(ff.x0, conn)
    else:
        vol = element_areas(ff.x0, conn) * next(iter(facts.thickness.values()), 1.0)
    m = np.zeros(len(ff.x0))
    np.add.at(m, conn.ravel(), np.repeat(rho * vol / conn.shape[1], conn.shape[1]))
    v = fr.fields["V"]
    return float(0.5 * (m * (v ** 2).sum(axis=1)).sum())


def digest(base, scene=None) -> list[str]:
    base = Path(base)
    h = read_history(base.with_name(base.name + "_history.csv"))
    facts = read_scene_facts(scene) if scene else None
    ff = None
    h5 = base.with_name(base.name + ".h5")
    if h5.exists():
        ff = FieldFile(h5)
    n = len(h["time"])
    tail = h["time"] >= h["time"][-1] - 0.1 * (h["time"][-1] - h["time"][0])
    if tail.sum() < 2:
        tail = np.arange(n) >= n - 2
    unit = "/m" if ff is None or ff.ndim == 2 else ""

    ke, ie = h["ALLKE"][-1], h["ALLIE"][-1]
    line1 = f"quasi-static: final ALLKE/ALLIE = {ke / ie:.3g} (ALLKE {ke:.4g} J{unit}, ALLIE {ie:.4g} J{unit})" \
        if ie > 0 else f"quasi-static: final ALLKE = {ke:.4g} J{unit}, ALLIE = {ie:.4g}"
    if ff is not None and facts is not None:
        ke_frame = frame_kinetic_energy(ff, facts)
        if ke_frame is not None:
            line1 += f"; KE from the last frame's velocities {ke_frame:.3g} J{unit}"
            if ie > 0:
                line1 += f" (ratio {ke_frame / ie:.2g})"

    weight = scene_weight(facts, ff) if (facts and ff is not None and facts.gravity > 0) else None
    walls = sorted({c.split("_", 1)[1] for c in h if c.startswith("WALLF1_")})
    parts = []
    total_last, total_med = 0.0, 0.0
    for w in walls:
        fx, fy = h["WALLF1_" + w], h["WALLF2_" + w]
        segs = facts.walls.get(w, []) if facts else []
        normal = segs[0].material_normal() if len(segs) == 1 else None
        text = w
        if normal is not None:
            fn = -(fx * normal[0] + fy * normal[1])       # compression of the wall, N per unit depth
            text += f" normal {np.median(fn[tail]) / 1e3:.4g} kN{unit},"
        v_med = float(np.median(-fy[tail]))
        total_last += -fy[-1]
        total_med += v_med
        text += f" vertical {v_med / weight:.3f} W" if weight else f" vertical {v_med / 1e3:.4g} kN{unit}"
        parts.append(text)
    if weight:
        line2 = (f"walls (medians over the last 10 % of the run; fill weight W = {weight / 1e3:.4g} kN{unit}): "
                 + "; ".join(parts) + f"; sum of vertical wall loads {total_med / weight:.3f} W"
                 + f" (last row {total_last / weight:.3f} W)")
    else:
        line2 = "walls: " + ("; ".join(parts) if parts else "none")

    et = h["ETOTAL"][-1]
    scale = max(abs(h["ALLIE"][-1]), abs(h["ALLWK"][-1]), abs(h["ALLKE"][-1]), 1e-300)
    line3 = (f"energy balance: ETOTAL = {et:.4g} J{unit} = {100 * abs(et) / scale:.2g} % of max(ALLIE, ALLWK, ALLKE)"
             f" (ALLWK {h['ALLWK'][-1]:.4g}, ALLFD {h['ALLFD'][-1]:.4g}, ALLVD {h['ALLVD'][-1]:.4g},"
             f" ALLAE {h['ALLAE'][-1]:.4g} = {100 * h['ALLAE'][-1] / max(ie, 1e-300):.2g} % of ALLIE)")
    if ff is not None:
        ff.close()
    return [line1, line2, line3]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="bulkflow-run-digest", description=__doc__.split("\n\n")[0])
    p.add_argument("base", help="output base of the run (BASE_history.csv, BASE.h5)")
    p.add_argument("--scene", help="the scene .inp (density, gravity, walls)")
    a = p.parse_args(argv)
    for line in digest(a.base, a.scene):
        print("  " + line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
