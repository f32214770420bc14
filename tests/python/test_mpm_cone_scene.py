"""bulkflow-make-cone (scripts/bulkflow/mpm/cone_scene.py): the quarter conical hopper scene.

The fill polygons are checked by casting the solver's lattice through them (the same rule as
src/mpm/mpm_setup.f90: centres lo + (i + 1/2) h/PPC, a polygon per z layer, Z1 <= z < Z2): every
particle is inside the cone and the cylinder, none behind a symmetry plane, and their number is the
hopper's quarter volume times the lattice density within the staircase of one spacing. The wall
profile, the symmetry planes, the outlet and the steps are read back from the text.
"""
import math
import re

import numpy as np
import pytest
from matplotlib.path import Path

from bulkflow.mpm.cone_scene import cone_geometry, cone_scene, layer_polygon
from bulkflow.mpm.study_conical import cone_mfi  # noqa: F401  (the study module imports cleanly)


def regions(text):
    lines = text.splitlines()
    out = []
    for i, line in enumerate(lines):
        if line.startswith("*PARTICLES"):
            z1 = float(re.search(r"Z1=([-0-9.]+)", line).group(1))
            z2 = float(re.search(r"Z2=([-0-9.]+)", line).group(1))
            pts = []
            for data in lines[i + 1:]:
                if data.startswith("*"):
                    break
                pts.append([float(v) for v in data.split(",")])
            out.append((z1, z2, np.array(pts)))
    return out


def lattice_points(text, cell, ppc):
    grid = text.splitlines()[[l.startswith("*MPM GRID") for l in text.splitlines()].index(True) + 1]
    lo = np.array([float(v) for v in grid.split(",")])
    dx = cell / ppc
    pts = []
    for z1, z2, poly in regions(text):
        k = np.arange(0, 200)
        zs = lo[2] + (k + 0.5) * dx
        zs = zs[(zs >= z1) & (zs < z2)]
        assert len(zs) == 1, "each region holds exactly one lattice layer"
        xs = lo[0] + (np.arange(0, 200) + 0.5) * dx
        ys = lo[1] + (np.arange(0, 400) + 0.5) * dx
        X, Y = np.meshgrid(xs, ys)
        P = np.c_[X.ravel(), Y.ravel()]
        inside = Path(poly).contains_points(P)
        pts.append(np.c_[P[inside], np.full(inside.sum(), zs[0])])
    return np.concatenate(pts)


@pytest.mark.parametrize("theta", [15.0, 30.0, 45.0])
def test_fill_is_inside_the_hopper_and_fills_it(theta):
    cell, ppc, outlet, radius, height = 0.05, 2, 0.2, 0.4, 0.8
    text = cone_scene(cell=cell, ppc=ppc, theta=theta, outlet=outlet, radius=radius, height=height)
    x = lattice_points(text, cell, ppc)
    y0, y_t = cone_geometry(theta, outlet, radius)
    r = np.hypot(x[:, 0], x[:, 2])
    r_wall = np.minimum(x[:, 1] * math.tan(math.radians(theta)), radius)
    assert (r < r_wall).all()
    assert x[:, 0].min() > 0 and x[:, 2].min() > 0
    assert x[:, 1].min() > y0 and x[:, 1].max() < y0 + height
    # quarter volume of the frustum (and the cylinder above it) against the lattice's count
    top = y0 + height
    t = math.tan(math.radians(theta))
    yc = min(y_t, top)
    r0, r1 = y0 * t, yc * t
    volume = math.pi / 12 * (yc - y0) * (r0 * r0 + r0 * r1 + r1 * r1) + math.pi / 4 * radius ** 2 * max(top - y_t, 0)
    n_expected = volume / (cell / ppc) ** 3
    # the staircase loses up to a shell one spacing thick over the wall; the lattice's first and last
    # layers in y may reach half a spacing past the fill's ends
    assert 0.85 * n_expected < len(x) < 1.03 * n_expected


def test_scene_walls_and_steps():
    text = cone_scene(theta=30.0, outlet=0.2, radius=0.4, height=0.8, wall_friction=20.0)
    y0, y_t = cone_geometry(30.0, 0.2, 0.4)
    assert "*SURFACE, TYPE=REVOLUTION, NAME=CONE\n0., 0., 0., 0., 1., 0.\n" in text
    assert f"START, 0.100000000, {y0:.9f}\nLINE, 0.400000000, {y_t:.9f}\nLINE, 0.400000000," in text
    assert "*CONTACT PAIR, INTERACTION=WALL-FRICTION\n, CONE\n" in text
    assert f"*FRICTION\n{math.tan(math.radians(20.0)):.9f}\n" in text
    assert "*MPM WALL, NAME=SYMX, TYPE=SYMMETRY\n0., 0., 0., 1., 0., 0.\n" in text
    assert "*MPM WALL, NAME=SYMZ, TYPE=SYMMETRY\n0., 0., 0., 0., 0., 1.\n" in text
    assert "*MPM WALL, NAME=OUTLET, OP=DELETE" in text.split("*STEP, NAME=DISCHARGE")[1]
    assert "*INFLOW" not in text
    assert "*INFLOW" in cone_scene(inflow=True)
    assert "DISCHARGE" not in cone_scene(discharge=False)
    # the symmetry planes are node planes: 4 cells behind each
    grid = text.split("*MPM GRID, CELL=0.05, SHAPE=GIMP\n")[1].splitlines()[0]
    assert grid.startswith("-0.200000000,") and grid.endswith(", -0.200000000")


def test_layer_polygon_and_bad_input():
    # a layer beyond the bin's radius, or above the fill's start at the outlet, misses the hopper
    assert layer_polygon(0.45, 0.2, 1.0, 30.0, 0.2, 0.4) is None
    p = layer_polygon(0.0125, 0.173, 0.973, 30.0, 0.2, 0.4)
    assert p[0] == (0.0, 0.173) and p[-1] == (0.0, 0.973)
    with pytest.raises(ValueError):
        cone_scene(radius=0.05, outlet=0.2)
    with pytest.raises(ValueError):
        cone_scene(theta=90.0)
