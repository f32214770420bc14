"""What the MPM post-processing needs from a 2D material-point scene: its `*MPM WALL`s step by
step (a wall deleted in a later step is the closable outlet), the `*OUTFLOW` level, the step
names, and the wedge hopper's geometry (θ, b, outlet level) as bulkflow-make-mpm-hopper lays it
out. Not a reader of the whole scene: the solver reads and checks scenes; this takes the lines it
needs (keyword syntax: docs/keywords.md, section "Material point method").
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from bulkflow.post.run_output import _lines, _params


@dataclass
class MpmWall:
    name: str
    kind: str                  #: FRICTION or SYMMETRY
    p0: tuple                  #: 2D segment p0 -> p1 (material on its left)
    p1: tuple
    first_step: int = 1        #: first step (1-based) in which the wall acts
    last_step: int | None = None   #: last step it acts in (None: to the end)

    def active(self, step: int) -> bool:
        return self.first_step <= step and (self.last_step is None or step <= self.last_step)


@dataclass
class MpmScene:
    walls: list = field(default_factory=list)     #: [MpmWall] in scene order
    steps: list = field(default_factory=list)     #: step names (1-based step k is steps[k-1])
    outflow: float | None = None                  #: *OUTFLOW, BELOW level
    cell: float | None = None                     #: *MPM GRID, CELL

    def step_name(self, step: int) -> str:
        return self.steps[step - 1] if 1 <= step <= len(self.steps) else f"step {step}"

    def outlets(self) -> list:
        """Walls that a step deletes: the closable outlet of a hopper scene."""
        return [w for w in self.walls if w.last_step is not None]

    def symmetry_x(self) -> float | None:
        """x of a vertical symmetry wall (the half model's axis), if there is one."""
        for w in self.walls:
            if w.kind == "SYMMETRY" and abs(w.p0[0] - w.p1[0]) < 1e-12:
                return w.p0[0]
        return None


def read_mpm_scene(path) -> MpmScene:
    """The walls, steps, outflow level and cell of a 2D MPM scene (*INCLUDE followed)."""
    scene = MpmScene()
    step = 0
    kw, params = "", {}
    by_name = {}
    for line in _lines(Path(path)):
        if line.startswith("*"):
            kw, params = _params(line)
            if kw == "STEP":
                step += 1
                scene.steps.append(params.get("NAME", f"STEP-{step}"))
            elif kw == "MPM GRID" and "CELL" in params:
                scene.cell = float(params["CELL"])
            elif kw == "OUTFLOW" and "BELOW" in params:
                scene.outflow = float(params["BELOW"])
            elif kw == "MPM WALL" and params.get("OP") == "DELETE":
                wall = by_name.get(params.get("NAME"))
                if wall is not None:
                    wall.last_step = step - 1
                kw = ""
            continue
        if kw == "MPM WALL":
            nums = [float(f) for f in line.split(",") if f.strip()]
            if len(nums) != 4:          # a 3D wall (point, normal) or a box line: not drawn
                kw = ""
                continue
            wall = MpmWall(params.get("NAME", ""), params.get("TYPE", "FRICTION"), tuple(nums[:2]),
                           tuple(nums[2:]), first_step=max(step, 1))
            scene.walls.append(wall)
            by_name[wall.name] = wall
            kw = ""
    return scene


def hopper_geometry(scene: MpmScene, tol: float = 1e-6) -> dict | None:
    """θ (deg from the vertical), full outlet width b and outlet level y0 of a wedge-hopper half
    model: the outlet is the horizontal wall a step deletes, the hopper wall the inclined wall that
    starts at its end (b/2, y0). None if the scene has no such pair."""
    axis = scene.symmetry_x() or 0.0
    for out in scene.outlets():
        if abs(out.p0[1] - out.p1[1]) > tol:
            continue
        y0 = out.p0[1]
        edge = max(out.p0, out.p1, key=lambda p: p[0])
        for w in scene.walls:
            if w is out or w.kind == "SYMMETRY":
                continue
            for a, b in ((w.p0, w.p1), (w.p1, w.p0)):
                if math.hypot(a[0] - edge[0], a[1] - edge[1]) < tol and b[1] > a[1] + tol:
                    theta = math.degrees(math.atan2(abs(b[0] - a[0]), b[1] - a[1]))
                    return dict(theta=theta, outlet=2.0 * (edge[0] - axis), y0=y0, wall=w, outlet_wall=out)
    return None
