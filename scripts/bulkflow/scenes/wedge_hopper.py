"""Wedge hopper scene generator: a plane-strain (CPE4R) or extruded (C3D8R) half model of a
converging wedge hopper filled with a Mohr-Coulomb granular material, settled under gravity
against frictional analytic rigid walls with the outlet closed by a rigid plate.

Geometry (thesis §4.1, §4.3 Table 4.2 and §6.2): the hopper apex is the origin, the centreline
is x = 0 (symmetry, XSYMM), the wall is the line through the apex at the half-angle θ from the
vertical. The outlet of width b is closed by a plate: a circular arc of radius r_out = b/(2 sinθ)
centred on the apex (thesis §6.2, `--bottom arc`, 2D only) or the flat line y = b/(2 tanθ)
(`--bottom flat`). The fill reaches the height H above the outlet, with a flat free surface.

The mesh is structured: `n_across` elements from the centreline to the wall, rows graded
geometrically so that every element is close to square (the elements near the outlet are the
smallest and set the stable increment). 3D: the plane mesh is extruded over `depth` in
`n_depth` layers with ZSYMM on both faces (the middle of a long hopper, thesis Fig. 4.1b); the
walls are then `*SURFACE, TYPE=PLANE` (a bulkflow extension), so a 3D scene is bulkflow-only.

The 2D input is plain Abaqus/Explicit syntax: flat (no parts), the material a `*USER MATERIAL`
of our VUMAT (umat/README.md; `abaqus job=hopper user=bulkflow_abaqus.f double=both`), the walls
analytic rigid surfaces on `*RIGID BODY` reference nodes held by `*BOUNDARY`, contact pairs and
gravity in the step. With `walls="pinned"` the walls are replaced by pinned nodes (no contact):
that variant also runs in CalculiX (`write_calculix`), for benchmarks.

    bulkflow-make-hopper -o inputs/demo/wedge_hopper.inp           # the default scene
    bulkflow-make-hopper --n-across 40 --dilation-table -o fine.inp
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

# Thesis Table 4.3: dilation angle against the volumetric strain (field variable 1).
THESIS_DILATION_TABLE = ((15.0, 0.0), (0.0, 0.2))


@dataclass
class WedgeHopper:
    """Parameters of the scene. SI units (m, kg, s, Pa), angles in degrees."""

    # geometry (thesis Table 4.2)
    theta: float = 30.0              #: hopper half-angle θ from the vertical
    outlet_width: float = 0.25       #: b, full outlet width
    height: float = 3.0              #: H, fill height above the outlet (at the centreline)
    bottom: str = "arc"              #: outlet plate: "arc" (centred on the apex) or "flat"
    dim: int = 2                     #: 2: CPE4R plane strain; 3: C3D8R slab
    depth: float = 0.1               #: 3D slab thickness (z); 2D: the section thickness is 1
    # mesh
    n_across: int = 20               #: elements from the centreline to the wall
    n_depth: int = 2                 #: 3D layers in z
    aspect: float = 1.0              #: element height / width (row grading)
    # material (thesis Table 4.2)
    density: float = 1600.0
    young: float = 10.0e6
    poisson: float = 0.2
    phi: float = 20.0                #: internal friction angle
    psi: float = 0.0                 #: dilation angle (constant)
    cohesion: float = 0.0
    dilation_table: tuple | None = None   #: ((ψ_i, ε_v,i), ...): ψ tabulated, *USER DEFINED FIELD
    elastic: bool = False            #: linear elastic material instead of Mohr-Coulomb
    # walls
    walls: str = "contact"           #: "contact": rigid walls + outlet plate; "pinned": fixed nodes
    wall_friction: float = 5.0       #: φw, μ = tan φw (wall and outlet plate)
    # loading and time
    gravity: float = 9.81
    ramp: float = 0.6                #: smooth-step rise time of gravity (0: gravity at once)
    hold: float = 0.4                #: settling time after the ramp
    dt_scale: float | None = None    #: *DYNAMIC, SCALE FACTOR (None: 1)
    fixed_dt: float | None = None    #: DIRECT USER CONTROL increment (None: stable increment)
    field_frames: int = 10
    history_points: int = 200
    restart: bool = False
    initial_k: float | None = None   #: geostatic initial stress: σv = −ρ g depth, σh = σzz = k σv
    title: str = ""

    # ---- derived geometry -------------------------------------------------------------------
    @property
    def outlet_radius(self) -> float:
        return 0.5 * self.outlet_width / math.sin(math.radians(self.theta))

    @property
    def outlet_y(self) -> float:
        return 0.5 * self.outlet_width / math.tan(math.radians(self.theta))

    @property
    def top_y(self) -> float:
        return self.outlet_y + self.height

    @property
    def mu(self) -> float:
        return math.tan(math.radians(self.wall_friction))

    @property
    def user_field(self) -> bool:
        return self.dilation_table is not None and not self.elastic

    def wave_speed(self) -> float:
        """Dilatational wave speed c_d = √((λ+2G)/ρ)."""
        e, nu = self.young, self.poisson
        return math.sqrt(e * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / self.density)

    def fill_weight(self) -> float:
        """Weight of the fill per unit depth (2D) or of the slab (3D), from the mesh area."""
        x, _, conn = self.plane_mesh()
        area = 0.0
        for q in conn:
            p = x[q]
            area += 0.5 * abs((p[2, 0] - p[0, 0]) * (p[3, 1] - p[1, 1]) - (p[2, 1] - p[0, 1]) * (p[3, 0] - p[1, 0]))
        return self.density * self.gravity * area * (self.depth if self.dim == 3 else 1.0)

    # ---- mesh -------------------------------------------------------------------------------
    def _boundary_curves(self, xi: np.ndarray):
        """Bottom and top curves at the across-coordinates xi ∈ [0, 1]: arrays (n, 2)."""
        th = math.radians(self.theta)
        if self.bottom == "arc":
            r = self.outlet_radius
            bot = np.column_stack([r * np.sin(xi * th), r * np.cos(xi * th)])
        else:
            bot = np.column_stack([xi * self.outlet_y * math.tan(th), np.full_like(xi, self.outlet_y)])
        top = np.column_stack([xi * self.top_y * math.tan(th), np.full_like(xi, self.top_y)])
        return bot, top

    def row_coordinates(self) -> np.ndarray:
        """η_j ∈ [0, 1] of the node rows: elements about `aspect` times as tall as wide."""
        th = math.radians(self.theta)
        a = (self.outlet_radius * th if self.bottom == "arc" else self.outlet_y * math.tan(th)) / self.n_across
        b = self.top_y * math.tan(th) / self.n_across
        length = self.top_y - (self.outlet_radius if self.bottom == "arc" else self.outlet_y)
        # element height h(η) = aspect·(a + (b − a)η), dη/dj = h/length → exponential rows
        rows = max(1, round(length * math.log(b / a) / (self.aspect * (b - a))))
        k = math.log(b / a) / rows
        eta = (a * np.exp(k * np.arange(rows + 1)) - a) / (b - a)
        eta[-1] = 1.0
        return eta

    def plane_mesh(self):
        """Nodes (n, 2), the (i, j) index grid of node numbers (0-based), quads (m, 4) CCW."""
        nx = self.n_across
        eta = self.row_coordinates()
        ny = len(eta) - 1
        xi = np.linspace(0.0, 1.0, nx + 1)
        bot, top = self._boundary_curves(xi)
        x = (1 - eta[:, None, None]) * bot[None, :, :] + eta[:, None, None] * top[None, :, :]  # (ny+1, nx+1, 2)
        x = x.reshape(-1, 2)
        grid = np.arange((ny + 1) * (nx + 1)).reshape(ny + 1, nx + 1)
        conn = np.stack([grid[:-1, :-1], grid[:-1, 1:], grid[1:, 1:], grid[1:, :-1]], axis=-1).reshape(-1, 4)
        return x, grid, conn

    def mesh(self):
        """Nodes (n, dim), elements (m, nen) 0-based, and named 0-based index sets:
        nodes 'axis', 'front', 'back' (3D), 'wall', 'bottom'; elements 'wall', 'bottom', 'top'."""
        x2, grid, conn2 = self.plane_mesh()
        ny, nx = grid.shape[0] - 1, grid.shape[1] - 1
        e_grid = np.arange(ny * nx).reshape(ny, nx)
        sets = {}
        if self.dim == 2:
            nodes, elems = x2, conn2
            sets["n_axis"] = grid[:, 0]
            sets["n_wall"] = grid[:, -1]
            sets["n_bottom"] = grid[0, :]
            sets["e_wall"] = e_grid[:, -1]
            sets["e_bottom"] = e_grid[0, :]
            sets["e_top"] = e_grid[-1, :]
        else:
            nz = self.n_depth
            z = np.linspace(0.0, self.depth, nz + 1)
            nn2 = len(x2)
            nodes = np.column_stack([np.tile(x2, (nz + 1, 1)), np.repeat(z, nn2)])
            layers = []
            for k in range(nz):
                lo, hi = conn2 + k * nn2, conn2 + (k + 1) * nn2
                layers.append(np.hstack([lo, hi]))
            elems = np.vstack(layers)
            ne2 = len(conn2)
            lay = lambda idx2, nper: np.concatenate([idx2 + k * nper for k in range(nz + 1)])
            elay = lambda idx2: np.concatenate([idx2 + k * ne2 for k in range(nz)])
            sets["n_axis"] = lay(grid[:, 0], nn2)
            sets["n_wall"] = lay(grid[:, -1], nn2)
            sets["n_bottom"] = lay(grid[0, :], nn2)
            sets["n_back"] = np.arange(nn2)
            sets["n_front"] = np.arange(nn2) + nz * nn2
            sets["e_wall"] = elay(e_grid[:, -1])
            sets["e_bottom"] = elay(e_grid[0, :])
            sets["e_top"] = elay(e_grid[-1, :])
        return nodes, elems, sets

    def min_char_length(self) -> float:
        """Smallest element characteristic length (area / longest edge, as bulkflow's CPE4R)."""
        x, _, conn = self.plane_mesh()
        p = x[conn]                                         # (m, 4, 2)
        d = np.diff(np.concatenate([p, p[:, :1]], axis=1), axis=1)
        l2 = (d ** 2).sum(axis=2).max(axis=1)
        area = 0.5 * np.abs((p[:, 2, 0] - p[:, 0, 0]) * (p[:, 3, 1] - p[:, 1, 1])
                            - (p[:, 2, 1] - p[:, 0, 1]) * (p[:, 3, 0] - p[:, 1, 0]))
        lc = area / np.sqrt(l2)
        if self.dim == 3:
            lc = np.minimum(lc, self.depth / self.n_depth)
        return float(lc.min())

    def stable_dt(self) -> float:
        """Estimate of the initial stable increment (bulk viscosity b1 = 0.06)."""
        xi = 0.06
        return self.min_char_length() / self.wave_speed() * (math.sqrt(1 + xi * xi) - xi)

    def n_elements(self) -> int:
        return self.n_across * (len(self.row_coordinates()) - 1) * (self.n_depth if self.dim == 3 else 1)

    # ---- material ---------------------------------------------------------------------------
    def material_lines(self) -> list[str]:
        if self.elastic:
            return ["*MATERIAL, NAME=ELASTIC-FILL", "*DENSITY", fmt(self.density),
                    "*USER MATERIAL, CONSTANTS=2", f"{fmt(self.young)}, {fmt(self.poisson)}"]
        table = list(self.dilation_table or ())
        props = [self.young, self.poisson, self.phi, self.psi, self.cohesion, 0, 0,   # 1-7
                 0, 0, 0, 0, 0,                                                        # 8-12 no flow function
                 len(table), 1 if table else 0, 0, 0]                                  # 13-16
        for psi_i, ev_i in table:
            props += [self.phi, psi_i, ev_i]
        lines = ["*MATERIAL, NAME=MC-FILL", "*DENSITY", fmt(self.density),
                 f"*USER MATERIAL, CONSTANTS={len(props)}"]
        lines += [", ".join(fmt(v) for v in props[i:i + 8]) for i in range(0, len(props), 8)]
        lines += ["*DEPVAR", "8"]
        if table:
            lines += ["*USER DEFINED FIELD"]
        return lines

    # ---- writer -----------------------------------------------------------------------------
    def inp_text(self) -> str:
        nodes, elems, sets = self.mesh()
        th = math.radians(self.theta)
        etype = "CPE4R" if self.dim == 2 else "C3D8R"
        nen = elems.shape[1]
        nn = len(nodes)
        title = self.title or (f"Wedge hopper, {etype} half model, theta={self.theta:g} deg, b={self.outlet_width:g} m, "
                               f"H={self.height:g} m, {len(elems)} elements, "
                               f"{'elastic' if self.elastic else 'Mohr-Coulomb'}")
        L = ["*HEADING", title,
             "** Generated by bulkflow-make-hopper (scripts/bulkflow/scenes/wedge_hopper.py); edit the generator,",
             "** not this file. Parameters:"]
        for f in dataclasses.fields(self):
            L.append(f"**   {f.name} = {getattr(self, f.name)!r}")
        L.append(f"** Derived: outlet radius {self.outlet_radius:.6g} m, outlet y {self.outlet_y:.6g} m, "
                 f"top y {self.top_y:.6g} m, mu = tan(phi_w) = {self.mu:.6g}, c_d = {self.wave_speed():.6g} m/s, "
                 f"stable dt ~ {self.stable_dt():.4g} s, fill weight {self.fill_weight():.6g} N"
                 f"{'/m' if self.dim == 2 else ''}")
        L.append("*NODE, NSET=ALLN")
        for i, p in enumerate(nodes):
            L.append(f"{i + 1}, " + ", ".join(f"{c:.9g}" for c in p))
        L.append(f"*ELEMENT, TYPE={etype}, ELSET=FILL")
        for i, e in enumerate(elems):
            L.append(f"{i + 1}, " + ", ".join(str(n + 1) for n in e))
        L += nset("AXIS", sets["n_axis"]) + nset("WALLN", sets["n_wall"]) + nset("BOTTOMN", sets["n_bottom"])
        if self.dim == 3:
            L += nset("BACK", sets["n_back"]) + nset("FRONT", sets["n_front"])
        L += elset("WALLE", sets["e_wall"]) + elset("BOTTOME", sets["e_bottom"]) + elset("TOPE", sets["e_top"])
        L += ["*SOLID SECTION, ELSET=FILL, MATERIAL=" + ("ELASTIC-FILL" if self.elastic else "MC-FILL")]
        L += ["1." if self.dim == 2 else ""]
        L += self.material_lines()
        if self.ramp > 0:
            L += ["*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP", f"0., 0., {fmt(self.ramp)}, 1."]
        if self.initial_k is not None:
            L += self.initial_stress_lines(nodes, elems)
        # symmetry
        L += ["*BOUNDARY", "AXIS, XSYMM"]
        if self.dim == 3:
            L += ["BACK, ZSYMM", "FRONT, ZSYMM"]
        contact = self.walls == "contact"
        if contact:
            face_wall, face_bottom = ("S2", "S1") if self.dim == 2 else ("S4", "S3")
            L += ["*SURFACE, TYPE=ELEMENT, NAME=FILL_WALL", f"WALLE, {face_wall}",
                  "*SURFACE, TYPE=ELEMENT, NAME=FILL_BOTTOM", f"BOTTOME, {face_bottom}"]
            r_top = 1.2 * self.top_y / math.cos(th)
            ref_wall, ref_plate = nn + 1, nn + 2
            z = [] if self.dim == 2 else [0.0]
            L += ["*NODE, NSET=WALLREF", f"{ref_wall}, " + ", ".join(fmt(v) for v in [0.0, 0.0] + z),
                  "*NODE, NSET=PLATEREF", f"{ref_plate}, " + ", ".join(fmt(v) for v in [0.0, 0.0] + z)]
            if self.dim == 2:
                # material on the left of the direction of travel (docs/keywords.md)
                L += ["*SURFACE, TYPE=SEGMENTS, NAME=WALL",
                      "START, 0., 0.", f"LINE, {r_top * math.sin(th):.9g}, {r_top * math.cos(th):.9g}"]
                if self.bottom == "arc":
                    r = self.outlet_radius
                    a0, a1 = -math.radians(5.0), th + math.radians(5.0)
                    L += ["*SURFACE, TYPE=SEGMENTS, NAME=PLATE",
                          f"START, {r * math.sin(a0):.9g}, {r * math.cos(a0):.9g}",
                          f"CIRCL, {r * math.sin(a1):.9g}, {r * math.cos(a1):.9g}, 0., 0."]
                else:
                    xw = 1.2 * self.outlet_y * math.tan(th)
                    L += ["*SURFACE, TYPE=SEGMENTS, NAME=PLATE",
                          f"START, {xw:.9g}, {self.outlet_y:.9g}", f"LINE, {-0.1 * xw:.9g}, {self.outlet_y:.9g}"]
            else:
                L += ["*SURFACE, TYPE=PLANE, NAME=WALL", "0., 0., 0.",
                      f"{-math.cos(th):.9g}, {math.sin(th):.9g}, 0.",
                      "*SURFACE, TYPE=PLANE, NAME=PLATE", f"0., {self.outlet_y:.9g}, 0.", "0., 1., 0."]
            L += [f"*RIGID BODY, REF NODE=WALLREF, ANALYTICAL SURFACE=WALL",
                  f"*RIGID BODY, REF NODE=PLATEREF, ANALYTICAL SURFACE=PLATE",
                  "*BOUNDARY", "WALLREF, ENCASTRE", "PLATEREF, ENCASTRE",
                  "*SURFACE INTERACTION, NAME=WALLFRICTION", "*FRICTION", f"{self.mu:.9g}"]
        else:
            L += ["*BOUNDARY", "WALLN, PINNED", "BOTTOMN, PINNED"]
        # the step
        period = self.ramp + self.hold
        L += ["*STEP, NAME=SETTLE, NLGEOM=YES", "Fill settles under gravity, outlet closed"]
        if self.fixed_dt:
            L += ["*DYNAMIC, EXPLICIT, DIRECT USER CONTROL", f"{fmt(self.fixed_dt)}, {fmt(period)}"]
        elif self.dt_scale:
            L += [f"*DYNAMIC, EXPLICIT, SCALE FACTOR={fmt(self.dt_scale)}", f", {fmt(period)}"]
        else:
            L += ["*DYNAMIC, EXPLICIT", f", {fmt(period)}"]
        L += ["*BULK VISCOSITY", "0.06, 1.2"]
        L += ["*DLOAD" + (", AMPLITUDE=RAMP" if self.ramp > 0 else ""), f"FILL, GRAV, {fmt(self.gravity)}, 0., -1." + (", 0." if self.dim == 3 else "")]
        if contact:
            L += ["*CONTACT PAIR, INTERACTION=WALLFRICTION", "FILL_WALL, WALL", "FILL_BOTTOM, PLATE"]
        if self.field_frames > 0:
            L += [f"*OUTPUT, FIELD, NUMBER INTERVAL={self.field_frames}", "*NODE OUTPUT", "U, V",
                  "*ELEMENT OUTPUT", "S, LE" + (", SDV" if not self.elastic else "")]   # PEEQ is SDV1
        L += [f"*OUTPUT, HISTORY, NUMBER INTERVAL={self.history_points}", "*ENERGY OUTPUT, VARIABLE=PRESELECT"]
        if self.restart:
            L += ["*RESTART, WRITE, NUMBER INTERVAL=1"]
        L += ["*END STEP", ""]
        return "\n".join(L)

    def initial_stress_lines(self, nodes, elems) -> list[str]:
        """Element sets of element rows and a geostatic *INITIAL CONDITIONS, TYPE=STRESS: the
        vertical stress of the row's mean centroid depth below the fill top, the horizontal and
        out-of-plane stresses k times it (tension positive, as Abaqus)."""
        nx = self.n_across
        rows = len(self.row_coordinates()) - 1
        yc = nodes[elems][:, :, 1].mean(axis=1)
        per_layer = nx * rows
        L = []
        cond = ["*INITIAL CONDITIONS, TYPE=STRESS"]
        for j in range(rows):
            ids = [k * per_layer + j * nx + i for k in range(self.n_depth if self.dim == 3 else 1) for i in range(nx)]
            depth = self.top_y - float(np.mean(yc[ids]))
            sv = -self.density * self.gravity * max(depth, 0.0)
            L += elset(f"ROW{j + 1}", ids)
            comps = [self.initial_k * sv, sv, self.initial_k * sv, 0.0] + ([0.0, 0.0] if self.dim == 3 else [])
            cond.append(f"ROW{j + 1}, " + ", ".join(f"{c:.6g}" for c in comps))
        return L + cond

    def write(self, path: str | Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(self.inp_text())
        return path

    # ---- CalculiX --------------------------------------------------------------------------
    def calculix_text(self, increments: int | None = None, dt: float | None = None) -> str:
        """The same mesh, elastic material, pinned walls, symmetry and gravity for CalculiX's
        explicit solver (`*DYNAMIC, EXPLICIT`, NLGEOM), over `increments` × `dt` (default: the
        scene's period). CalculiX chooses its own constant increment (its "Volumetric COURANT"
        stable increment, printed as "SELECTED time increment"); `DIRECT` is not used because
        CalculiX 2.20 hangs with `*DYNAMIC, EXPLICIT, DIRECT`. No field or print output."""
        if self.walls != "pinned" or not self.elastic:
            raise ValueError("the CalculiX twin exists for elastic scenes with pinned walls only")
        nodes, elems, sets = self.mesh()
        etype = "CPE4R" if self.dim == 2 else "C3D8R"
        dt = dt or self.fixed_dt or 0.9 * self.stable_dt()
        period = dt * increments if increments else self.ramp + self.hold
        L = ["*HEADING", "CalculiX twin of a bulkflow benchmark scene (wedge_hopper.py)", "*NODE, NSET=NALL"]
        for i, p in enumerate(nodes):
            L.append(f"{i + 1}, " + ", ".join(f"{c:.9g}" for c in p))
        L.append(f"*ELEMENT, TYPE={etype}, ELSET=FILL")
        for i, e in enumerate(elems):
            L.append(f"{i + 1}, " + ", ".join(str(n + 1) for n in e))
        L += nset("AXIS", sets["n_axis"]) + nset("WALLN", sets["n_wall"]) + nset("BOTTOMN", sets["n_bottom"])
        if self.dim == 3:
            L += nset("BACK", sets["n_back"]) + nset("FRONT", sets["n_front"])
        L += ["*MATERIAL, NAME=FILLMAT", "*ELASTIC", f"{fmt(self.young)}, {fmt(self.poisson)}",
              "*DENSITY", fmt(self.density)]
        L += ["*SOLID SECTION, ELSET=FILL, MATERIAL=FILLMAT"] + (["1."] if self.dim == 2 else [])
        if self.ramp > 0:
            L += ["*AMPLITUDE, NAME=RAMP", f"0., 0., {fmt(self.ramp)}, 1., {fmt(self.ramp + self.hold + period)}, 1."]
        L += ["*BOUNDARY", "AXIS, 1, 1", "WALLN, 1, 2" if self.dim == 2 else "WALLN, 1, 3",
              "BOTTOMN, 1, 2" if self.dim == 2 else "BOTTOMN, 1, 3"]
        if self.dim == 3:
            L += ["BACK, 3, 3", "FRONT, 3, 3"]
        L += ["*STEP, NLGEOM, INC=10000000", "*DYNAMIC, EXPLICIT", f"{dt:.9g}, {period:.9g}",
              "*DLOAD" + (", AMPLITUDE=RAMP" if self.ramp > 0 else ""), f"FILL, GRAV, {fmt(self.gravity)}, 0., -1., 0.",
              "*NODE FILE, FREQUENCY=0", "*EL FILE, FREQUENCY=0",
              "*END STEP", ""]
        return "\n".join(L)


def fmt(v: float) -> str:
    """A number as Abaqus reads it: integers with a trailing dot, others in short form."""
    v = float(v)
    if v == int(v) and abs(v) < 1e15:
        return f"{int(v)}."
    return f"{v:.9g}"


def _id_lines(ids) -> list[str]:
    ids = [str(int(i) + 1) for i in ids]
    return [", ".join(ids[k:k + 16]) for k in range(0, len(ids), 16)]


def nset(name, ids) -> list[str]:
    return [f"*NSET, NSET={name}"] + _id_lines(sorted(set(int(i) for i in ids)))


def elset(name, ids) -> list[str]:
    return [f"*ELSET, ELSET={name}"] + _id_lines(sorted(set(int(i) for i in ids)))


# ---- command line ---------------------------------------------------------------------------
def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="bulkflow-make-hopper", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    d = WedgeHopper()
    p.add_argument("-o", "--output", required=True, help="the .inp file to write")
    p.add_argument("--calculix", metavar="FILE", help="also write a CalculiX twin (elastic, pinned walls only)")
    p.add_argument("--calculix-increments", type=int, default=None)
    g = p.add_argument_group("geometry and mesh")
    g.add_argument("--theta", type=float, default=d.theta, help="hopper half-angle (deg)")
    g.add_argument("--outlet-width", type=float, default=d.outlet_width, help="b (m)")
    g.add_argument("--height", type=float, default=d.height, help="fill height H above the outlet (m)")
    g.add_argument("--bottom", choices=["arc", "flat"], default=d.bottom)
    g.add_argument("--dim", type=int, choices=[2, 3], default=d.dim, help="2: CPE4R, 3: C3D8R slab")
    g.add_argument("--depth", type=float, default=d.depth, help="3D slab thickness (m)")
    g.add_argument("--n-across", type=int, default=d.n_across, help="elements centreline to wall")
    g.add_argument("--n-depth", type=int, default=d.n_depth, help="3D element layers")
    g.add_argument("--aspect", type=float, default=d.aspect, help="element height/width")
    g = p.add_argument_group("material")
    g.add_argument("--density", type=float, default=d.density)
    g.add_argument("--young", type=float, default=d.young)
    g.add_argument("--poisson", type=float, default=d.poisson)
    g.add_argument("--phi", type=float, default=d.phi)
    g.add_argument("--psi", type=float, default=d.psi)
    g.add_argument("--cohesion", type=float, default=d.cohesion)
    g.add_argument("--dilation-table", action="store_true",
                   help="ψ from 15° at ε_v = 0 to 0° at ε_v = 0.2 (thesis Table 4.3) with *USER DEFINED FIELD")
    g.add_argument("--elastic", action="store_true", help="linear elastic fill")
    g = p.add_argument_group("walls, loading, time")
    g.add_argument("--walls", choices=["contact", "pinned"], default=d.walls)
    g.add_argument("--wall-friction", type=float, default=d.wall_friction, help="φw (deg)")
    g.add_argument("--gravity", type=float, default=d.gravity)
    g.add_argument("--ramp", type=float, default=d.ramp, help="smooth-step rise time (s); 0: gravity at once")
    g.add_argument("--initial-k", type=float, default=None,
                   help="geostatic initial stress, horizontal/vertical ratio k (default: none)")
    g.add_argument("--hold", type=float, default=d.hold, help="settling time after the ramp (s)")
    g.add_argument("--dt-scale", type=float, default=None)
    g.add_argument("--fixed-dt", type=float, default=None)
    g.add_argument("--field-frames", type=int, default=d.field_frames, help="0: no field output")
    g.add_argument("--history-points", type=int, default=d.history_points)
    g.add_argument("--title", default="")
    return p


def main(argv=None) -> int:
    a = _parser().parse_args(argv)
    if a.dim == 3 and a.bottom == "arc":
        a.bottom = "flat"            # a 3D analytic surface is a plane
    scene = WedgeHopper(theta=a.theta, outlet_width=a.outlet_width, height=a.height, bottom=a.bottom,
                        dim=a.dim, depth=a.depth, n_across=a.n_across, n_depth=a.n_depth, aspect=a.aspect,
                        density=a.density, young=a.young, poisson=a.poisson, phi=a.phi, psi=a.psi,
                        cohesion=a.cohesion, dilation_table=THESIS_DILATION_TABLE if a.dilation_table else None,
                        elastic=a.elastic, walls=a.walls, wall_friction=a.wall_friction, gravity=a.gravity,
                        ramp=a.ramp, hold=a.hold, dt_scale=a.dt_scale, fixed_dt=a.fixed_dt,
                        field_frames=a.field_frames, history_points=a.history_points, title=a.title,
                        initial_k=a.initial_k)
    path = scene.write(a.output)
    print(f"{path}: {scene.n_elements()} {'CPE4R' if scene.dim == 2 else 'C3D8R'} elements, "
          f"stable dt ~ {scene.stable_dt():.3g} s, {scene.ramp + scene.hold:g} s "
          f"(~{(scene.ramp + scene.hold) / scene.stable_dt():.0f} increments), "
          f"fill weight {scene.fill_weight():.5g} N{'/m' if scene.dim == 2 else ''}")
    if a.calculix:
        Path(a.calculix).write_text(scene.calculix_text(increments=a.calculix_increments))
        print(f"{a.calculix}: CalculiX twin")
    return 0


if __name__ == "__main__":
    sys.exit(main())
