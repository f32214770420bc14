"""The thesis ch. 4 wedge hopper (Table 4.2) as a material-point scene for bulkflow.

Half model (symmetry plane x = 0), plane strain: apex at the origin, walls at the hopper
half-angle theta from the vertical, outlet of full width b at y0 = (b/2)/tan(theta), fill height H
above the outlet. Step FILL: outlet closed (a frictional wall), gravity ramped smoothly (in total time:
it stays on in the discharge step), light
local damping so the fill comes to rest. Step DISCHARGE: the outlet wall is deleted, particles
falling 2 cells below the outlet leave (*OUTFLOW), optional *INFLOW keeps the top level.

    python -m bulkflow.mpm.hopper_scene -o inputs/mpm/wedge_hopper_mpm.inp [--cell 0.05] ...

Material (Table 4.2/4.3): rho 1600, E 10 MPa, nu 0.2, phi 20 deg, psi 15 -> 0 deg over
volumetric strain 0 -> 0.2 (VUSDFLD field 1 = tr LE), c = 0, wall friction tan 5 deg.
Every one of these is a parameter (the parametric studies of thesis §4.5.8 vary them):
`phi`, `psi_initial`, `eps_cv` (volumetric strain at which psi reaches 0; thesis eq. 4.1
eps_cv = ln(eta_i/eta_cv), see `eps_cv_from_eta`), `young`, `poisson`, `density`;
`psi_constant` replaces the table by a constant dilation angle (thesis Fig. 4.14's psi = 10 deg);
`model="DP"` gives the linear Drucker-Prager material matched to Mohr-Coulomb in plane strain
(thesis eq. 3.2, umat/README.md DP mode 1) with the constant dilation `psi_constant` (default 0).
"""
import argparse
import math
import re
import shlex
import sys

ETA_INITIAL = 0.64          # random close packing (thesis §4.3)


def _num(x):
    """A real as Abaqus input writes it: 9 significant digits, always with a decimal point."""
    t = f"{x:.9g}"
    return t if ("." in t or "e" in t) else t + "."


def aligned_cell(cell, outlet, offset=0.5):
    """The cell size nearest to `cell` that puts the outlet edge x = b/2 `offset` cells past a node
    line (the grid has node lines on the axis x = 0). Where the edge falls inside a cell decides
    how the corner between outlet and wall is resolved: at 2-4 cells across the outlet half-width
    an edge on a node line (b = 0.20, 0.30 m at h = 0.05 m) discharged 10-20 % less than the
    mid-cell edges of b = 0.15, 0.25, 0.35 m. Comparing widths at one edge offset removes that."""
    q = 0.5 * outlet / cell
    k = max(0, round(q - offset))
    candidates = [0.5 * outlet / (j + offset) for j in (k - 1, k, k + 1) if j + offset > 0]
    return min(candidates, key=lambda h: abs(h - cell))


def eps_cv_from_eta(eta_cv, eta_i=ETA_INITIAL):
    """Volumetric strain at which dilation stops: thesis eq. 4.1, eps_v = ln(eta_i / eta_cv)."""
    return math.log(eta_i / eta_cv)


def material_lines(name, model="MC", density=1600.0, young=1.0e7, poisson=0.2, phi=20.0, psi_initial=15.0,
                   eps_cv=0.2, psi_constant=None, dilation=True):
    """The *MATERIAL block of the hopper fill (Table 4.2/4.3 by default; module doc): Mohr-Coulomb with
    the dilation table (VUSDFLD), a constant dilation angle, the built-in *MOHR COULOMB (no dilation) or
    the matched Drucker-Prager. Shared by the wedge (this module) and the cone (cone_scene.py)."""
    lines = []
    w = lines.append
    w(f"*MATERIAL, NAME={name}")
    w("*DENSITY")
    w(f"{_num(density)}")
    if model == "DP":
        # linear Drucker-Prager from the Mohr-Coulomb parameters by the plane-strain match
        w("*USER MATERIAL, CONSTANTS=6")
        w(f"{_num(young)}, {_num(poisson)}, {_num(phi)}, {_num(psi_constant or 0.0)}, 0., 1.")
        w("*DEPVAR")
        w("8")
    elif psi_constant is not None:
        w("*USER MATERIAL, CONSTANTS=16")
        w(f"{_num(young)}, {_num(poisson)}, {_num(phi)}, {_num(psi_constant)}, 0., 0., 0., 0.")
        w("0., 0., 0., 0., 0., 1., 0., 0.")
        w("*DEPVAR")
        w("8")
    elif dilation:
        # props layout: umat/README.md (as inputs/demo/wedge_hopper_dilation.inp)
        w("*USER MATERIAL, CONSTANTS=22")
        w(f"{_num(young)}, {_num(poisson)}, {_num(phi)}, 0., 0., 0., 0., 0.")
        w("0., 0., 0., 0., 2., 1., 0., 0.")
        w(f"{_num(phi)}, {_num(psi_initial)}, 0., {_num(phi)}, 0., {_num(eps_cv)}")
        w("*DEPVAR")
        w("8")
        w("*USER DEFINED FIELD")
    else:
        w("*ELASTIC")
        w(f"{_num(young)}, {_num(poisson)}")
        w("*MOHR COULOMB")
        w(f"{_num(phi)}, 0.")
        w("*MOHR COULOMB HARDENING")
        w("0., 0.")
    return lines


def step_lines(ramp, fill_time, discharge_time, field_frames, history_dt, gravity, inflow_lines=(),
               discharge=True, discharge_frames=None):
    """The steps of a hopper scene: FILL (outlet closed, gravity `gravity` -- the *DLOAD data line --
    ramped by a smooth step, the scene's local damping) and DISCHARGE (damping off, the wall OUTLET
    deleted, `inflow_lines` if any), each with particle frames (`discharge_frames` in the discharge
    step if given) and history rows. Shared by the wedge
    (this module) and the cone (cone_scene.py)."""
    lines = []
    w = lines.append
    # Gravity that stays on: the ramp runs in total time, so the discharge step, which does not
    # define gravity again, carries it on at full value (docs/keywords.md, "Prescribed conditions
    # across steps"; with TIME=STEP TIME it would be held at the ramp's end value, the same here).
    w("** gravity: ramped in the fill step, then on at full value (amplitude in total time)")
    w("*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP, TIME=TOTAL TIME")
    w(f"0., 0., {ramp:g}, 1.")
    w("*STEP, NAME=FILL")
    w("Outlet closed: the fill settles under gravity")
    w("*DYNAMIC, EXPLICIT")
    w(f", {fill_time:g}")
    w("*DLOAD, AMPLITUDE=RAMP")
    w(gravity)
    lines += _output_lines(field_frames, history_dt)
    w("*END STEP")
    if not discharge:
        return lines
    w("*STEP, NAME=DISCHARGE")
    w("Outlet open: discharge" + (" with inflow at the top" if inflow_lines else ""))
    w("*DYNAMIC, EXPLICIT")
    w(f", {discharge_time:g}")
    w("*MPM CONTROLS, DAMPING=0.")
    w("*MPM WALL, NAME=OUTLET, OP=DELETE")
    lines += list(inflow_lines)
    lines += _output_lines(discharge_frames or field_frames, history_dt)
    w("*END STEP")
    return lines


def _output_lines(field_frames, history_dt):
    return [f"*OUTPUT, FIELD, NUMBER INTERVAL={field_frames}", "*ELEMENT OUTPUT", "S, SDV",
            f"*OUTPUT, HISTORY, TIME INTERVAL={history_dt:g}", "*ENERGY OUTPUT"]


def controls_line(flip, cfl, damping, pic_time=0.0, max_dilation=0.0):
    """The model-data `*MPM CONTROLS` line of the scene generators: PIC TIME (the blend as a rate,
    docs/theory/mpm.md 4.3) in place of FLIP and MAX DILATION only when asked, so that a scene
    that asks for neither keeps its text (and the studies' run caches) of before."""
    blend = f"PIC TIME={pic_time:g}" if pic_time > 0 else f"FLIP={flip:g}"
    held = f", MAX DILATION={max_dilation:g}" if max_dilation > 0 else ""
    return f"*MPM CONTROLS, {blend}, CFL={cfl:g}, DAMPING={damping:g}{held}"


def hopper_scene(cell=0.05, ppc=2, theta=30.0, outlet=0.25, height=3.0, wall_friction=5.0,
                 fill_time=1.0, ramp=0.6, discharge_time=3.0, inflow=True, fill_damping=0.1,
                 flip=0.99, cfl=0.3, shape="GIMP", field_frames=10, history_dt=0.01,
                 dilation=True, title="", phi=20.0, psi_initial=15.0, eps_cv=0.2,
                 psi_constant=None, young=1.0e7, poisson=0.2, density=1600.0, model="MC",
                 wall_reach=None, outflow_cells=2.0, discharge_frames=None, command=None, pic_time=0.0,
                 open_edge=False):
    """The scene text. `discharge_frames`: field frames of the discharge step (default
    `field_frames`, the number of the fill step); `command`: the command line that wrote the
    file, put in its header (main() passes its own)."""
    t = math.radians(theta)
    y0 = 0.5 * outlet / math.tan(t)          # outlet level
    ytop = y0 + height
    xtop = ytop * math.tan(t)
    mu = math.tan(math.radians(wall_friction))
    # grid: node lines on x = 0 and y = y0 (walls on node lines where they can be)
    nx_lo = 4
    ny_below = 8
    lo = (-nx_lo * cell, y0 - ny_below * cell)
    ymax = ytop + 0.5 * height / 3 + 4 * cell
    xmax = (ymax * math.tan(t)) + 4 * cell
    hi = (xmax, ymax)
    wall_top = (ymax - cell) * math.tan(t), ymax - cell
    out_level = y0 - outflow_cells * cell
    lines = []
    w = lines.append
    w("*HEADING")
    w(title or f"MPM wedge hopper (thesis ch. 4): theta={theta:g} deg, b={outlet:g} m, H={height:g} m, "
      f"cell {cell:g} m, PPC {ppc}")
    w("** Generated by scripts/bulkflow/mpm/hopper_scene.py; edit the generator, not this file.")
    if command:
        w(f"** command: {command}")
    w(f"** outlet y0 = {y0:.6f} m, top y = {ytop:.6f} m, top half-width {xtop:.6f} m, mu_w = {mu:.7f}")
    # the cell in full: 6 digits (0.0357143 for 0.125/3.5) moved the node lines off the axis
    w(f"*MPM GRID, CELL={cell:.12g}, SHAPE={shape}")
    w(f"{lo[0]:.9f}, {lo[1]:.9f}")
    w(f"{hi[0]:.9f}, {hi[1]:.9f}")
    w(controls_line(flip, cfl, fill_damping, pic_time))
    name = "DP-FILL" if model == "DP" else "MC-FILL"
    lines += material_lines(name, model=model, density=density, young=young, poisson=poisson, phi=phi,
                            psi_initial=psi_initial, eps_cv=eps_cv, psi_constant=psi_constant,
                            dilation=dilation)
    w(f"*PARTICLES, MATERIAL={name}, PPC={ppc}, TYPE=POLYGON")
    for x, y in [(0.0, y0), (0.5 * outlet, y0), (xtop, ytop), (0.0, ytop)]:
        w(f"{x:.9f}, {y:.9f}")
    w("*MPM WALL, NAME=AXIS, TYPE=SYMMETRY")
    w(f"0., {hi[1]:.9f}, 0., {lo[1]:.9f}")
    # REACH (docs/keywords.md): the inclined wall also acts on nodes up to REACH cells in front of it
    # OPEN= (docs/keywords.md): the wall holds the particles, not the nodes, at the outlet's edge, and
    # so does the outlet plate at its end there while the fill rests on both
    w(f"*MPM WALL, NAME=WALL, FRICTION={mu:.7f}" + (f", REACH={wall_reach:g}" if wall_reach is not None else "")
      + (", OPEN=START" if open_edge else ""))
    w(f"{0.5 * outlet:.9f}, {y0:.9f}, {wall_top[0]:.9f}, {wall_top[1]:.9f}")
    w(f"*MPM WALL, NAME=OUTLET, FRICTION={mu:.7f}" + (", OPEN=END" if open_edge else ""))
    w(f"{lo[0]:.9f}, {y0:.9f}, {0.5 * outlet:.9f}, {y0:.9f}")
    w(f"*OUTFLOW, BELOW={out_level:.9f}")
    inflow_lines = [f"*INFLOW, MATERIAL={name}, LEVEL={ytop:.9f}, PPC={ppc}", f"0., {xtop:.9f}"] if inflow else []
    lines += step_lines(ramp, fill_time, discharge_time, field_frames, history_dt, ", GRAV, 9.81, 0., -1.",
                        inflow_lines, discharge_frames=discharge_frames)
    return "\n".join(lines) + "\n"


def command_line(argv):
    """The generator's command for a file header: the arguments as given, the output file last as
    FILE (so the header does not depend on where the file was written)."""
    args, skip = [], False
    for x in argv:
        if skip:
            skip = False
        elif x in ("-o", "--output"):
            skip = True
        elif not (x.startswith("--output=") or (x.startswith("-o") and not x.startswith("--"))):
            args.append(shlex.quote(x))
    return " ".join(["bulkflow-make-mpm-hopper", *args, "-o", "FILE"])



def with_mu_of_i(text, block):
    """The scene with the mu(I) block `block` ("1., phi2, I0, d, rho_s": umat/README.md props
    layout, docs/mu_of_i.md) appended to its Mohr-Coulomb *USER MATERIAL constants."""
    m = re.search(r"\*USER MATERIAL, CONSTANTS=(\d+)\n((?:[^*].*\n)+)", text)
    if m is None:
        raise ValueError("no *USER MATERIAL in the scene to append the mu(I) block to")
    n = int(m.group(1)) + 5
    body = m.group(2).rstrip("\n").rstrip(",") + ",\n" + block + "\n"
    return text[:m.start()] + f"*USER MATERIAL, CONSTANTS={n}\n" + body + text[m.end():]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", required=True)
    p.add_argument("--cell", type=float, default=0.05)
    p.add_argument("--ppc", type=int, default=2)
    p.add_argument("--theta", type=float, default=30.0)
    p.add_argument("--outlet", type=float, default=0.25)
    p.add_argument("--height", type=float, default=3.0)
    p.add_argument("--wall-friction", type=float, default=5.0)
    p.add_argument("--fill-time", type=float, default=1.0)
    p.add_argument("--discharge-time", type=float, default=3.0)
    p.add_argument("--no-inflow", action="store_true")
    p.add_argument("--no-dilation", action="store_true", help="constant psi = 0 (built-in *MOHR COULOMB)")
    p.add_argument("--shape", choices=["GIMP", "LINEAR"], default="GIMP")
    p.add_argument("--flip", type=float, default=0.99)
    p.add_argument("--cfl", type=float, default=0.3)
    p.add_argument("--field-frames", type=int, default=10, help="field frames per step")
    p.add_argument("--discharge-frames", type=int,
                   help="field frames of the discharge step (default: --field-frames)")
    p.add_argument("--history-dt", type=float, default=0.01)
    p.add_argument("--phi", type=float, default=20.0, help="internal friction angle [deg]")
    p.add_argument("--psi-initial", type=float, default=15.0, help="dilation angle at eps_v = 0 [deg]")
    p.add_argument("--eta-cv", type=float, help="constant-volume solid fraction (eps_cv = ln(0.64/eta_cv))")
    p.add_argument("--eps-cv", type=float, default=0.2, help="volumetric strain where psi reaches 0")
    p.add_argument("--psi-constant", type=float, help="constant dilation angle instead of the table [deg]")
    p.add_argument("--young", type=float, default=1.0e7)
    p.add_argument("--poisson", type=float, default=0.2)
    p.add_argument("--density", type=float, default=1600.0)
    p.add_argument("--model", choices=["MC", "DP"], default="MC")
    a = p.parse_args(argv)
    text = hopper_scene(cell=a.cell, ppc=a.ppc, theta=a.theta, outlet=a.outlet, height=a.height,
                        wall_friction=a.wall_friction, fill_time=a.fill_time,
                        discharge_time=a.discharge_time, inflow=not a.no_inflow,
                        dilation=not a.no_dilation, shape=a.shape, flip=a.flip, cfl=a.cfl,
                        field_frames=a.field_frames, history_dt=a.history_dt, phi=a.phi,
                        psi_initial=a.psi_initial,
                        eps_cv=eps_cv_from_eta(a.eta_cv) if a.eta_cv else a.eps_cv,
                        psi_constant=a.psi_constant, young=a.young, poisson=a.poisson,
                        density=a.density, model=a.model, discharge_frames=a.discharge_frames,
                        command=command_line(sys.argv[1:] if argv is None else argv))
    with open(a.output, "w") as f:
        f.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
