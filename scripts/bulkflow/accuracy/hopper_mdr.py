"""Family `hopper-mdr`: the steady mass discharge rate of the MPM wedge hopper, refined in the cell.

The thesis ch. 4 wedge hopper of bulkflow-make-mpm-hopper (θ 30°, outlet b 0.25 m, Mohr–Coulomb
sand of Table 4.2/4.3, uGIMP, 2 × 2 particles per cell, inflow on top so the discharge stays
steady) written by bulkflow.mpm.hopper_run.scene_text, with cells h = 0.125/n m for n = 1.5, 2.5,
3.5, … so that the outlet edge x = b/2 always falls mid-cell (bulkflow-mpm-study convergence
explains why mixing edge offsets makes the series jump). The steady MDR is
bulkflow.mpm.discharge.mean_discharge_rate (regression of the discharged mass from 0.5 s after
opening); the full hopper's is twice the half model's. Also measured, with its own observed
order and reference: the normal force on the discharging wall (wall_force).

No closed form: the reference is Richardson-extrapolated from the three finest members, with the
grid convergence index as its uncertainty; each member's error is |MDR_h/MDR_ext − 1|. When the
three finest do not converge monotonically there is no observed order and the command says so.
--quick: a 1 m fill, 0.5 s fill and 1.0 s discharge (minutes); full: the thesis's 3 m fill,
1 s fill and 1.5 s discharge (the default of bulkflow-mpm-study convergence).
"""
from __future__ import annotations

import numpy as np

from ..mpm.discharge import mean_discharge_rate
from ..mpm.hopper_run import scene_text
from ..mpm.hopper_scene import with_mu_of_i
from .runs import particles_from_log

EDGE_CELLS = [1.5, 2.5, 3.5, 4.5, 5.5]
QUICK_EDGE_CELLS = [1.5, 2.5, 3.5, 4.5, 5.5]
FULL = dict(height=3.0, fill_time=1.0, discharge_time=1.5)
QUICK = dict(height=1.0, fill_time=0.5, ramp=0.3, discharge_time=1.0)
# bulkflow-accuracy --pic-time: *MPM CONTROLS, PIC TIME in every member (0: the scene's FLIP=0.99)
PIC_TIME = 0.0
# bulkflow-accuracy --inertial-friction: (φ2 [deg], I0, d [m], ρs [kg/m3]) or None (static MC)
INERTIAL_FRICTION = None
# bulkflow-accuracy --hopper-scene KEY=VALUE: further hopper_scene keywords in every member (a
# variant family: wall_friction=0, psi_constant=0, ...)
SCENE_EXTRA: dict = {}
# bulkflow-accuracy --open-edge: the wall holds the particles, not the nodes, at the outlet's edge
OPEN_EDGE = False


def members(quick: bool) -> list[dict]:
    rows = []
    for n in (QUICK_EDGE_CELLS if quick else EDGE_CELLS):
        h = 0.125 / n
        rows.append({"cell": h, "h": h, "quick_case": quick, "elements": 0,
                     "label": f"cell {1000 * h:.1f} mm, 2×2 PPC, uGIMP"})
    return rows


def scene(member: dict) -> str:
    kw = dict(QUICK if member["quick_case"] else FULL)
    if PIC_TIME > 0:
        kw["pic_time"] = PIC_TIME
    kw.update(SCENE_EXTRA)
    if OPEN_EDGE:
        kw["open_edge"] = True
    # 2 particle frames in the fill step, 6 in the discharge: the wall force averages the last 3
    text = scene_text(cell=member["cell"], ppc=2, shape="GIMP", field_frames=2, discharge_frames=6, **kw)
    if INERTIAL_FRICTION is not None:
        # the μ(I) block appended to the sand's MC constants (the scene's material is a *USER
        # MATERIAL with its VUSDFLD: umat/README.md props layout, docs/mu_of_i.md)
        text = with_mu_of_i(text, "1., " + ", ".join(f"{v:.9g}" for v in INERTIAL_FRICTION))
    return text


def wall_force(base, cell: float) -> float:
    """Normal force per metre of depth on the discharging inclined wall, N/m: the wall normal
    stress of the particles 1-2 cells from the wall (bulkflow.mpm.paths.wall_path, bins of 0.1 m
    whatever the cell) summed along the wall, averaged over the last 3 particle frames."""
    import h5py

    from ..mpm.paths import frames, wall_path

    with h5py.File(f"{base}.h5", "r") as f:
        wp = wall_path(frames(f, 3), cell, 30.0, 0.25, bin_width=0.1)
    return float(np.nansum(wp[:, 2]) * 0.1)


def measure(base, member: dict) -> dict:
    hist = np.genfromtxt(f"{base}_history.csv", delimiter=",", names=True)
    mdr = 2.0 * float(mean_discharge_rate(hist))
    return {"value": mdr, "wall_force": wall_force(base, member["cell"]), "particles": particles_from_log(base)}


KIND = {
    "name": "hopper-mdr",
    "title": "MPM wedge hopper (thesis ch. 4), steady MDR of the full hopper, cell size h",
    "parameter": "cell h",
    "parameter_unit": "m",
    "quantity": "MDR",
    "error_measure": "|MDR_h / MDR_Richardson − 1|, MDR the full hopper's steady discharge rate, kg/s/m",
    "reference": "richardson",
    "also": {"wall_force": "discharging wall normal force, N/m (last 3 frames)"},
    "members": members,
    "scene": scene,
    "measure": measure,
    "expected_order": "between 1 and 2 for uGIMP in smooth flow; the outlet's free fall and the "
                      "wall contact on grid nodes usually give about 1",
}
