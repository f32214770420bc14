"""bulkflow-accuracy bin-mdr and the regularised families without a solver: the members' cells and
scenes (PIC TIME, the μ(I) block where the material takes it), the measure on synthetic discharge
histories (to T_ss, or to the end when the rate held), and the command line's checks."""
import numpy as np
import pytest

from bulkflow.accuracy import bin_mdr, bin_tss, cli, hopper_mdr
from bulkflow.mpm.bin_scene import OUTLET


@pytest.fixture(autouse=True)
def _module_defaults():
    """The CLI sets module globals; every test starts from the defaults and leaves them."""
    saved = (bin_mdr.PIC_TIME, bin_mdr.INERTIAL_FRICTION, hopper_mdr.PIC_TIME, hopper_mdr.INERTIAL_FRICTION)
    yield
    bin_mdr.PIC_TIME, bin_mdr.INERTIAL_FRICTION, hopper_mdr.PIC_TIME, hopper_mdr.INERTIAL_FRICTION = saved


def test_members_are_odd_numbers_of_cells_across_the_thesis_outlet():
    rows = bin_mdr.members(False)
    assert [r["edge_cells"] for r in rows] == [2, 3, 4]
    for r in rows:
        assert r["h"] == pytest.approx(OUTLET / (2 * r["edge_cells"] + 1), rel=1e-12)
    assert [r["edge_cells"] for r in bin_mdr.members(True)] == [1, 2, 3]


def test_scene_has_the_blend_rate_and_no_mu_of_i_unless_asked():
    text = bin_mdr.scene(bin_mdr.members(False)[0])
    assert "*MPM CONTROLS, PIC TIME=0.01," in text
    assert "*INERTIAL FRICTION" not in text
    assert "1000000., 0.3" in text                       # E = 1 MPa (module text)
    bin_mdr.INERTIAL_FRICTION = (55.2, 0.279, 0.71e-3, 2650.0)
    text = bin_mdr.scene(bin_mdr.members(False)[0])
    lines = text.splitlines()
    k = lines.index("*INERTIAL FRICTION")
    # inside the sand's material: after its hardening table, before the particles
    assert lines[k - 2] == "*MOHR COULOMB HARDENING" and lines[k + 2].startswith("*PARTICLES")
    assert [float(v) for v in lines[k + 1].split(",")] == [55.2, 0.279, 0.71e-3, 2650.0]


def test_inertial_friction_refuses_a_scene_without_one_mohr_coulomb_material():
    with pytest.raises(ValueError, match="exactly one"):
        bin_mdr.with_inertial_friction("*MATERIAL, NAME=X\n*USER MATERIAL, CONSTANTS=1\n1.\n", (40, 0.3, 1e-3, 2500))


def test_hopper_family_appends_the_block_to_the_user_material_constants():
    member = hopper_mdr.members(True)[0]
    plain = hopper_mdr.scene(member)
    hopper_mdr.INERTIAL_FRICTION = (37.1, 0.279, 0.5e-3, 2500.0)
    text = hopper_mdr.scene(member)
    n0 = int(plain.split("*USER MATERIAL, CONSTANTS=")[1].split("\n")[0])
    n1 = int(text.split("*USER MATERIAL, CONSTANTS=")[1].split("\n")[0])
    assert n1 == n0 + 5
    block = text.split("*USER MATERIAL, CONSTANTS=")[1].split("*DEPVAR")[0].split("\n")[-2]
    assert [float(v) for v in block.split(",")] == [1.0, 37.1, 0.279, 0.5e-3, 2500.0]


def _history(tmp_path, rates, t_open=0.3, t_end=2.8, m0=31.0):
    """A history CSV with a piecewise-constant discharge rate [(start after opening, rate), ...]."""
    t = np.round(np.arange(0.0, t_end + 1e-9, 0.01), 10)
    s = np.clip(t - t_open, 0.0, None)
    out = np.zeros_like(t)
    for i, (start, rate) in enumerate(rates):
        end = rates[i + 1][0] if i + 1 < len(rates) else np.inf
        out += rate * np.clip(np.minimum(s, end) - start, 0.0, None)
    step = np.where(t < t_open - 1e-12, 1.0, 2.0)
    base = tmp_path / "run"
    np.savetxt(f"{base}_history.csv", np.column_stack([t, step, np.where(step == 1, t, t - t_open), m0 - out, out]),
               delimiter=",", header="time,step,step_time,MASS,MASS_OUT", comments="")
    (tmp_path / "run.log").write_text("bulkflow: 3000 particles, 1 rank\n")
    return base


def test_measure_takes_the_rate_to_the_end_when_it_held(tmp_path):
    res = bin_mdr.measure(_history(tmp_path, [(0.0, 8.0)]), {})
    assert res["value"] == pytest.approx(8.0, rel=1e-9) and res["t_ss"] is None
    assert res["particles"] == 3000


def test_measure_stops_at_the_end_of_steady_discharge(tmp_path):
    # 8 kg/s/m, then 4 from 1.7 s after opening: the window 1.5-2.0 s changes by > 10 %,
    # T_ss = 1.5 s, and the MDR is the steady 8 (the slower tail is not averaged in)
    res = bin_mdr.measure(_history(tmp_path, [(0.0, 8.0), (1.7, 4.0)]), {})
    assert res["t_ss"] == pytest.approx(1.5)
    assert res["value"] == pytest.approx(8.0, rel=1e-9)


@pytest.mark.parametrize("argv, message", [
    (["wave-bar", "--inertial-friction", "55,0.3,1e-3,2650"], "applies to hopper-mdr, bin-mdr only"),
    (["bin-mdr", "--inertial-friction", "55,0.3,1e-3"], "expected four numbers"),
    (["bin-mdr", "--inertial-friction", "95,0.3,1e-3,2650"], "(0, 89]"),
    (["k0-column", "--pic-time", "0.01"], "--pic-time applies to"),
    (["wave-bar", "--edge-cells", "1,2,3"], "--edge-cells applies to"),
    (["bin-mdr", "--edge-cells", "2,3"], "at least three distinct"),
    (["bin-mdr", "--edge-cells", "2,3,3.5"], "whole numbers"),
    (["hopper-mdr", "--edge-cells", "4.5,5.5,6"], "n + 1/2"),
    (["bin-mdr", "--hopper-scene", "wall_friction=0"], "applies to hopper-mdr only"),
    (["hopper-mdr", "--hopper-scene", "cell=0.1"], "expected KEY=VALUE"),
    (["hopper-mdr", "--hopper-scene", "wall_friction"], "expected KEY=VALUE"),
    (["hopper-mdr", "--hopper-scene", "wall_friction=steel"], "a number or true/false"),
    (["k0-column", "--open-edge"], "--open-edge applies to"),
])
def test_command_line_refuses(argv, message, capsys):
    with pytest.raises(SystemExit):
        cli.main(argv)
    assert message in capsys.readouterr().err


def test_inertial_friction_block_reads_four_numbers():
    assert cli.inertial_friction_block("55.2, 0.279, 0.71e-3, 2650") == (55.2, 0.279, 0.71e-3, 2650.0)


def test_edge_cells_list_reads_the_members():
    assert cli.edge_cells_list("4,5,6", half=False) == [4, 5, 6]
    assert cli.edge_cells_list("4.5, 5.5, 6.5", half=True) == [4.5, 5.5, 6.5]
    assert isinstance(cli.edge_cells_list("4,x,6", half=False), str)


def test_hopper_scene_keywords_reach_every_member(monkeypatch):
    assert cli.hopper_scene_keywords(["wall_friction=0", "dilation=false"]) == {"wall_friction": 0.0,
                                                                                 "dilation": False}
    monkeypatch.setattr(hopper_mdr, "SCENE_EXTRA", {"wall_friction": 0.0})
    member = hopper_mdr.members(True)[0]
    frictionless = hopper_mdr.scene(member)
    monkeypatch.setattr(hopper_mdr, "SCENE_EXTRA", {})
    default = hopper_mdr.scene(member)
    assert frictionless != default
    assert "*MPM WALL, NAME=WALL, FRICTION=0.0000000" in frictionless


@pytest.mark.parametrize("module, walls", [
    (hopper_mdr, ("*MPM WALL, NAME=WALL, FRICTION=0.0874887, OPEN=START", "NAME=OUTLET, FRICTION=0.0874887, OPEN=END")),
    (bin_mdr, ("NAME=FLOOR, FRICTION=0.1227846, OPEN=END", "NAME=OUTLET, FRICTION=0.1227846, OPEN=START")),
    (bin_tss, ("NAME=FLOOR, FRICTION=0.1227846, OPEN=END", "NAME=OUTLET, FRICTION=0.1227846, OPEN=START")),
])
def test_open_edge_opens_the_walls_at_the_outlet_edge_in_every_member(monkeypatch, module, walls):
    """--open-edge: the wall ending at the outlet's edge and the outlet plate open there (the
    eccentric bins' floor ends at the outlet, their plate starts there); none without it."""
    members = module.members(True)
    assert all("OPEN=" not in module.scene(m) for m in members)
    monkeypatch.setattr(module, "OPEN_EDGE", True)
    for m in members:
        text = module.scene(m)
        assert text.count("OPEN=") == 2
        for wall in walls:
            assert wall in text
