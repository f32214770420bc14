"""The flat-bottomed quasi-2D bin of thesis ch. 5 as a material-point scene for bulkflow.

    bulkflow-make-bin -o bin.inp [--case concentric|eccentric] [--sand NDNS|DS] [--density 1800] ...

Geometry (docs/bins.md says how it is read from the thesis): a flat-bottomed bin of width
`width` (0.172 m: the camera's 1024 px at 0.168 mm/px span the whole bin length), filled to
`fill` (0.200 m) above the bottom, one outlet of width `outlet` (11.8 mm) in the bottom at y = 0.
- concentric: outlet in the middle; half model x in [0, width/2] with a mirrored symmetry plane
  on x = 0 (mpm_mirror, as the ch. 4 hopper), the side wall at x = width/2;
- eccentric: outlet against the right wall (x in [width - outlet, width]); full model, walls at
  x = 0 and x = width; `right_wall_friction` (deg) gives the right wall its own friction (34 deg:
  the thesis's check that the 7 deg wall is why the eccentric bin discharges faster).
2D plane strain, per metre of depth. The bottom left and right of the outlet is a fixed floor; the
outlet is a wall deleted in the discharge step (as the hopper's). Grid: node lines on the walls
and on the mirror; the cell is outlet / (2k + 1) (`edge_cells` = k), which puts the concentric
outlet's edge mid-cell (its resolved width is the nominal one) and the eccentric outlet's inner
edge on a node line (resolved about half a cell narrower: docs/bins.md, "Grid").

Sand (thesis Table 5.3): E 8 MPa, nu 0.3, rho_i 1800 kg/m3 (or the 1600 variant), wall friction
7 deg, c = 0.
- NDNS: no dilation, no softening: phi = phi_cv = 34 deg, psi = 0 (built-in *MOHR COULOMB);
- DS: phi from phi_peak = phi_cv + 0.8 psi_max = 46 deg (thesis eq. 5.4, Bolton) and psi from
  psi_max = 15 deg, both falling linearly with the volumetric strain to phi_cv and 0 at
  eps_cv = ln(eta_i / eta_cv) (thesis eq. 4.1): our MC VUMAT's angle table on field 1 = tr LE
  (VUSDFLD). eta_i = rho_i / rho_s, eta_cv = rho_cv / rho_s with rho_cv = 1387 kg/m3 (loose
  cubic packing) and rho_s = 1800 / 0.68 (the thesis's eta_i = 0.68 at rho_i = 1800).

Steps: FILL (outlet closed, gravity ramped smoothly in total time, local damping so the fill
settles), DISCHARGE (outlet wall deleted, no damping, particles 2 cells below the outlet leave
through *OUTFLOW, no inflow: the bin empties as in the experiments). `fill_layers` = N > 1 fills in
N layers instead: the first placed, each further one topped up by *INFLOW in a step of its own
(bin_steps; docs/bins.md says what it changes).

`side_friction` = t writes `*MPM SIDE FRICTION, GAP=t, FRICTION=tan(phi_w)` (the front and back
glass walls of the quasi-2D bin, issue 20 point 2); the keyword needs a solver that has it.
"""
import argparse
import math
import sys

from .hopper_scene import _num, controls_line, eps_cv_from_eta

OUTLET = 0.0118              # m, thesis §5.1
FILL = 0.200                 # m, initial material height
WIDTH = 1024 * 0.168e-3      # m, bin length: the camera's field of view (§5.2)
D_PARTICLE = 0.71e-3         # m, ASTM C778 20-30 sand
RHO_I = 1800.0               # kg/m3, Table 5.3
RHO_CV = 1387.0              # kg/m3, Table 5.3 (DS)
ETA_I_1800 = 0.68            # initial packing fraction at rho_i = 1800 (§5.3)
RHO_SOLID = RHO_I / ETA_I_1800
YOUNG, POISSON = 8.0e6, 0.3
PHI_CV, PSI_MAX = 34.0, 15.0
PHI_WALL = 7.0
CASES = ("concentric", "eccentric")
SANDS = ("NDNS", "DS")


def phi_peak(phi_cv=PHI_CV, psi_max=PSI_MAX):
    """Bolton's peak friction angle for quartz sand in plane strain (thesis eq. 5.4)."""
    return phi_cv + 0.8 * psi_max


def eps_cv(rho_i=RHO_I, rho_cv=RHO_CV, rho_solid=RHO_SOLID):
    """Volumetric strain at which the DS sand reaches the constant-volume state (thesis eq. 4.1)."""
    return eps_cv_from_eta(rho_cv / rho_solid, eta_i=rho_i / rho_solid)


def bin_cell(outlet=OUTLET, edge_cells=1):
    """Cell size: outlet / (2k + 1), k = `edge_cells` (the concentric half-outlet is k + 1/2 cells)."""
    if edge_cells < 0:
        raise ValueError("edge_cells must be >= 0")
    return outlet / (2 * edge_cells + 1)


def bin_geometry(case="concentric", cell=None, outlet=OUTLET, width=WIDTH, fill=FILL, edge_cells=1):
    """The model's geometry (all in m; y = 0 is the bottom). Returns a dict: cell, x_left (left wall,
    or the mirror of the half model), x_right (right wall), x_out0, x_out1 (the outlet's span in the
    model), width_model (width of the bin as resolved: walls on node lines), outlet_model (full
    outlet width resolved by the grid: concentric the nominal one, eccentric the nominal one too;
    the grid treats its inner edge differently: docs/bins.md), half (True: half model)."""
    if case not in CASES:
        raise ValueError(f"case must be one of {CASES}")
    if not (outlet > 0 and fill > 0 and width > 0) or (cell is not None and cell <= 0):
        raise ValueError("outlet, width, fill and cell must be > 0")
    h = cell or bin_cell(outlet, edge_cells)
    if width < outlet + 2 * h:
        raise ValueError(f"the bin ({width:g} m) must be wider than the outlet ({outlet:g} m) by 2 cells")
    if case == "concentric":
        n = max(2, round(0.5 * width / h))
        return dict(cell=h, x_left=0.0, x_right=n * h, x_out0=0.0, x_out1=0.5 * outlet,
                    width_model=2 * n * h, outlet_model=outlet, half=True, fill=fill)
    n = max(3, round(width / h))
    return dict(cell=h, x_left=0.0, x_right=n * h, x_out0=n * h - outlet, x_out1=n * h,
                width_model=n * h, outlet_model=outlet, half=False, fill=fill)


def _material(w, sand, density, young, poisson, phi_cv, psi_max, eps):
    w("*MATERIAL, NAME=MC-SAND")
    w("*DENSITY")
    w(_num(density))
    if sand == "NDNS":
        w("*ELASTIC")
        w(f"{_num(young)}, {_num(poisson)}")
        w("*MOHR COULOMB")
        w(f"{_num(phi_cv)}, 0.")
        w("*MOHR COULOMB HARDENING")
        w("0., 0.")
        return
    # our MC VUMAT with a 2-row angle table on field 1 (umat/README.md props layout):
    # (phi_peak, psi_max) at eps_v = 0 -> (phi_cv, 0) at eps_cv, held beyond the ends
    pk = phi_peak(phi_cv, psi_max)
    w("*USER MATERIAL, CONSTANTS=22")
    w(f"{_num(young)}, {_num(poisson)}, {_num(pk)}, 0., 0., 0., 0., 0.")
    w("0., 0., 0., 0., 2., 1., 0., 0.")
    w(f"{_num(pk)}, {_num(psi_max)}, 0., {_num(phi_cv)}, 0., {_num(eps)}")
    w("*DEPVAR")
    w("8")
    w("*USER DEFINED FIELD")


def bin_scene(case="concentric", sand="NDNS", cell=None, edge_cells=1, ppc=2, outlet=OUTLET, width=WIDTH,
              fill=FILL, density=RHO_I, rho_cv=RHO_CV, young=YOUNG, poisson=POISSON, phi_cv=PHI_CV,
              psi_max=PSI_MAX, wall_friction=PHI_WALL, right_wall_friction=None, floor_friction=None,
              fill_time=0.3, ramp=0.2, discharge_time=8.0, fill_damping=0.1, flip=0.99, cfl=0.3,
              shape="GIMP", field_dt=0.1, history_dt=0.01, outflow_cells=2.0, side_friction=None,
              max_dilation=0.0, pic_time=0.0, open_edge=False, fill_layers=1, layer_time=0.1, title=""):
    """The scene text (Abaqus keyword syntax). Angles in degrees; see the module text.
    fill_layers > 1: the fill in that many layers of layer_time each (bin_steps)."""
    if sand not in SANDS:
        raise ValueError(f"sand must be one of {SANDS}")
    levels = layer_levels(fill, fill_layers, layer_time)
    g = bin_geometry(case, cell, outlet, width, fill, edge_cells)
    h = g["cell"]
    mu = math.tan(math.radians(wall_friction))
    mu_floor = math.tan(math.radians(wall_friction if floor_friction is None else floor_friction))
    mu_right = math.tan(math.radians(wall_friction if right_wall_friction is None else right_wall_friction))
    eps = eps_cv(density, rho_cv)
    lo = (g["x_left"] - 4 * h, -8 * h)
    hi = (g["x_right"] + 4 * h, fill + 6 * h)
    top = hi[1] - h                  # walls end one cell below the grid top
    lines = []
    w = lines.append
    w("*HEADING")
    w(title or f"MPM flat-bottomed bin (thesis ch. 5), {case}, {sand} sand, rho_i {density:g}: "
      f"outlet {outlet * 1e3:g} mm, width {g['width_model'] * 1e3:.4g} mm, fill {fill * 1e3:g} mm, "
      f"cell {h * 1e3:.4g} mm, PPC {ppc}")
    w("** Generated by scripts/bulkflow/mpm/bin_scene.py; edit the generator, not this file.")
    w(f"** {'half model (mirror x = 0)' if g['half'] else 'full model'}; outlet x {g['x_out0']:.6f} .. "
      f"{g['x_out1']:.6f} m at y = 0; walls x = {g['x_left']:.6f}{' (mirror)' if g['half'] else ''}, "
      f"{g['x_right']:.6f} m; eps_cv = {eps:.6f}")
    w(f"*MPM GRID, CELL={h:.12g}, SHAPE={shape}")
    # corners in full, so that the node lines fall on x = 0 and y = 0 to round-off
    w(f"{lo[0]:.15g}, {lo[1]:.15g}")
    w(f"{hi[0]:.15g}, {hi[1]:.15g}")
    w(controls_line(flip, cfl, fill_damping, pic_time, max_dilation))
    if side_friction is not None:
        # front and back glass walls of the quasi-2D bin (issue 20 point 2, docs/keywords.md)
        w(f"*MPM SIDE FRICTION, GAP={side_friction:.9g}, FRICTION={mu:.7f}")
    _material(w, sand, density, young, poisson, phi_cv, psi_max, eps)
    w(f"*PARTICLES, MATERIAL=MC-SAND, PPC={ppc}, TYPE=BOX")
    w(f"{g['x_left']:.9f}, 0.")
    w(f"{g['x_right']:.9f}, {levels[0]:.9f}")
    x0, x1 = g["x_out0"], g["x_out1"]
    # OPEN= (docs/keywords.md): the floor holds the particles, not the nodes, at the outlet's edge,
    # and so does the outlet plate at its end there while the fill rests on both
    opening = (", OPEN=START" if g["half"] else ", OPEN=END") if open_edge else ""
    plate_opening = (", OPEN=END" if g["half"] else ", OPEN=START") if open_edge else ""
    if g["half"]:
        w("*MPM WALL, NAME=AXIS, TYPE=SYMMETRY")
        w(f"0., {hi[1]:.9f}, 0., {lo[1]:.9f}")
        w(f"*MPM WALL, NAME=FLOOR, FRICTION={mu_floor:.7f}{opening}")
        w(f"{x1:.9f}, 0., {g['x_right']:.9f}, 0.")
        w(f"*MPM WALL, NAME=RIGHT, FRICTION={mu:.7f}")
        w(f"{g['x_right']:.9f}, 0., {g['x_right']:.9f}, {top:.9f}")
        plate = (lo[0], x1)
    else:
        w(f"*MPM WALL, NAME=LEFT, FRICTION={mu:.7f}")
        w(f"{g['x_left']:.9f}, {top:.9f}, {g['x_left']:.9f}, 0.")
        w(f"*MPM WALL, NAME=FLOOR, FRICTION={mu_floor:.7f}{opening}")
        w(f"{g['x_left']:.9f}, 0., {x0:.9f}, 0.")
        w(f"*MPM WALL, NAME=RIGHT, FRICTION={mu_right:.7f}")
        w(f"{g['x_right']:.9f}, 0., {g['x_right']:.9f}, {top:.9f}")
        plate = (x0, hi[0])
    w(f"*MPM WALL, NAME=OUTLET, FRICTION={mu_floor:.7f}{plate_opening}")
    w(f"{plate[0]:.9f}, 0., {plate[1]:.9f}, 0.")
    w(f"*OUTFLOW, BELOW={-outflow_cells * h:.9f}")
    w("** gravity: ramped in the fill step, then on at full value (amplitude in total time)")
    w("*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP, TIME=TOTAL TIME")
    w(f"0., 0., {ramp:g}, 1.")
    layers = (levels, layer_time, ppc, f"{g['x_left']:.9f}, {g['x_right']:.9f}") if fill_layers > 1 else None
    lines += bin_steps(fill_time, discharge_time, field_dt, history_dt, layers=layers)
    return "\n".join(lines) + "\n"


def layer_levels(fill, fill_layers, layer_time):
    """The free-surface level after each layer of a layered fill (the last one is `fill`)."""
    if fill_layers < 1:
        raise ValueError("fill_layers must be >= 1")
    if not layer_time > 0:
        raise ValueError("layer_time must be > 0")
    return [fill * k / fill_layers for k in range(1, fill_layers + 1)]


def fill_end(fill_time, fill_layers=1, layer_time=0.1):
    """Total time at the end of the fill (the state at rest that the outlet opens on)."""
    return fill_time + (fill_layers - 1) * layer_time


def bin_steps(fill_time, discharge_time, field_dt, history_dt, gravity="9.81, 0., -1.", fields="S, SDV",
              layers=None):
    """The steps of a bin run (2D scenes and the 3D slab): FILL with the outlet closed and
    gravity ramped by the amplitude RAMP (one field frame at its end), DISCHARGE with the outlet
    wall deleted and no damping.

    layers = (levels, layer_time, ppc, band): a layered fill. The scene's particles are the first
    layer only; after FILL, one step FILL-k of layer_time per further level, in which *INFLOW
    (band: its data line) tops the sand up to that level while the layers below settle under the
    added weight. Not pouring: inflow stacks particles on each column with its top's velocity,
    and the walls' friction ends less mobilised than after the fill at once (measured:
    docs/bins.md, "2D with side friction against a 3D slab")."""
    lines = []
    fill_steps = [("FILL", "Outlet closed: the fill settles under gravity", fill_time,
                   ["*DLOAD, AMPLITUDE=RAMP", f", GRAV, {gravity}"], fill_time)]
    if layers is not None:
        levels, layer_time, ppc, band = layers
        for k, level in enumerate(levels[1:], start=2):
            fill_steps.append((f"FILL-{k}", f"Outlet closed: layer {k} of {len(levels)} filled to y = {level:.6g} m",
                               layer_time, [f"*INFLOW, MATERIAL=MC-SAND, LEVEL={level:.9f}, PPC={ppc}", band],
                               layer_time))
    steps = (*fill_steps,
             ("DISCHARGE", "Outlet open: the bin empties through the outlet", discharge_time,
              ["*MPM CONTROLS, DAMPING=0.", "*MPM WALL, NAME=OUTLET, OP=DELETE"], field_dt))
    for name, text, period, loads, frame_dt in steps:
        lines += [f"*STEP, NAME={name}", text, "*DYNAMIC, EXPLICIT", f", {period:g}", *loads,
                  f"*OUTPUT, FIELD, TIME INTERVAL={frame_dt:g}", "*ELEMENT OUTPUT", fields,
                  f"*OUTPUT, HISTORY, TIME INTERVAL={history_dt:g}", "*ENERGY OUTPUT", "*END STEP"]
    return lines


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", required=True)
    p.add_argument("--case", choices=CASES, default="concentric")
    p.add_argument("--sand", choices=SANDS, default="NDNS")
    p.add_argument("--edge-cells", type=int, default=1, help="k: cell = outlet / (2k + 1)")
    p.add_argument("--cell", type=float, help="grid cell [m] (overrides --edge-cells)")
    p.add_argument("--ppc", type=int, default=2)
    p.add_argument("--outlet", type=float, default=OUTLET, help="outlet width [m]")
    p.add_argument("--width", type=float, default=WIDTH, help="bin width (length in the image) [m]")
    p.add_argument("--fill", type=float, default=FILL, help="fill height [m]")
    p.add_argument("--density", type=float, default=RHO_I, help="initial bulk density rho_i [kg/m3]")
    p.add_argument("--rho-cv", type=float, default=RHO_CV, help="constant-volume bulk density (DS) [kg/m3]")
    p.add_argument("--young", type=float, default=YOUNG)
    p.add_argument("--poisson", type=float, default=POISSON)
    p.add_argument("--phi-cv", type=float, default=PHI_CV, help="constant-volume friction angle [deg]")
    p.add_argument("--psi-max", type=float, default=PSI_MAX, help="DS: maximum dilation angle [deg]")
    p.add_argument("--wall-friction", type=float, default=PHI_WALL, help="wall friction angle [deg]")
    p.add_argument("--right-wall-friction", type=float, help="eccentric: right wall friction angle [deg]")
    p.add_argument("--floor-friction", type=float, help="bottom friction angle [deg] (default: the wall's)")
    p.add_argument("--fill-time", type=float, default=0.3)
    p.add_argument("--fill-layers", type=int, default=1,
                   help="fill in N layers: the first placed, the others by *INFLOW (default 1: placed at once)")
    p.add_argument("--layer-time", type=float, default=0.1, help="--fill-layers: time per further layer [s]")
    p.add_argument("--ramp", type=float, default=0.2, help="gravity ramp time [s]")
    p.add_argument("--discharge-time", type=float, default=8.0)
    p.add_argument("--shape", choices=["GIMP", "LINEAR"], default="GIMP")
    p.add_argument("--flip", type=float, default=0.99)
    p.add_argument("--cfl", type=float, default=0.3)
    p.add_argument("--field-dt", type=float, default=0.1, help="particle frame interval in the discharge [s]")
    p.add_argument("--history-dt", type=float, default=0.01)
    p.add_argument("--side-friction", type=float, metavar="GAP",
                   help="front/back wall gap [m]: writes *MPM SIDE FRICTION (solver with issue 20 point 2)")
    p.add_argument("--max-dilation", type=float, default=0.0, metavar="J",
                   help="*MPM CONTROLS, MAX DILATION=J: particles' V/V0 held at most J (0: off; docs/bins.md)")
    p.add_argument("--pic-time", type=float, default=0.0, metavar="TAU",
                   help="*MPM CONTROLS, PIC TIME=TAU [s] in place of --flip: the PIC/FLIP blend as a rate, "
                        "independent of the increment (0: off; docs/bins.md)")
    p.add_argument("--open-edge", action="store_true",
                   help="the floor holds the particles, not the grid nodes, at the outlet's edge (*MPM WALL, "
                        "OPEN=; docs/keywords.md)")
    a = p.parse_args(argv)
    if a.pic_time < 0:
        p.error("--pic-time must be >= 0")
    try:
        text = bin_scene(case=a.case, sand=a.sand, cell=a.cell, edge_cells=a.edge_cells, ppc=a.ppc,
                         outlet=a.outlet, width=a.width, fill=a.fill, density=a.density, rho_cv=a.rho_cv,
                         young=a.young, poisson=a.poisson, phi_cv=a.phi_cv, psi_max=a.psi_max,
                         wall_friction=a.wall_friction, right_wall_friction=a.right_wall_friction,
                         floor_friction=a.floor_friction, fill_time=a.fill_time, ramp=a.ramp,
                         discharge_time=a.discharge_time, shape=a.shape, flip=a.flip, cfl=a.cfl,
                         field_dt=a.field_dt, history_dt=a.history_dt, side_friction=a.side_friction,
                         max_dilation=a.max_dilation, pic_time=a.pic_time, open_edge=a.open_edge,
                         fill_layers=a.fill_layers, layer_time=a.layer_time)
    except ValueError as e:
        p.error(str(e))
    with open(a.output, "w") as f:
        f.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
