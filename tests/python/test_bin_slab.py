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


def _frame_file(path, x, s, t=0.3):
    """A particle file with one frame at total time t, the datasets glass_at_rest reads."""
    import h5py
    with h5py.File(path, "w") as f:
        g = f.create_group("particles").create_group("000001")
        g.attrs["total_time"] = [t]
        g["coordinates"] = x
        g["S"] = s


def test_glass_at_rest_reads_k_and_the_mobilised_friction_of_the_glass_layers(tmp_path):
    import numpy as np

    from bulkflow.mpm.bin_slab import glass_at_rest

    mu = math.tan(math.radians(7.0))
    rng = np.random.default_rng(3)
    rows = []
    for y in (0.05, 0.15):                       # two height bands of a 0.2 m fill
        for z in (0.002, 0.006, 0.010, 0.014):   # four layers across the gap, jittered below
            for xx in (0.05, 0.06):
                syy = -1000.0 * (0.2 - y) / 0.2
                szz = 0.43 * syy
                glass = z in (0.002, 0.014)
                # the glass layers hold half the Coulomb limit low down, all of it high up; the
                # inner layers' shear is not the glass's and must not count
                mob = (0.5 if y < 0.1 else 1.0) if glass else 0.1
                syz = np.sign(z - 0.008) * mob * mu * abs(szz)
                rows.append(([xx, y, z + rng.uniform(-2e-4, 2e-4)], [0.43 * syy, syy, szz, 0.0, syz, 0.0]))
    x = np.array([r[0] for r in rows])
    s = np.array([r[1] for r in rows])
    _frame_file(tmp_path / "slab.h5", x, s)
    res = glass_at_rest(tmp_path / "slab", 0.3, (0.0, 0.1), mu, 0.2, bands=2)
    assert [r["K"] for r in res] == pytest.approx([0.43, 0.43])
    assert [r["mobilised"] for r in res] == pytest.approx([0.5, 1.0])
    # a 2D file (out-of-plane coordinate 0, four stress columns): K only
    x2 = x.copy()
    x2[:, 2] = 0
    _frame_file(tmp_path / "flat.h5", x2, s[:, :4])
    res = glass_at_rest(tmp_path / "flat", 0.3, (0.0, 0.1), mu, 0.2, bands=2)
    assert [r["mobilised"] for r in res] == [None, None]
    assert [r["K"] for r in res] == pytest.approx([0.43, 0.43])


def wall_box(text, name):
    """The keyword line and the box (lo, hi) of a bounded 3D wall."""
    m = re.search(rf"(\*MPM WALL, NAME={name}[^\n]*)\n.*\n(.*)\n(.*)\n", text)
    return m.group(1), [float(v) for v in m.group(2).split(",")], [float(v) for v in m.group(3).split(",")]


@pytest.mark.parametrize("case", ["concentric", "eccentric"])
def test_open_edge_opens_the_box_faces_at_the_outlet_edge(case):
    common = dict(cell=SMALL["cell"], outlet=SMALL["outlet"], width=SMALL["width"], fill=SMALL["fill"])
    closed, _, _ = slab_scene(case, **common)
    assert "OPEN=" not in closed
    text, g, _ = slab_scene(case, open_edge=True, **common)
    edge = g["x_out1"] if case == "concentric" else g["x_out0"]
    for name in ("FLOOR", "OUTLET"):
        line, lo, hi = wall_box(text, name)
        face = re.search(r"OPEN=(X(LOW|HIGH))", line).group(1)
        # the open face is the box's face on the outlet's edge, x = edge
        assert (lo[0] if face == "XLOW" else hi[0]) == pytest.approx(edge, abs=1e-9)
    assert text.count("OPEN=") == 2


def _steps(text):
    """(name, the keyword lines of the step) of every step."""
    out = []
    for block in text.split("*STEP, NAME=")[1:]:
        name, _, body = block.partition("\n")
        out.append((name, body.split("*END STEP")[0]))
    return out


@pytest.mark.parametrize("three_d", [False, True])
def test_fill_in_layers_tops_up_by_inflow_between_the_fill_and_the_discharge(three_d):
    from bulkflow.mpm.bin_scene import bin_scene
    common = dict(cell=SMALL["cell"], outlet=SMALL["outlet"], width=SMALL["width"], fill=SMALL["fill"])
    make = (lambda **k: slab_scene(**k, **common)[0]) if three_d else (lambda **k: bin_scene(**k, **common))
    once = make()
    assert "*INFLOW" not in once and [n for n, _ in _steps(once)] == ["FILL", "DISCHARGE"]
    assert make(fill_layers=1) == once                   # one layer is the fill at once
    text = make(fill_layers=4, layer_time=0.05)
    steps = _steps(text)
    assert [n for n, _ in steps] == ["FILL", "FILL-2", "FILL-3", "FILL-4", "DISCHARGE"]
    # the scene's particles are the first layer only
    region = text.split("*PARTICLES")[1].split("*MPM WALL")[0]
    tops = [float(line.split(",")[1]) for line in region.splitlines()[1:] if line.strip()]
    assert max(tops) == pytest.approx(SMALL["fill"] / 4)
    for k, (name, body) in enumerate(steps[1:4], start=2):
        assert ", 0.05\n" in body                          # layer_time
        m = re.search(r"\*INFLOW, MATERIAL=MC-SAND, LEVEL=([0-9.]+), PPC=2\n(.*)\n", body)
        assert float(m.group(1)) == pytest.approx(SMALL["fill"] * k / 4)
        band = [float(v) for v in m.group(2).split(",")]
        # the band spans the bin between its walls (and the slot in 3D), the first layer's columns
        assert len(band) == (4 if three_d else 2)
        assert band[0] == pytest.approx(0.0) and band[len(band) // 2] == pytest.approx(SMALL["width"] / 2)
    assert "*INFLOW" not in steps[0][1] and "*INFLOW" not in steps[-1][1]
    assert "OP=DELETE" in steps[-1][1]


def test_fill_layers_must_be_one_or_more():
    from bulkflow.mpm.bin_scene import bin_scene
    with pytest.raises(ValueError):
        bin_scene(fill_layers=0)
    with pytest.raises(ValueError):
        slab_scene(fill_layers=2, layer_time=0.0)


def test_discharge_is_the_last_step_whatever_the_fill():
    import numpy as np
    from bulkflow.mpm.bin_slab import discharged_per_metre
    hist = np.array([(1, 0.1, 0.0), (3, 0.05, 0.0), (4, 0.1, 2.0), (4, 0.2, 5.0)],
                    dtype=[("step", float), ("step_time", float), ("MASS_OUT", float)])
    t, m = discharged_per_metre(hist, 2.0)
    assert t.tolist() == [0.1, 0.2] and m.tolist() == [4.0, 10.0]
