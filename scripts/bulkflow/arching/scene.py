"""Arching scene generator (thesis §6.2): half of a plane-strain wedge hopper, converging section
only, for the flow/no-flow decision of a cohesive bulk solid at a given outlet width.

Geometry: the hopper apex is the origin, the centreline x = 0 carries symmetry (XSYMM), the wall
is the line through the apex at the half-angle θ from the vertical (an analytic rigid surface
with Coulomb friction μ = tan φw). The material lies between the outlet arc and the horizontal
top surface y = H (H: vertical height of the top above the apex, the theory package's
`Hopper.height`). The outlet arc meets the wall at the distance r_out = B / (2 sin θ) from the
apex (B: outlet width); it is centred at the apex (`arch="apex"`, the thesis FEM) or on the axis
at r_out sin β / sin(θ + β) above it, with radius r_out sin θ / sin(θ + β) (`arch="enstad"`,
Enstad's arch meeting the wall at β to its normal; docs/theory/hopper_theory.md §d.1).

Mesh: a polar mesh of CPE4R elements — `n_arc` elements along the outlet (rays from the apex at
equal angles) and rows spaced geometrically along each ray so that elements stay close to square
(sizes grow with the distance from the apex: ~2-7 k elements for 30 along the outlet).

Material: our Mohr–Coulomb VUMAT (`*USER MATERIAL`, props of umat/README.md) with ψ = 0 and
cohesion from a flow function fc(σ1) (linear fc0 + kσ1, the thesis's bilinear variant, or a
table), σ1 recorded until the freeze time and frozen after: the end of the sliding step
(passive) or of the gravity step (active). The scene is plain Abaqus syntax except for our
`*STOP CONDITION` (a user running it in Abaqus deletes that line and judges the opening step by
eye or from the history).

Steps (thesis §6.2):
  1. GRAVITY — gravity by smooth step, outlet plate closed (rigid arc, same friction as the wall);
  2. SLIDE   — (passive only) the plate moves a small distance toward the apex by smooth step;
  3. OPEN    — contact with the plate deleted; `*STOP CONDITION` ends the run at FLOW (largest
               displacement since the opening > 3 % of B, `criterion="physical"`, or > half the
               outlet element length, `criterion="half-element"`, the thesis's rule) or ARREST.
Steps 1-2 are quasi-static: `*FIXED MASS SCALING, DT=..., TYPE=BELOW MIN` scales the small outlet
elements up to the given stable increment (`mass_scaling_dt_factor` × the smallest physical
element increment); step 3 restores the physical masses (`FACTOR=1`).

    bulkflow-make-arching --case B --height 2 --outlet-width 0.22 -o caseB.inp
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bulkflow.theory import Hopper, Material, enstad_outlet_arch
from bulkflow.theory.cases import CASES, READINGS
from bulkflow.theory.cases import case as theory_case
from bulkflow.theory.mohr import fc_from_c

G = 9.81
CRITERIA = ("physical", "half-element")
#: physical FLOW limit as a fraction of the outlet width (README "The decision": why 2 %)
FLOW_WIDTH_FRACTION = 0.03
#: ARREST's creep rule, GROWTH of `*STOP CONDITION` per criterion: u_max grows by less than this ×
#: the FLOW limit over HOLD (physical: 0.02 × 3 % B per 0.05 s = 0.012 B/s, ~4 mm/s at B = 35 cm)
GROWTH = {"physical": 0.02, "half-element": 0.05}


def fc0_from_c0(c0: float, phi_deg: float) -> float:
    """Thesis eq. 6.9 at zero consolidation: fc0 = 2 c0 cos φ / (1 − sin φ)."""
    return float(fc_from_c(c0, phi_deg))


#: The named cases are the theory package's (thesis Tables 6.1, 6.2: bulkflow.theory.cases), so
#: scenes and estimates share one source. How the tabulated cohesion becomes fc0 (issue 4 part 3,
#: docs/theory/hopper_theory.md §0 item 4): "c0" — it is c0 and eq. 6.9 gives fc0 (as the thesis documents); "fc0" —
#: it is fc0 itself (what the thesis's own polymer theory numbers imply). Cases A and B offer "c0"
#: only. The powders' fill height is not reported; the theory's EL_HEIGHT (1 m above the apex).
CASE_NAMES = tuple(CASES)


def case_material(case: str, reading: str = "c0") -> dict:
    """rho, phi, phi_w, k, fc0, theta, height of a named case under a c0 reading."""
    c = theory_case(case)
    return dict(rho=c.rho, theta=c.theta_deg, phi=c.phi_deg, phi_w=c.phi_w_deg, k=c.k,
                fc0=float(c.fc0(reading)), height=c.height)


def enstad_beta(case_or_params: dict) -> float:
    """Enstad's arch angle β (deg) for the material/hopper of `case_material`-like parameters."""
    m = Material(rho=case_or_params["rho"], phi_deg=case_or_params["phi"], phi_w_deg=case_or_params["phi_w"],
                 k=case_or_params["k"], fc0=case_or_params["fc0"])
    h = Hopper(theta_deg=case_or_params["theta"], height=case_or_params["height"])
    return float(enstad_outlet_arch(h, m, 0.1)["beta_deg"])


@dataclass
class ArchingScene:
    """Parameters of an arching scene. SI units (m, kg, s, Pa), angles in degrees."""

    # geometry
    theta: float = 30.0              #: hopper half-angle from the vertical
    outlet_width: float = 0.25       #: B = 2 r_out sin θ
    height: float = 2.0              #: H: top surface height above the apex
    arch: str = "apex"               #: outlet arc centred at the apex, or "enstad"
    beta: float = 0.0                #: Enstad arch angle to the wall normal (deg), arch="enstad"
    # mesh
    n_arc: int = 30                  #: elements along the outlet arc
    # material
    density: float = 400.0
    young: float = 10.0e6
    poisson: float = 0.2
    phi: float = 20.0
    phi_w: float = 0.0
    psi: float = 0.0                 #: dilation angle (deg), 0 <= psi <= phi; the thesis's ch. 6 material: 0
    #: "nonassociated": the VUMAT gets φ, ψ and the flow function as given (the thesis); "davis": it
    #: gets the associated material of Davis (1968) with the same collapse strength, ψ* = φ*,
    #: tan φ* = η tan φ, c* = η c, η = cos ψ cos φ / (1 − sin ψ sin φ) (README "Mesh dependence")
    flow_rule: str = "nonassociated"
    flow: str = "linear"             #: "linear", "bilinear" (thesis §6.5.4) or "table"
    fc0: float = 2000.0              #: unconfined yield strength at σ1 = 0 (linear/bilinear)
    k: float = 0.0                   #: flow-function slope
    table: tuple = ()                #: ((σ1, fc), ...) for flow="table"
    # steps
    state: str = "passive"           #: "passive" (slide the plate) or "active" (no sliding)
    t_gravity: float = 0.4           #: gravity smooth-step time (s)
    t_slide: float = 0.2             #: sliding step time (s)
    #: plate travel toward the apex (m). 5 mm left a 3 m fill of Case A short of the passive state
    #: (its critical width then grew with the height and mass scaling shifted it); from 20 mm on
    #: the width no longer depends on the travel (20 and 40 mm within 1 cm), as thesis §6.2 says.
    slide: float = 0.02
    t_open: float = 1.0              #: longest opening step (s); the stop condition ends it earlier
    mass_scaling_dt_factor: float = 4.0   #: steps 1-2: BELOW MIN to this × the smallest increment; ≤ 1: none
    bulk_viscosity: tuple = (0.06, 1.2)   #: *BULK VISCOSITY b1, b2 of every step (the solver's defaults)
    hourglass: str = "viscous"       #: CPE4R hourglass form, "viscous" (the solver's default) or "stiffness"
    hourglass_scale: float = 1.0     #: hourglass coefficient x the solver's default for the form
    dt_scale: float = 1.0            #: *DYNAMIC SCALE FACTOR of every step (1: none written); perturbs the increments
    stop: bool = True                #: *STOP CONDITION in the opening step
    #: FLOW rule: "physical" (u_max > flow_width_fraction × B, the same on every mesh) or
    #: "half-element" (u_max > flow_fraction × the outlet element length, thesis §6.2)
    criterion: str = "physical"
    flow_fraction: float = 0.5       #: half-element: FLOW limit as a fraction of the outlet element length
    flow_width_fraction: float = FLOW_WIDTH_FRACTION   #: physical: FLOW limit as a fraction of B
    ke_fraction: float = 0.02        #: ARREST: ALLKE below this fraction of its peak ...
    hold: float = 0.05               #: ... for this long (s)
    min_open_time: float = 0.05      #: ARREST not before this step time (s)
    growth: float | None = None      #: ARREST also when u_max grows < this × the FLOW limit over `hold` (None: GROWTH[criterion])
    field_frames: int = 4            #: frames per step (0: none)
    history_points: int = 200        #: history rows per step
    gravity: float = G
    title: str = ""

    # ---- derived ------------------------------------------------------------------------------
    @property
    def th(self) -> float:
        return math.radians(self.theta)

    @property
    def r_out(self) -> float:
        """Distance along the wall from the apex to the outlet edge."""
        return self.outlet_width / (2.0 * math.sin(self.th))

    @property
    def mu(self) -> float:
        return math.tan(math.radians(self.phi_w))

    def arc_centre_radius(self) -> tuple[float, float]:
        """(y_c, ρ_a) of the outlet arc: centre (0, y_c), radius ρ_a, through the wall point at r_out."""
        if self.arch == "apex":
            return 0.0, self.r_out
        b = math.radians(self.beta)
        s = math.sin(self.th + b)
        return self.r_out * math.sin(b) / s, self.r_out * math.sin(self.th) / s

    def bottom_radius(self, a: np.ndarray) -> np.ndarray:
        """Distance from the apex along the ray at angle a (from the vertical) to the outlet arc."""
        yc, ra = self.arc_centre_radius()
        ca = np.cos(a)
        return yc * ca + np.sqrt(yc ** 2 * ca ** 2 - yc ** 2 + ra ** 2)

    def top_radius(self, a: np.ndarray) -> np.ndarray:
        return self.height / np.cos(a)

    def n_radial(self) -> int:
        da = self.th / self.n_arc
        ratio = float(self.top_radius(np.array(0.0)) / self.bottom_radius(np.array(0.0)))
        if ratio <= 1.0:
            raise ValueError(f"the top surface (H = {self.height:g} m) is not above the outlet "
                             f"(r = {float(self.bottom_radius(np.array(0.0))):.4g} m)")
        return max(2, int(math.ceil(math.log(ratio) / da)))

    def element_length(self) -> float:
        """Length of an outlet element along the arc (at the axis)."""
        return float(self.bottom_radius(np.array(0.0))) * self.th / self.n_arc

    def wave_speed(self) -> float:
        e, n = self.young, self.poisson
        m = e * (1 - n) / ((1 + n) * (1 - 2 * n))
        return math.sqrt(m / self.density)

    def stable_dt(self) -> float:
        """Smallest element increment, with the solver's 0.9 safety and b1 = 0.06 damping."""
        return 0.9 * self.element_length() / self.wave_speed() * (math.sqrt(1 + 0.06 ** 2) - 0.06)

    def freeze_time(self) -> float:
        return self.t_gravity + (self.t_slide if self.state == "passive" else 0.0)

    # ---- mesh -------------------------------------------------------------------------------
    def mesh(self):
        """nodes (n, 2), elements (m, 4) 0-based, and index sets."""
        n, mrad = self.n_arc, self.n_radial()
        a = np.linspace(0.0, self.th, n + 1)
        rb, rt = self.bottom_radius(a), self.top_radius(a)
        s = np.linspace(0.0, 1.0, mrad + 1)
        r = rb[None, :] * (rt / rb)[None, :] ** s[:, None]             # (mrad+1, n+1)
        x = r * np.sin(a)[None, :]
        y = r * np.cos(a)[None, :]
        x[:, 0] = 0.0
        y[-1, :] = self.height                                          # exact flat top
        nodes = np.column_stack([x.ravel(), y.ravel()])
        nid = np.arange((mrad + 1) * (n + 1)).reshape(mrad + 1, n + 1)
        elems = np.array([[nid[j, i], nid[j, i + 1], nid[j + 1, i + 1], nid[j + 1, i]]
                          for j in range(mrad) for i in range(n)])
        eid = np.arange(mrad * n).reshape(mrad, n)
        sets = dict(n_axis=nid[:, 0], n_wall=nid[:, n], n_bottom=nid[0, :], n_top=nid[-1, :],
                    e_wall=eid[:, n - 1], e_bottom=eid[0, :], e_top=eid[-1, :])
        return nodes, elems, sets

    def n_elements(self) -> int:
        return self.n_arc * self.n_radial()

    # ---- material ---------------------------------------------------------------------------
    def vumat_strength(self) -> tuple[float, float, float]:
        """(φ, ψ, f) the VUMAT gets: the angles (deg) and the factor on fc(σ1). "nonassociated": φ, ψ,
        1. "davis": φ* = ψ* with tan φ* = η tan φ, and f such that the VUMAT's cohesion
        fc (1 − sin φ*)/(2 cos φ*) (thesis eq. 6.9 with φ*) is η times that of the material."""
        if self.flow_rule == "nonassociated":
            return self.phi, self.psi, 1.0
        if self.flow_rule != "davis":
            raise ValueError(f"flow_rule {self.flow_rule!r}: expected nonassociated or davis")
        if self.flow == "bilinear":
            raise ValueError("flow_rule davis scales fc(σ1) by a factor; the bilinear flow function's first leg "
                             "does not scale with fc0 and k: give it as a table")
        f, p = math.radians(self.phi), math.radians(self.psi)
        eta = math.cos(p) * math.cos(f) / (1.0 - math.sin(p) * math.sin(f))
        fs = math.atan(eta * math.tan(f))
        scale = eta * (1.0 - math.sin(f)) / math.cos(f) * math.cos(fs) / (1.0 - math.sin(fs))
        return math.degrees(fs), math.degrees(fs), scale

    def material_lines(self) -> list[str]:
        kind = {"linear": 1, "bilinear": 2, "table": 3}[self.flow]
        phi, psi, f = self.vumat_strength()
        table = [(s1, f * fc) for s1, fc in self.table] if self.flow == "table" else []
        props = [self.young, self.poisson, phi, psi, 0.0, 0, 0,                             # 1-7
                 kind, f * self.fc0, f * self.k, self.freeze_time(), 0,                 # 8-12
                 0, 0, 0, len(table)]                                                   # 13-16
        for s1, fc in table:
            props += [s1, fc]
        lines = ["*MATERIAL, NAME=MC-POWDER", "*DENSITY", fmt(self.density),
                 f"*USER MATERIAL, CONSTANTS={len(props)}"]
        lines += [", ".join(fmt(v) for v in props[i:i + 8]) for i in range(0, len(props), 8)]
        lines += ["*DEPVAR", "8"]
        return lines

    # ---- writer -----------------------------------------------------------------------------
    def inp_text(self) -> str:
        nodes, elems, sets = self.mesh()
        nn = len(nodes)
        th = self.th
        title = self.title or (f"Arching, theta={self.theta:g} deg, B={self.outlet_width:.6g} m, "
                               f"H={self.height:g} m, {self.arch} arch, {self.state}, {len(elems)} CPE4R")
        L = ["*HEADING", title,
             "** Generated by bulkflow-make-arching (scripts/bulkflow/arching/scene.py). Parameters:"]
        for f in dataclasses.fields(self):
            L.append(f"**   {f.name} = {getattr(self, f.name)!r}")
        L.append(f"** Derived: r_out = {self.r_out:.6g} m, outlet element {self.element_length():.5g} m, "
                 f"c_d = {self.wave_speed():.5g} m/s, stable dt ~ {self.stable_dt():.4g} s, "
                 f"freeze time {self.freeze_time():.6g} s")
        L.append("*NODE, NSET=ALLN")
        L += [f"{i + 1}, {p[0]:.10g}, {p[1]:.10g}" for i, p in enumerate(nodes)]
        L.append("*ELEMENT, TYPE=CPE4R, ELSET=POWDER")
        L += [f"{i + 1}, " + ", ".join(str(v + 1) for v in e) for i, e in enumerate(elems)]
        L += nset("AXIS", sets["n_axis"]) + nset("OUTLETN", sets["n_bottom"])
        L += elset("WALLE", sets["e_wall"]) + elset("BOTTOME", sets["e_bottom"])
        if self.hourglass == "viscous" and self.hourglass_scale == 1.0:
            L += ["*SOLID SECTION, ELSET=POWDER, MATERIAL=MC-POWDER", "1."]
        else:
            L += [f"*SECTION CONTROLS, NAME=HG, HOURGLASS={self.hourglass.upper()}", fmt(self.hourglass_scale),
                  "*SOLID SECTION, ELSET=POWDER, MATERIAL=MC-POWDER, CONTROLS=HG", "1."]
        L += self.material_lines()
        L += ["*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP, TIME=TOTAL TIME", f"0., 0., {fmt(self.t_gravity)}, 1."]
        if self.state == "passive":
            L += ["*AMPLITUDE, NAME=SLIDE, DEFINITION=SMOOTH STEP, TIME=STEP TIME", f"0., 0., {fmt(self.t_slide)}, 1."]

        L += ["*BOUNDARY", "AXIS, XSYMM",
              "*SURFACE, TYPE=ELEMENT, NAME=POWDER_WALL", "WALLE, S2",
              "*SURFACE, TYPE=ELEMENT, NAME=POWDER_OUTLET", "BOTTOME, S1"]
        ref_wall, ref_plate = nn + 1, nn + 2
        r_top = 1.3 * float(self.top_radius(np.array(th)))
        r_low = 0.3 * self.r_out
        yc, ra = self.arc_centre_radius()
        half = th + math.radians(self.beta if self.arch == "enstad" else 0.0)   # arc half-angle
        a0, a1 = -math.radians(5.0), half + math.radians(3.0)
        L += ["*NODE, NSET=WALLREF", f"{ref_wall}, 0., 0.", "*NODE, NSET=PLATEREF", f"{ref_plate}, 0., 0.",
              # material on the left of the direction of travel (docs/keywords.md)
              "*SURFACE, TYPE=SEGMENTS, NAME=WALL",
              f"START, {r_low * math.sin(th):.10g}, {r_low * math.cos(th):.10g}",
              f"LINE, {r_top * math.sin(th):.10g}, {r_top * math.cos(th):.10g}",
              "*SURFACE, TYPE=SEGMENTS, NAME=PLATE",
              f"START, {ra * math.sin(a0):.10g}, {yc + ra * math.cos(a0):.10g}",
              f"CIRCL, {ra * math.sin(a1):.10g}, {yc + ra * math.cos(a1):.10g}, 0., {yc:.10g}",
              "*RIGID BODY, REF NODE=WALLREF, ANALYTICAL SURFACE=WALL",
              "*RIGID BODY, REF NODE=PLATEREF, ANALYTICAL SURFACE=PLATE",
              "*BOUNDARY", "WALLREF, ENCASTRE", "PLATEREF, ENCASTRE",
              "*SURFACE INTERACTION, NAME=WALLFRICTION", "*FRICTION", f"{self.mu:.10g}",
              "*CONTACT PAIR, INTERACTION=WALLFRICTION", "POWDER_WALL, WALL", "POWDER_OUTLET, PLATE"]
        ms = self.mass_scaling_dt()
        outputs = []
        if self.field_frames > 0:
            outputs += [f"*OUTPUT, FIELD, NUMBER INTERVAL={self.field_frames}", "*NODE OUTPUT", "U, V",
                        "*ELEMENT OUTPUT", "S, SDV"]
        outputs += [f"*OUTPUT, HISTORY, NUMBER INTERVAL={self.history_points}",
                    "*ENERGY OUTPUT, VARIABLE=PRESELECT", "*NODE OUTPUT, NSET=OUTLETN", "U2"]
        L += ["*STEP, NAME=GRAVITY, NLGEOM=YES", "Gravity by smooth step, outlet closed",
              self.dynamic_line(), f", {fmt(self.t_gravity)}", "*BULK VISCOSITY",
              ", ".join(fmt(v) for v in self.bulk_viscosity)]
        if ms > 0:
            L += [f"*FIXED MASS SCALING, DT={ms:.6g}, TYPE=BELOW MIN"]
        L += ["*DLOAD, AMPLITUDE=RAMP", f"POWDER, GRAV, {fmt(self.gravity)}, 0., -1."]
        L += outputs + ["*END STEP"]
        if self.state == "passive":
            L += ["*STEP, NAME=SLIDE, NLGEOM=YES", "The plate slides toward the apex: passive state",
                  self.dynamic_line(), f", {fmt(self.t_slide)}",
                  "*BOUNDARY, AMPLITUDE=SLIDE", f"PLATEREF, 2, 2, {-self.slide:.10g}", "*END STEP"]
        L += ["*STEP, NAME=OPEN, NLGEOM=YES", "Outlet opened: contact with the plate deleted",
              self.dynamic_line(), f", {fmt(self.t_open)}"]
        if ms > 0:
            L += ["*FIXED MASS SCALING, FACTOR=1"]
        L += ["*CONTACT PAIR, OP=DELETE", "POWDER_OUTLET, PLATE"]
        if self.stop:
            L += [f"*STOP CONDITION, NSET=ALLN, DISPLACEMENT={self.flow_limit():.6g}, "
                  f"KINETIC FRACTION={fmt(self.ke_fraction)}, HOLD={fmt(self.hold)}, "
                  f"MIN TIME={fmt(self.min_open_time)}, GROWTH={fmt(self.growth_fraction())}"]
        L += ["*END STEP", ""]
        return "\n".join(L)

    def mass_scaling_dt(self) -> float:
        """Target element increment of steps 1-2 (0: no mass scaling)."""
        if self.mass_scaling_dt_factor <= 1.0:
            return 0.0
        return self.mass_scaling_dt_factor * self.stable_dt() / 0.9

    def dynamic_line(self) -> str:
        if self.dt_scale == 1.0:
            return "*DYNAMIC, EXPLICIT"
        return f"*DYNAMIC, EXPLICIT, SCALE FACTOR={fmt(self.dt_scale)}"

    def growth_fraction(self) -> float:
        return GROWTH[self.criterion] if self.growth is None else self.growth

    def flow_limit(self) -> float:
        """The FLOW displacement of `*STOP CONDITION` (m) under the scene's criterion."""
        if self.criterion == "physical":
            return self.flow_width_fraction * self.outlet_width
        if self.criterion == "half-element":
            return self.flow_fraction * self.element_length()
        raise ValueError(f"criterion {self.criterion!r}: expected one of {', '.join(CRITERIA)}")

    def write(self, path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(self.inp_text())
        return path


def fmt(v: float) -> str:
    return f"{v:.9g}"


def _id_lines(ids) -> list[str]:
    ids = [str(int(i) + 1) for i in ids]
    return [", ".join(ids[k:k + 16]) for k in range(0, len(ids), 16)]


def nset(name, ids) -> list[str]:
    return [f"*NSET, NSET={name}"] + _id_lines(sorted(set(int(i) for i in ids)))


def elset(name, ids) -> list[str]:
    return [f"*ELSET, ELSET={name}"] + _id_lines(sorted(set(int(i) for i in ids)))


def scene_from_case(case: str, reading: str = "c0", **overrides) -> ArchingScene:
    """An ArchingScene for a named case (A, B, polymer, sic) under a c0 reading, with overrides."""
    d = case_material(case, reading)
    kw = dict(theta=d["theta"], height=d["height"], density=d["rho"], phi=d["phi"], phi_w=d["phi_w"],
              k=d["k"], fc0=d["fc0"])
    kw.update(overrides)
    return ArchingScene(**kw)


def add_scene_arguments(p: argparse.ArgumentParser) -> None:
    """Options shared by bulkflow-make-arching and bulkflow-cow."""
    d = ArchingScene()
    p.add_argument("--case", choices=CASE_NAMES, help="named parameter set (thesis Tables 6.1, 6.2)")
    p.add_argument("--reading", choices=READINGS, default="c0",
                   help="how the tabulated cohesion value becomes fc0: c0 (eq. 6.9) or fc0 (taken as is)")
    g = p.add_argument_group("geometry and mesh (override the case)")
    g.add_argument("--theta", type=float)
    g.add_argument("--height", type=float, help="top surface height above the apex (m)")
    g.add_argument("--arch", choices=["apex", "enstad"], default=d.arch)
    g.add_argument("--beta", type=float, default=None,
                   help="Enstad arch angle (deg); default: the theory's (bulkflow.theory.enstad_outlet_arch)")
    g.add_argument("--n-arc", type=int, default=d.n_arc, help="elements along the outlet arc")
    g = p.add_argument_group("material (override the case)")
    g.add_argument("--density", type=float)
    g.add_argument("--young", type=float, default=d.young)
    g.add_argument("--poisson", type=float, default=d.poisson)
    g.add_argument("--phi", type=float)
    g.add_argument("--phi-w", type=float)
    g.add_argument("--psi", type=float, default=d.psi, help="dilation angle (deg), 0 (the thesis) .. phi")
    g.add_argument("--flow-rule", choices=["nonassociated", "davis"], default=d.flow_rule,
                   help="davis: the VUMAT gets Davis's associated material of equal strength (phi*, c*)")
    g.add_argument("--fc0", type=float, help="unconfined yield strength at zero consolidation (Pa)")
    g.add_argument("--c0", type=float, help="cohesion at zero consolidation (Pa), converted by eq. 6.9")
    g.add_argument("--k", type=float)
    g.add_argument("--flow", choices=["linear", "bilinear", "table"], default=d.flow)
    g.add_argument("--table", type=str, default="", help="flow table 's1:fc,s1:fc,...' (Pa)")
    g = p.add_argument_group("steps")
    g.add_argument("--state", choices=["passive", "active"], default=d.state)
    g.add_argument("--t-gravity", type=float, default=d.t_gravity)
    g.add_argument("--t-slide", type=float, default=d.t_slide)
    g.add_argument("--slide", type=float, default=d.slide)
    g.add_argument("--t-open", type=float, default=d.t_open)
    g.add_argument("--mass-scaling", type=float, default=d.mass_scaling_dt_factor,
                   help="steps 1-2: element increments raised to this x the smallest (<= 1: no mass scaling)")
    g.add_argument("--no-stop", action="store_true", help="no *STOP CONDITION: the opening step runs in full")
    g.add_argument("--criterion", choices=CRITERIA, default=d.criterion,
                   help="FLOW rule: u_max > --flow-width-fraction x B (physical) or > half the outlet element "
                        "(half-element, thesis 6.2)")
    g.add_argument("--flow-width-fraction", type=float, default=d.flow_width_fraction,
                   help="physical criterion: the FLOW displacement as a fraction of the outlet width B")
    g.add_argument("--hold", type=float, default=d.hold)
    g.add_argument("--ke-fraction", type=float, default=d.ke_fraction)
    g.add_argument("--field-frames", type=int, default=d.field_frames)


def scene_from_args(a, outlet_width: float | None = None) -> ArchingScene:
    base = {}
    if a.case:
        d = case_material(a.case, a.reading)
        base = dict(theta=d["theta"], height=d["height"], density=d["rho"], phi=d["phi"],
                    phi_w=d["phi_w"], k=d["k"], fc0=d["fc0"])
    for name, key in [("theta", "theta"), ("height", "height"), ("density", "density"), ("phi", "phi"),
                      ("phi_w", "phi_w"), ("k", "k"), ("fc0", "fc0")]:
        v = getattr(a, name)
        if v is not None:
            base[key] = v
    if a.c0 is not None:
        base["fc0"] = fc0_from_c0(a.c0, base.get("phi", ArchingScene.phi))
    table = ()
    if a.table:
        table = tuple(tuple(float(v) for v in pair.split(":")) for pair in a.table.split(","))
    beta = a.beta
    if beta is None:
        beta = 0.0
        if a.arch == "enstad":
            d = ArchingScene()
            beta = enstad_beta(dict(rho=base.get("density", d.density), phi=base.get("phi", d.phi),
                                    phi_w=base.get("phi_w", d.phi_w), k=base.get("k", d.k),
                                    fc0=base.get("fc0", d.fc0), theta=base.get("theta", d.theta),
                                    height=base.get("height", d.height)))
    s = ArchingScene(**base, arch=a.arch, beta=beta, n_arc=a.n_arc, young=a.young, poisson=a.poisson,
                     psi=a.psi, flow_rule=a.flow_rule, flow=a.flow, table=table, state=a.state, t_gravity=a.t_gravity, t_slide=a.t_slide,
                     slide=a.slide, t_open=a.t_open, mass_scaling_dt_factor=a.mass_scaling,
                     stop=not a.no_stop, criterion=a.criterion, flow_width_fraction=a.flow_width_fraction,
                     hold=a.hold, ke_fraction=a.ke_fraction, field_frames=a.field_frames)
    if outlet_width is not None:
        s.outlet_width = outlet_width
    return s


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="bulkflow-make-arching", description=__doc__.split("\n\n")[0])
    p.add_argument("-o", "--output", required=True, help="the .inp file to write")
    p.add_argument("--outlet-width", type=float, required=True, help="B (m)")
    add_scene_arguments(p)
    a = p.parse_args(argv)
    s = scene_from_args(a, a.outlet_width)
    path = s.write(a.output)
    print(f"{path}: {s.n_elements()} CPE4R elements, r_out {s.r_out:.4g} m, outlet element "
          f"{s.element_length() * 1e3:.3g} mm, stable dt ~ {s.stable_dt():.3g} s, fc0 {s.fc0:.5g} Pa")
    return 0


if __name__ == "__main__":
    sys.exit(main())
