"""The FLOW criterion of the arching scenes (issue 21): the physical rule (u_max > a fraction of
the outlet width B) is the same on every mesh; the thesis's half-element rule shrinks with the
element. The rule reaches the solver as `*STOP CONDITION, DISPLACEMENT=..., GROWTH=...` and the
history decision (bulkflow.arching.decision) reads it back from the scene."""
import dataclasses
import math

import numpy as np
import pytest

from bulkflow.arching.decision import ARREST, FLOW, decide, read_stop_params
from bulkflow.arching.scene import FLOW_WIDTH_FRACTION, GROWTH, ArchingScene, scene_from_case

MESHES = (8, 16, 30, 60, 120)


def _stop_line(s: ArchingScene) -> dict:
    line = next(ln for ln in s.inp_text().splitlines() if ln.startswith("*STOP CONDITION"))
    return {k.strip(): v.strip() for k, v in (kv.split("=") for kv in line.split(",")[1:])}


def test_physical_limit_does_not_depend_on_the_mesh():
    limits = []
    for n in MESHES:
        s = scene_from_case("B", "c0", outlet_width=0.36, height=1.0, n_arc=n)
        assert s.criterion == "physical"
        kv = _stop_line(s)
        limits.append(float(kv["DISPLACEMENT"]))
        assert float(kv["GROWTH"]) == GROWTH["physical"]
    assert np.allclose(limits, FLOW_WIDTH_FRACTION * 0.36, rtol=1e-6)


def test_half_element_limit_halves_with_the_element():
    limits = [float(_stop_line(scene_from_case("B", "c0", outlet_width=0.36, height=1.0, n_arc=n,
                                               criterion="half-element"))["DISPLACEMENT"]) for n in MESHES]
    for n, lim in zip(MESHES, limits):
        s = scene_from_case("B", "c0", outlet_width=0.36, height=1.0, n_arc=n)
        assert math.isclose(lim, 0.5 * s.element_length(), rel_tol=1e-5)
    assert math.isclose(limits[0] / limits[-1], MESHES[-1] / MESHES[0], rel_tol=1e-5)


def test_physical_limit_scales_with_the_outlet_width():
    a = scene_from_case("polymer", "fc0", outlet_width=0.2, n_arc=16)
    b = dataclasses.replace(a, outlet_width=0.4)
    assert math.isclose(b.flow_limit() / a.flow_limit(), 2.0)
    assert math.isclose(dataclasses.replace(a, flow_width_fraction=0.05).flow_limit(), 0.01)


def test_unknown_criterion_is_refused():
    with pytest.raises(ValueError, match="criterion"):
        dataclasses.replace(ArchingScene(), criterion="quarter-element").flow_limit()


def test_dt_scale_writes_scale_factor_only_when_asked():
    s = scene_from_case("B", "c0", outlet_width=0.3, n_arc=8)
    assert "SCALE FACTOR" not in s.inp_text()
    lines = dataclasses.replace(s, dt_scale=0.98).inp_text().splitlines()
    assert sum(ln == "*DYNAMIC, EXPLICIT, SCALE FACTOR=0.98" for ln in lines) == 3


def _history(path, t, u, ke, step=3):
    cols = ["time", "step", "step_time", "increment", "ALLKE", "UMAX_ALLN"]
    with open(path, "w") as f:
        f.write(",".join(cols) + "\n")
        for i, (ti, ui, ki) in enumerate(zip(t, u, ke)):
            f.write(",".join(f"{v:.15e}" for v in (1.0 + ti, step, ti, i, ki, ui)) + "\n")
    return path


@pytest.mark.parametrize("n_arc", [30, 60, 120])
def test_a_slump_that_rearches_is_arrest_on_every_mesh(tmp_path, n_arc):
    """After the opening the outlet material slides 1.6 % of B and comes to rest (the shape of the
    Case B run at B = 37 cm, 1 m, n_arc 16: 5.8 mm, then at rest): the physical rule calls it ARREST
    on every mesh; the half-element rule calls the same motion FLOW once half an element is below it."""
    width = 0.37
    t = np.linspace(0.0, 0.5, 251)
    u = 0.016 * width * (1.0 - np.exp(-t / 0.08))
    ke = 0.01 * (t / 0.03) * np.exp(1.0 - t / 0.03)
    hist = _history(tmp_path / "h.csv", t, u, ke)
    phys = scene_from_case("B", "c0", outlet_width=width, height=1.0, n_arc=n_arc)
    half = dataclasses.replace(phys, criterion="half-element")
    d_phys = decide(hist, read_stop_params(phys.write(tmp_path / "p.inp")))
    d_half = decide(hist, read_stop_params(half.write(tmp_path / "h.inp")))
    assert d_phys.outcome == ARREST
    assert d_half.outcome == FLOW                      # 5.9 mm > half of a 6.5, 3.2 or 1.6 mm element


def test_an_accelerating_outlet_is_flow_under_both(tmp_path):
    width = 0.40
    t = np.linspace(0.0, 0.3, 151)
    u = 0.5 * 2.0 * t ** 2                             # accelerating at 2 m/s^2
    ke = t ** 2
    hist = _history(tmp_path / "h.csv", t, u, ke)
    for crit in ("physical", "half-element"):
        s = scene_from_case("B", "c0", outlet_width=width, height=1.0, n_arc=30, criterion=crit)
        assert decide(hist, read_stop_params(s.write(tmp_path / f"{crit}.inp"))).outcome == FLOW
