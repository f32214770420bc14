"""The 3D slab of the flat-bottomed bin (bulkflow.mpm.bin_slab): glass walls on node planes at
z = 0 and z = t, the particles filling exactly the slot, the bin's walls as the 2D scene's."""
import math
import re

import pytest

from bulkflow.mpm.bin_slab import SMALL, slab_scene


def grid(text):
    m = re.search(r"\*MPM GRID, CELL=([0-9.eE+-]+), SHAPE=GIMP\n(.*)\n(.*)\n", text)
    h = float(m.group(1))
    lo = [float(v) for v in m.group(2).split(",")]
    hi = [float(v) for v in m.group(3).split(",")]
    return h, lo, hi


def wall(text, name):
    m = re.search(rf"\*MPM WALL, NAME={name}[^\n]*\n(.*)\n", text)
    return [float(v) for v in m.group(1).split(",")]


@pytest.mark.parametrize("case", ["concentric", "eccentric"])
@pytest.mark.parametrize("gap_cells", [1, 4])
def test_glass_walls_on_node_planes(case, gap_cells):
    text, g, t = slab_scene(case, gap_cells=gap_cells, cell=SMALL["cell"], outlet=SMALL["outlet"],
                            width=SMALL["width"], fill=SMALL["fill"])
    h, lo, hi = grid(text)
    assert t == pytest.approx(gap_cells * h)
    for z in (0.0, t):                                   # both glass walls on node planes
        k = (z - lo[2]) / h
        assert abs(k - round(k)) < 1e-9
    assert wall(text, "FRONT") == pytest.approx([0, 0, 0, 0, 0, 1])
    assert wall(text, "BACK") == pytest.approx([0, 0, t, 0, 0, -1])
    mu = math.tan(math.radians(7.0))
    for name in ("FRONT", "BACK"):
        assert re.search(rf"NAME={name}, FRICTION=([0-9.]+)", text).group(1) == f"{mu:.7f}"
    assert f"Z1=0., Z2={t:.9f}" in text                # the particles fill the slot exactly
    assert ("NAME=AXIS, TYPE=SYMMETRY" in text) == (case == "concentric")
    assert ("NAME=LEFT" in text) == (case == "eccentric")
    assert ", GRAV, 9.81, 0., -1., 0." in text


def test_gap_must_be_a_cell_or_more():
    with pytest.raises(ValueError):
        slab_scene(gap_cells=0)


def test_smooth_glass_keeps_the_bins_wall_friction():
    text, _, _ = slab_scene(gap_cells=2, glass_friction=0.0, cell=SMALL["cell"], outlet=SMALL["outlet"],
                            width=SMALL["width"], fill=SMALL["fill"])
    assert "NAME=FRONT, FRICTION=0.0000000" in text and "NAME=BACK, FRICTION=0.0000000" in text
    assert f"NAME=RIGHT, FRICTION={math.tan(math.radians(7.0)):.7f}" in text
