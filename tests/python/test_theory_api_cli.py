"""The stable API (Material, Hopper, critical_width_estimates), the cases data and the CLI."""
import io
import json
import math
import os
import subprocess
import sys
from contextlib import redirect_stdout
from pathlib import Path

import pytest

from bulkflow.theory import Hopper, Material, critical_width_estimates
from bulkflow.theory import cases, cli, enstad

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def test_api_example_from_the_issue():
    m = Material(rho=400.0, phi_deg=20.0, phi_w_deg=0.0, k=0.0, fc0=cases.case("B").fc0(), E=10e6, nu=0.2)
    h = Hopper(theta_deg=30.0, height=2.0)
    assert h.R == pytest.approx(2.0 / math.cos(math.radians(30)))
    est = critical_width_estimates(h, m)
    for key in ("mclean", "jenike", "enstad", "assumptions", "delta_mod_deg", "beta_jenike_deg", "X",
                "fc_enstad", "sigma1_outlet_jenike", "r_star", "jenike_by_beta", "notes"):
        assert key in est
    assert isinstance(est["assumptions"], dict)
    assert est["enstad"] == pytest.approx(2 * est["r_star"] * math.sin(math.radians(30)))
    assert 100 * est["enstad"] == pytest.approx(21.7, abs=0.05)
    assert "flows" not in est
    assert critical_width_estimates(h.replace(outlet_width=0.25), m)["flows"]["enstad"] is True


def test_hopper_geometry_helpers():
    h = Hopper(theta_deg=30.0, height=2.0, outlet_width=0.3)
    assert h.outlet_radius() == pytest.approx(0.3)
    assert h.width_at(h.outlet_radius()) == pytest.approx(0.3)


def test_cases_both_readings():
    for key in ("polymer", "sic"):
        c = cases.case(key)
        assert c.readings == ("c0", "fc0")
        assert c.fc0("fc0") == c.c_tab
        assert c.fc0("c0") > 3 * c.c_tab
        assert "reading c0" in c.material("c0").name
    with pytest.raises(ValueError):
        cases.case("A").fc0("fc0")          # Table 6.1 is unambiguous: c0 only
    assert cases.case("a").key == "A"
    assert cases.TABLE_6_3["polymer"] == {"mclean": 35.0, "jenike": 28.0, "enstad": 30.0}
    assert cases.TABLE_6_3["sic"] == {"mclean": 12.0, "jenike": 10.2, "enstad": 10.4}


def test_bilinear_flow_function_only_acts_below_the_merge_stress():
    # The bilinear function (Fig. 6.11) differs from the linear one only below σ₁* = f_c0/(1 − k).
    # SiC at 1 m: every theory's consolidation stress is above σ₁* (≈ 1.1 kPa), nothing changes —
    # in these theories the arch's f_c comes from the material above r*, consolidated harder.
    c = cases.case("sic")
    lin = critical_width_estimates(c.hopper(1.0), c.material("c0"))
    bi = critical_width_estimates(c.hopper(1.0), c.material("c0").replace(flow="bilinear"))
    merge = c.fc0("c0") / (1 - 0.47)
    for t in ("mclean", "jenike"):
        assert bi[t] == pytest.approx(lin[t], rel=1e-9)
        assert lin[f"sigma1_outlet_{t}"] > merge
    assert bi["enstad"] == pytest.approx(lin["enstad"], rel=2e-3) and lin["sigma1_cons_enstad"] > merge
    # Case A at 0.5 m: the arch's consolidation (1.4 kPa) is below σ₁* (1.9 kPa): Enstad drops
    a = cases.case("A")
    lin_a = critical_width_estimates(a.hopper(0.5), a.material())
    bi_a = critical_width_estimates(a.hopper(0.5), a.material().replace(flow="bilinear"))
    assert lin_a["sigma1_cons_enstad"] < a.material().fc0 / (1 - 0.2)
    assert bi_a["enstad"] < 0.95 * lin_a["enstad"]
    # the numerical Enstad route agrees with the closed form for the linear function
    from bulkflow.theory.model import _enstad_width_numeric
    m = c.material("c0")
    h = c.hopper(1.0)
    B, _ = _enstad_width_numeric(h, m, lin["beta_enstad_arch_deg"], lin["beta_enstad_cons_deg"],
                                 lin["delta_mod_deg"], 9.81)
    assert B == pytest.approx(lin["enstad"], rel=2e-3)


def test_consolidation_routes_and_fallback():
    c = cases.case("A")
    for route in ("first_term", "full", "radial", "at_enstad"):
        e = critical_width_estimates(c.hopper(2.0), c.material(), consolidation=route)
        assert 0.3 < e["jenike"] < 0.7 and e["assumptions"]["consolidation"].startswith(route)
    # X ≤ 1.5 with k > 0: first term is flagged / replaced
    m = Material(rho=400, phi_deg=20, phi_w_deg=0, k=0.1, fc0=2000.0)
    e = critical_width_estimates(Hopper(30, 2.0), m)
    assert e["X"] < 1.5 and e["notes"]
    with pytest.raises(ValueError):
        critical_width_estimates(Hopper(30, 2.0), m, consolidation="bogus")


def _run(argv):
    buf = io.StringIO()
    with redirect_stdout(buf):
        assert cli.main(argv) == 0
    return buf.getvalue()


def test_cli_case_B_text_and_json():
    out = _run(["--case", "B", "--height", "2", "--outlet-width", "0.3"])
    assert "Enstad" in out and "21.7" in out and "50.4" in out and "67.0" in out
    assert "NO FLOW" in out and "assumptions" in out
    doc = json.loads(_run(["--case", "B", "--height", "2", "--json"]))
    assert doc["estimates"]["enstad"] == pytest.approx(0.2165, abs=1e-4)
    assert doc["estimates"]["assumptions"]["jenike_beta"] == "theta_plus_omega"


def test_cli_explicit_material_equals_case():
    a = json.loads(_run(["--theta", "30", "--height", "2", "--rho", "400", "--phi", "20", "--phi-w", "0",
                         "--k", "0", "--c0", "800", "--json"]))
    b = json.loads(_run(["--case", "B", "--json"]))
    for t in ("mclean", "jenike", "enstad"):
        assert a["estimates"][t] == pytest.approx(b["estimates"][t])


def test_cli_json_is_strict_with_inf():
    doc = json.loads(_run(["--case", "polymer", "--reading", "c0", "--height", "0.5", "--json"]))
    assert doc["estimates"]["enstad"] == "inf"


def test_cli_table_6_3():
    out = _run(["--table-6-3"])
    for s in ("35.0", "28.0", "30.0", "12.0", "10.2", "10.4", "reading c0", "reading fc0", "172.1"):
        assert s in out
    doc = json.loads(_run(["--table-6-3", "--json"]))
    assert len(doc["rows"]) == 4
    assert {(r["powder"], r["reading"]) for r in doc["rows"]} == {
        ("polymer", "c0"), ("polymer", "fc0"), ("sic", "c0"), ("sic", "fc0")}


def test_cli_discharge_and_arch():
    doc = json.loads(_run(["--case", "A", "--outlet-width", "0.5", "--particle-diameter", "0.001", "--json"]))
    d = doc["discharge"]
    assert d["rose_tanaka_kg_s"] / d["beverloo_kg_s"] == pytest.approx(math.tan(math.radians(30)) ** -0.35)
    arch = doc["outlet_arch"]
    c, r = enstad.arch_centre(arch["r_wall"], 30.0, doc["estimates"]["beta_enstad_arch_deg"])
    assert arch["enstad_centre_height_above_apex"] == pytest.approx(c) and c > 0


def test_cli_module_runs_as_a_process():
    env = dict(os.environ, PYTHONPATH=str(SCRIPTS))
    p = subprocess.run([sys.executable, "-m", "bulkflow.theory.cli", "--case", "A", "--json"],
                       capture_output=True, text=True, env=env, check=True)
    assert json.loads(p.stdout)["estimates"]["enstad"] == pytest.approx(0.5227, abs=1e-4)


def test_cli_console_script_declared():
    text = (SCRIPTS / "pyproject.toml").read_text()
    assert 'bulkflow-theory = "bulkflow.theory.cli:main"' in text


def test_enstad_outlet_arch_for_scene_generators():
    from bulkflow.theory import enstad_outlet_arch
    a = cases.case("A")
    arch = enstad_outlet_arch(a.hopper(2.0, outlet_width=0.5), a.material())
    assert arch["beta_deg"] == pytest.approx(24.54, abs=0.01)
    assert arch["r_wall"] == pytest.approx(0.5)
    t = math.radians(30)
    # the arc passes through both outlet edges (±r sin θ, r cos θ)
    assert math.hypot(0.5 * math.sin(t), 0.5 * math.cos(t) - arch["centre_height"]) == pytest.approx(arch["radius"])
    assert arch["crown_height"] == pytest.approx(arch["centre_height"] + arch["radius"])
    b = enstad_outlet_arch(cases.case("B").hopper(2.0), cases.case("B").material(), outlet_width=0.3)
    assert b["centre_height"] == pytest.approx(0.0) and b["radius"] == pytest.approx(0.3)
    with pytest.raises(ValueError):
        enstad_outlet_arch(cases.case("B").hopper(2.0), cases.case("B").material())


def test_hopper_from_scene_matches_the_scene_generator_geometry():
    from bulkflow.scenes.wedge_hopper import WedgeHopper
    scene = WedgeHopper(theta=30.0, outlet_width=0.4, height=1.5)
    h = Hopper.from_scene(30.0, 0.4, 1.5)
    assert h.height == pytest.approx(scene.top_y)
    assert h.outlet_radius() == pytest.approx(scene.outlet_radius)
