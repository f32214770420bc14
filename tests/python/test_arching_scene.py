"""bulkflow.arching.scene: geometry, mesh, material and steps of the arching scene generator."""
import dataclasses
import math

import numpy as np
import pytest

from bulkflow.arching.scene import ArchingScene, case_material, fc0_from_c0, scene_from_case


def _areas(nodes, elems):
    x, y = nodes[elems, 0], nodes[elems, 1]
    return 0.5 * (x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0] + x[:, 1] * y[:, 2] - x[:, 2] * y[:, 1]
                  + x[:, 2] * y[:, 3] - x[:, 3] * y[:, 2] + x[:, 3] * y[:, 0] - x[:, 0] * y[:, 3])


@pytest.mark.parametrize("arch", ["apex", "enstad"])
def test_mesh_fills_the_domain(arch):
    s = ArchingScene(theta=30.0, outlet_width=0.25, height=2.0, n_arc=12, arch=arch, beta=15.0)
    nodes, elems, sets = s.mesh()
    a = _areas(nodes, elems)
    assert np.all(a > 0), "elements must be counter-clockwise (positive area)"
    th = math.radians(s.theta)
    # wall nodes on the wall line, axis nodes on x = 0, top nodes at y = H
    w = nodes[sets["n_wall"]]
    assert np.allclose(w[:, 0] * math.cos(th) - w[:, 1] * math.sin(th), 0.0, atol=1e-12)
    assert np.allclose(nodes[sets["n_axis"], 0], 0.0)
    assert np.allclose(nodes[sets["n_top"], 1], s.height)
    # the outlet nodes lie on the outlet arc, which meets the wall at r_out
    yc, ra = s.arc_centre_radius()
    b = nodes[sets["n_bottom"]]
    assert np.allclose(np.hypot(b[:, 0], b[:, 1] - yc), ra, rtol=1e-10)
    assert math.isclose(float(np.hypot(*b[-1])), s.r_out, rel_tol=1e-10)
    # the area is the sector-to-top area minus the region below the arc
    total = float(np.sum(a))
    h = s.height
    trapezoid = 0.5 * h * h * math.tan(th)          # triangle apex-axis-wall up to y = H
    assert total < trapezoid
    if arch == "apex":
        assert math.isclose(total, trapezoid - 0.5 * s.r_out ** 2 * th, rel_tol=2e-3)


def test_outlet_width_and_elements():
    s = ArchingScene(theta=30.0, outlet_width=0.3, height=2.0, n_arc=30)
    assert math.isclose(s.r_out, 0.3, rel_tol=1e-12)                # B = 2 r sin 30°
    assert math.isclose(s.element_length(), 0.3 * math.radians(30) / 30, rel_tol=1e-12)
    assert s.n_elements() == 30 * s.n_radial()
    assert 2000 < s.n_elements() < 7000
    assert math.isclose(s.flow_limit(), 0.03 * 0.3)                 # physical criterion: 3 % of B
    assert math.isclose(dataclasses.replace(s, criterion="half-element").flow_limit(), 0.5 * s.element_length())


def test_readings_and_cases():
    assert math.isclose(fc0_from_c0(800.0, 20.0), 2 * 800 * math.cos(math.radians(20)) / (1 - math.sin(math.radians(20))))
    assert math.isclose(case_material("polymer", "c0")["fc0"], 1952.19, rel_tol=1e-4)
    assert case_material("polymer", "fc0")["fc0"] == 519.0
    assert math.isclose(case_material("B")["fc0"], 2285.0, rel_tol=1e-3)
    with pytest.raises(ValueError):
        case_material("A", "fc0")                    # Cases A and B have the c0 reading only


def test_inp_text_steps_and_material():
    s = scene_from_case("A", "c0", outlet_width=0.5, n_arc=8, t_gravity=0.4, t_slide=0.2, slide=0.004)
    text = s.inp_text()
    lines = text.splitlines()
    # props: flow function linear (8), fc0 (9), k (10), freeze at the end of the sliding step (11)
    i = lines.index("*USER MATERIAL, CONSTANTS=16")
    props = [float(v) for v in (lines[i + 1] + "," + lines[i + 2]).split(",")]
    assert props[7] == 1 and math.isclose(props[8], s.fc0, rel_tol=1e-8) and props[9] == 0.2
    assert math.isclose(props[10], 0.6)
    assert [ln for ln in lines if ln.startswith("*STEP")] == ["*STEP, NAME=GRAVITY, NLGEOM=YES",
                                                               "*STEP, NAME=SLIDE, NLGEOM=YES",
                                                               "*STEP, NAME=OPEN, NLGEOM=YES"]
    assert "PLATEREF, 2, 2, -0.004" in lines
    assert any(ln.startswith("*FIXED MASS SCALING, DT=") for ln in lines)
    assert "*FIXED MASS SCALING, FACTOR=1" in lines
    assert "*CONTACT PAIR, OP=DELETE" in lines
    stop = [ln for ln in lines if ln.startswith("*STOP CONDITION")]
    assert len(stop) == 1 and "NSET=ALLN" in stop[0]
    # the gravity ramp must use the total time: a step-time ramp restarts (and drops gravity) in
    # every later step
    assert "*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP, TIME=TOTAL TIME" in lines
    # friction of wall and plate: tan(phi_w)
    j = lines.index("*FRICTION")
    assert math.isclose(float(lines[j + 1]), math.tan(math.radians(20.0)), rel_tol=1e-9)


def test_active_state_has_no_sliding_step():
    s = scene_from_case("A", "c0", outlet_width=0.5, n_arc=8, state="active", t_gravity=0.4)
    text = s.inp_text()
    assert "NAME=SLIDE" not in text
    assert math.isclose(s.freeze_time(), 0.4)


def test_no_mass_scaling_option():
    s = scene_from_case("B", "c0", outlet_width=0.3, n_arc=8, mass_scaling_dt_factor=1.0)
    assert "*FIXED MASS SCALING" not in s.inp_text()


def _props(lines):
    i = next(k for k, ln in enumerate(lines) if ln.startswith("*USER MATERIAL"))
    n = int(lines[i].split("=")[1])
    vals = []
    k = i + 1
    while len(vals) < n:
        vals += [float(v) for v in lines[k].split(",")]
        k += 1
    return vals


def test_flow_function_variants():
    s = scene_from_case("sic", "c0", outlet_width=0.15, n_arc=8, flow="bilinear")
    assert _props(s.material_lines())[7] == 2
    t = ArchingScene(flow="table", table=((0.0, 100.0), (1000.0, 500.0)))
    p = _props(t.material_lines())
    assert p[7] == 3 and p[15] == 2 and p[16:20] == [0.0, 100.0, 1000.0, 500.0]


def _vumat_cohesion(props, sigma1=0.0):
    """The cohesion our VUMAT derives from the props of a linear flow function (umat/README.md):
    c = fc (1 - sin φ) / (2 cos φ), fc = fc0 + k σ1, φ = prop 3."""
    phi = math.radians(props[2])
    return (props[8] + props[9] * sigma1) * (1 - math.sin(phi)) / (2 * math.cos(phi))


def test_dilation_angle_option():
    assert _props(scene_from_case("B", "c0", outlet_width=0.3, n_arc=8).material_lines())[3] == 0.0
    assert _props(scene_from_case("B", "c0", outlet_width=0.3, n_arc=8, psi=20.0).material_lines())[3] == 20.0


@pytest.mark.parametrize("case,reading,psi", [("B", "c0", 0.0), ("polymer", "fc0", 0.0), ("A", "c0", 10.0)])
def test_davis_flow_rule(case, reading, psi):
    """Davis (1968): the associated material with tan φ* = η tan φ and c* = η c, η = cos ψ cos φ /
    (1 − sin ψ sin φ), at every consolidation stress of the flow function."""
    s = scene_from_case(case, reading, outlet_width=0.3, n_arc=8, psi=psi)
    d = dataclasses.replace(s, flow_rule="davis")
    p0, p1 = _props(s.material_lines()), _props(d.material_lines())
    f, q = math.radians(s.phi), math.radians(psi)
    eta = math.cos(q) * math.cos(f) / (1 - math.sin(q) * math.sin(f))
    assert p1[2] == p1[3], "Davis's material is associated"
    assert math.isclose(math.tan(math.radians(p1[2])), eta * math.tan(f), rel_tol=1e-7)
    assert p1[2] < s.phi
    for sigma1 in (0.0, 1000.0, 5000.0):
        assert math.isclose(_vumat_cohesion(p1, sigma1), eta * _vumat_cohesion(p0, sigma1), rel_tol=1e-7)
    # the scene keeps the material's own angles (the theories use them)
    assert d.phi == s.phi and d.psi == psi


def test_davis_of_an_associated_material_is_the_material():
    s = scene_from_case("B", "c0", outlet_width=0.3, n_arc=8, psi=20.0)
    a, b = _props(s.material_lines()), _props(dataclasses.replace(s, flow_rule="davis").material_lines())
    assert np.allclose(a, b, rtol=1e-7)


def test_davis_rejects_the_bilinear_flow_function():
    s = scene_from_case("sic", "c0", outlet_width=0.15, n_arc=8, flow="bilinear", flow_rule="davis")
    with pytest.raises(ValueError):
        s.material_lines()


def test_hourglass_and_bulk_viscosity_options():
    s = scene_from_case("B", "c0", outlet_width=0.3, n_arc=8)
    lines = s.inp_text().splitlines()
    assert "*SOLID SECTION, ELSET=POWDER, MATERIAL=MC-POWDER" in lines and "*SECTION CONTROLS" not in s.inp_text()
    assert lines[lines.index("*BULK VISCOSITY") + 1] == "0.06, 1.2"
    t = dataclasses.replace(s, hourglass="stiffness", hourglass_scale=2.0, bulk_viscosity=(0.0, 0.0)).inp_text()
    lines = t.splitlines()
    i = lines.index("*SECTION CONTROLS, NAME=HG, HOURGLASS=STIFFNESS")
    assert lines[i + 1] == "2" and lines[i + 2] == "*SOLID SECTION, ELSET=POWDER, MATERIAL=MC-POWDER, CONTROLS=HG"
    assert lines[lines.index("*BULK VISCOSITY") + 1] == "0, 0"
